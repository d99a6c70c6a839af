"""Gain schedule of the coupled law in dynamic pressure and mass.

Each scheduled parameter (T_V_s, xi_V, T_H_s, xi_H, ny_trim_tau_s) is a smooth function of the scheduling
variables, fitted by least squares over the tuned design points::

    p(q̄, m) = c0 + c1 ln(q̄ / q̄_ref) + c2 (m / m_ref - 1)

clipped to the tuning box. The law evaluates it in flight from the measured state
(q̄ = ½ ρ V², ρ = p_s / (R T_s)) and swaps its tuning when a parameter moves by more than
:data:`REFRESH_REL`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fms_testbed.core.atmosphere import R_JPKGK

SCHEDULED = ("T_V_s", "xi_V", "T_H_s", "xi_H", "ny_trim_tau_s")
"""Coupled-law parameters the schedule sets (s, -, s, -, s)."""
REFRESH_REL = 0.005
"""Relative change of a scheduled parameter that makes the law take the new tuning."""


@dataclass(frozen=True)
class GainSchedule:
    """Fitted schedule (module docstring).

    Attributes
    ----------
    qbar_ref_pa : reference dynamic pressure, Pa;  mass_ref_kg : reference mass, kg
    coeffs : parameter → (c0, c1, c2) in the parameter's unit
    bounds : parameter → (lower, upper) clip
    """

    qbar_ref_pa: float
    mass_ref_kg: float
    coeffs: dict[str, tuple[float, float, float]]
    bounds: dict[str, tuple[float, float]]

    def values(self, qbar_pa: float, mass_kg: float) -> dict[str, float]:
        """Scheduled parameters at dynamic pressure ``qbar_pa`` (Pa) and mass ``mass_kg`` (kg)."""
        x = (1.0, math.log(max(qbar_pa, 1.0) / self.qbar_ref_pa), mass_kg / self.mass_ref_kg - 1.0)
        out = {}
        for name, c in self.coeffs.items():
            lo, hi = self.bounds.get(name, (-math.inf, math.inf))
            out[name] = min(max(c[0] * x[0] + c[1] * x[1] + c[2] * x[2], lo), hi)
        return out

    def regressors(self, qbar_pa: np.ndarray, mass_kg: np.ndarray) -> np.ndarray:
        """Design matrix [1, ln(q̄/q̄_ref), m/m_ref - 1] (rows: points); q̄ in Pa, m in kg."""
        q, m = np.asarray(qbar_pa, float), np.asarray(mass_kg, float)
        return np.column_stack([np.ones_like(q), np.log(q / self.qbar_ref_pa),
                                m / self.mass_ref_kg - 1.0])


def fit_schedule(qbar_pa, mass_kg, table: dict[str, np.ndarray],
                 bounds: dict[str, tuple[float, float]]) -> GainSchedule:
    """Least-squares fit of :class:`GainSchedule` to tuned values at design points.

    Parameters
    ----------
    qbar_pa, mass_kg : scheduling variables of the points, Pa and kg
    table : parameter → tuned values at the points;  bounds : clip of each parameter
    """
    q, m = np.asarray(qbar_pa, float), np.asarray(mass_kg, float)
    s = GainSchedule(float(np.exp(np.mean(np.log(q)))), float(np.mean(m)), {}, dict(bounds))
    X = s.regressors(q, m)
    coeffs = {}
    for name, y in table.items():
        c, *_ = np.linalg.lstsq(X, np.asarray(y, float), rcond=None)
        coeffs[name] = tuple(float(v) for v in c)
    return replace(s, coeffs=coeffs)


def qbar_from_state(tas_mps: float, p_static_pa: float, t_static_k: float) -> float:
    """Dynamic pressure ½ ρ V², Pa, with ρ = p_s / (R T_s) (m/s, Pa, K)."""
    rho = p_static_pa / (R_JPKGK * max(t_static_k, 1.0))
    return 0.5 * rho * tas_mps * tas_mps
