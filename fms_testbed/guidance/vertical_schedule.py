"""Gain schedule of the coupled law in dynamic pressure and mass: a table over the design points.

The tuned parameters (T_V_s, xi_V, T_H_s, xi_H, ny_trim_tau_s) are tabulated at the design
points. The points are grouped by mass (masses within :data:`MASS_LEVEL_REL` of each other form
one level); the schedule is piecewise linear in ln q̄ within a level and linear in mass between
the two levels around the query, held constant beyond the table's ends::

    p(q̄, m) = (1 - w) p_i(ln q̄) + w p_(i+1)(ln q̄),   w = (m - m_i) / (m_(i+1) - m_i)

so it passes through every tuned point and is continuous in both variables. The law evaluates
it in flight from the measured state (q̄ = ½ ρ V², ρ = p_s / (R T_s)) and takes the new tuning
when a parameter moves by more than :data:`REFRESH_REL`; VNAV's altitude read-ahead
(2 ξ_H T_H and T_H², :func:`fms_testbed.guidance.vertical.scheduled_lead`) follows the same
table, which is why it lives below the control layer (:mod:`fms_testbed.control.schedule`
re-exports it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fms_testbed.core.atmosphere import R_JPKGK

SCHEDULED = ("T_V_s", "xi_V", "T_H_s", "xi_H", "ny_trim_tau_s")
"""Coupled-law parameters the schedule sets (s, -, s, -, s)."""
REFRESH_REL = 0.005
"""Relative change of a scheduled parameter that makes the law take the new tuning."""
MASS_LEVEL_REL = 0.02
"""Design masses closer than this fraction are one mass level of the table."""


@dataclass(frozen=True)
class MassLevel:
    """One mass level: its mass (kg), the ln q̄ of its points (sorted) and each parameter's
    values there."""

    mass_kg: float
    ln_qbar: np.ndarray
    values: dict[str, np.ndarray]


@dataclass(frozen=True)
class GainSchedule:
    """The schedule table (module docstring), mass levels sorted by mass."""

    levels: tuple[MassLevel, ...]

    def values(self, qbar_pa: float, mass_kg: float, names=None) -> dict[str, float]:
        """Scheduled parameters at dynamic pressure ``qbar_pa`` (Pa) and mass ``mass_kg`` (kg)
        (only ``names`` when given)."""
        lq = float(np.log(max(qbar_pa, 1.0)))
        at = [{k: float(np.interp(lq, lv.ln_qbar, v)) for k, v in lv.values.items()
               if names is None or k in names} for lv in self.levels]
        ms = [lv.mass_kg for lv in self.levels]
        if len(ms) == 1 or mass_kg <= ms[0]:
            return at[0]
        if mass_kg >= ms[-1]:
            return at[-1]
        i = int(np.searchsorted(ms, mass_kg)) - 1
        w = (mass_kg - ms[i]) / (ms[i + 1] - ms[i])
        return {k: (1 - w) * at[i][k] + w * at[i + 1][k] for k in at[i]}

    def table(self) -> list[dict]:
        """The table as plain rows (qbar_pa, mass_kg and the parameters) for the aircraft file."""
        return [{"qbar_pa": round(float(np.exp(q)), 1), "mass_kg": round(lv.mass_kg, 1),
                 **{k: round(float(v[j]), 4) for k, v in lv.values.items()}}
                for lv in self.levels for j, q in enumerate(lv.ln_qbar)]


def schedule_from_points(rows: list[dict]) -> GainSchedule:
    """Build the table from rows ``{qbar_pa, mass_kg, <parameter>: value}`` (Pa, kg).

    Points of one mass level at the same q̄ (within 0.1 %) are averaged.
    """
    rows = sorted(rows, key=lambda r: r["mass_kg"])
    groups: list[list[dict]] = []
    for r in rows:
        if groups and abs(r["mass_kg"] / groups[-1][0]["mass_kg"] - 1) <= MASS_LEVEL_REL:
            groups[-1].append(r)
        else:
            groups.append([r])
    names = [k for k in rows[0] if k not in ("qbar_pa", "mass_kg")]
    levels = []
    for g in groups:
        g = sorted(g, key=lambda r: r["qbar_pa"])
        lq, vals = [], {k: [] for k in names}
        for r in g:
            q = float(np.log(r["qbar_pa"]))
            if lq and q - lq[-1] < 1e-3:
                n = len([x for x in g if abs(np.log(x["qbar_pa"]) - q) < 1e-3])
                for k in names:
                    vals[k][-1] += (r[k] - vals[k][-1]) / n
                continue
            lq.append(q)
            for k in names:
                vals[k].append(float(r[k]))
        levels.append(MassLevel(float(np.mean([r["mass_kg"] for r in g])), np.array(lq),
                                {k: np.array(v) for k, v in vals.items()}))
    return GainSchedule(tuple(levels))


def schedule_from_config(cfg) -> GainSchedule | None:
    """The aircraft configuration ``cfg``'s ``coupled_law_schedule`` as a :class:`GainSchedule`
    (None when absent)."""
    sc = cfg.coupled_law_schedule
    if sc is None:
        return None
    return schedule_from_points([p.model_dump() for p in sc.points])


def qbar_from_state(tas_mps: float, p_static_pa: float, t_static_k: float) -> float:
    """Dynamic pressure ½ ρ V², Pa, at TAS ``tas_mps`` (m/s) with ρ = p_s / (R T_s) from the
    static pressure ``p_static_pa`` (Pa) and temperature ``t_static_k`` (K)."""
    rho = p_static_pa / (R_JPKGK * max(t_static_k, 1.0))
    return 0.5 * rho * tas_mps * tas_mps
