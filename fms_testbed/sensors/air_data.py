"""Air-data computer, the truth side: what the pitot-static system, the temperature probe and the
vanes measure, turned into TAS, CAS, Mach and altitudes the way an air-data computer does.

The computer measures static pressure p_s, impact pressure q_c (from the true Mach number and p_s,
St-Venant), total temperature and the vanes, and derives (ISA, ICAO Doc 7488):

    M = √(2/(γ-1) ((q_c/p_s + 1)^((γ-1)/γ) - 1)),   T_s = T_t / (1 + (γ-1)/2 M²),
    TAS = M √(γ R T_s),   CAS = a0 √(2/(γ-1) ((q_c/P0 + 1)^((γ-1)/γ) - 1)),
    pressure altitude = the ISA altitude of p_s.

:class:`AirDataSpec` holds the errors; with the default spec (all zero) the outputs equal the
truth JSBSim flies, so a flight on it is the flight on truth air data. Guidance and the laws read
:class:`~fms_testbed.core.state.AirData`, never :class:`~fms_testbed.core.state.AircraftState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.atmosphere import A0_MPS, GAMMA, P0_PA, R_JPKGK, altitude_of_pressure_m
from fms_testbed.core.state import AirData, AircraftState

_K = (GAMMA - 1.0) / GAMMA


@dataclass(frozen=True)
class AirDataSpec:
    """Air-data errors (SI); all zero by default: the computer then reports the truth.

    Attributes
    ----------
    static_pressure_bias_pa : static-source error, Pa (positive: reads high)
    tas_scale : scale-factor error on the airspeed (0.01: reads 1 % high)
    temperature_bias_k : total-temperature probe error, K
    """

    static_pressure_bias_pa: float = 0.0
    tas_scale: float = 0.0
    temperature_bias_k: float = 0.0


class AirDataComputer:
    """The air-data computer: :meth:`update` turns the true state into :class:`AirData`.

    Parameters
    ----------
    spec : its errors (default: none)
    """

    def __init__(self, spec: AirDataSpec = AirDataSpec()):
        self.spec = spec
        self._perfect = spec == AirDataSpec()

    def update(self, truth: AircraftState) -> AirData:
        """Air data at ``truth.t_s`` (m/s, m, Pa, K, rad): with a perfect computer the true
        TAS, CAS, Mach and vanes, and the pressure altitude of the true static pressure."""
        ps = truth.p_static_pa
        ts = truth.t_static_k
        if self._perfect or not (ps > 0.0 and ts > 0.0):
            h_p = float(altitude_of_pressure_m(ps)) if ps > 0.0 else truth.alt_m
            return AirData(truth.t_s, truth.tas_mps, truth.cas_mps, truth.mach, h_p, truth.alt_m,
                           truth.vs_mps, ps, ts, truth.alpha_rad, truth.beta_rad)
        sp = self.spec
        mach = truth.mach * (1.0 + sp.tas_scale)
        ps_m = ps + sp.static_pressure_bias_pa
        qc = ps_m * ((1.0 + 0.5 * (GAMMA - 1.0) * mach * mach) ** (1.0 / _K) - 1.0)
        tt = ts * (1.0 + 0.5 * (GAMMA - 1.0) * truth.mach ** 2) + sp.temperature_bias_k
        ts_m = tt / (1.0 + 0.5 * (GAMMA - 1.0) * mach * mach)
        tas = mach * math.sqrt(GAMMA * R_JPKGK * ts_m)
        cas = A0_MPS * math.sqrt(2.0 / (GAMMA - 1.0) * ((qc / P0_PA + 1.0) ** _K - 1.0))
        h_p = float(altitude_of_pressure_m(ps_m))
        return AirData(truth.t_s, tas, cas, mach, h_p, truth.alt_m + (h_p - float(altitude_of_pressure_m(ps))),
                       truth.vs_mps, ps_m, ts_m, truth.alpha_rad, truth.beta_rad)


__all__ = ["AirDataSpec", "AirDataComputer"]
