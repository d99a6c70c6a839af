"""Air-data computer, the truth side: what the pitot-static system, the temperature probe and the
vanes measure, turned into TAS, CAS, Mach and altitudes the way an air-data computer does.

The computer measures static pressure p_s, impact pressure q_c = p_t - p_s (the true q_c from
the true Mach number and p_s, St-Venant), total temperature and the vanes, and derives (ISA,
ICAO Doc 7488):

    M = √(2/(γ-1) ((q_c/p_s + 1)^((γ-1)/γ) - 1)),   T_s = T_t / (1 + (γ-1)/2 M²),
    TAS = M √(γ R T_s),   CAS = a0 √(2/(γ-1) ((q_c/P0 + 1)^((γ-1)/γ) - 1)),
    pressure altitude = the ISA altitude of p_s.

Error model (:class:`AirDataSpec`, the realised errors of one installation; all zero by default,
so a flight on it is the flight on truth air data)::

    p_s,m = p_s + q_c (c_pe + c_pe,α α) + b_ps + w_p        static source: the residual position
                                                            error after the computer's static-
                                                            source error correction, transducer
                                                            bias, noise
    q_c,m = (p_t - p_s,m)(1 + k_qc) + b_qc + w_p            the pitot sees the true total pressure
    M_m = M(q_c,m, p_s,m) (1 + k_M)                         a residual Mach (airspeed) scale
    T_t,m = T_t + b_T                                       total-temperature probe
    α_m = α (1 + k_α) + b_α + w_v,   β_m = β (1 + k_β) + b_β + w_v          vanes

with first-order lags of the pneumatic lines on p_s and q_c (``static_lag_s``, ``pitot_lag_s``)
and of the probe on T_t (``temperature_lag_s``). The altitude the altimeter shows carries the
pressure altitude's error (the altimeter setting is the computer's, exact), and the barometric
vertical speed is the rate of that altitude.

:class:`AirDataErrors` holds the 1σ of each error for an installation type and draws a seeded
realisation (:meth:`AirDataErrors.draw`); :data:`TYPICAL` is a transport aircraft's air-data
system after calibration (sources in its docstring). Scenario key ``air_data: {errors: none |
typical, seed: N}`` (:meth:`AirDataComputer.from_spec`). Guidance and the laws read
:class:`~fms_testbed.core.state.AirData`, never :class:`~fms_testbed.core.state.AircraftState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from fms_testbed.core.atmosphere import A0_MPS, GAMMA, P0_PA, R_JPKGK, altitude_of_pressure_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AirData, AircraftState

_K = (GAMMA - 1.0) / GAMMA


@dataclass(frozen=True)
class AirDataSpec:
    """The realised errors of one air-data installation (SI); all zero: the truth.

    Attributes
    ----------
    static_pressure_bias_pa : static transducer bias b_ps, Pa (positive: reads high)
    tas_scale : residual Mach/airspeed scale k_M (0.01: reads 1 % high)
    temperature_bias_k : total-temperature probe bias b_T, K
    static_position_error : residual static-source position error c_pe = Δp_s / q_c
    static_position_error_per_rad : its angle-of-attack slope c_pe,α, 1/rad
    impact_pressure_scale : impact-pressure transducer scale k_qc
    impact_pressure_bias_pa : impact-pressure transducer bias b_qc, Pa
    pressure_noise_pa : white noise σ on each pressure reading, Pa
    static_lag_s, pitot_lag_s, temperature_lag_s : first-order lags of the static line, the
        pitot line and the temperature probe, s
    alpha_bias_rad, alpha_scale, beta_bias_rad, beta_scale : vane biases (rad) and scales
    vane_noise_rad : white noise σ on each vane reading, rad
    """

    static_pressure_bias_pa: float = 0.0
    tas_scale: float = 0.0
    temperature_bias_k: float = 0.0
    static_position_error: float = 0.0
    static_position_error_per_rad: float = 0.0
    impact_pressure_scale: float = 0.0
    impact_pressure_bias_pa: float = 0.0
    pressure_noise_pa: float = 0.0
    static_lag_s: float = 0.0
    pitot_lag_s: float = 0.0
    temperature_lag_s: float = 0.0
    alpha_bias_rad: float = 0.0
    alpha_scale: float = 0.0
    beta_bias_rad: float = 0.0
    beta_scale: float = 0.0
    vane_noise_rad: float = 0.0


_DRAWN = ("static_pressure_bias_pa", "tas_scale", "temperature_bias_k", "static_position_error",
          "static_position_error_per_rad", "impact_pressure_scale", "impact_pressure_bias_pa",
          "alpha_bias_rad", "alpha_scale", "beta_bias_rad", "beta_scale")
"""The :class:`AirDataSpec` fields drawn as random constants (the rest are taken as given)."""


@dataclass(frozen=True)
class AirDataErrors:
    """1σ of each :class:`AirDataSpec` error of an installation type (same fields, same units):
    the drawn ones (:data:`_DRAWN`) are random constants N(0, σ²) of one installation, the noise
    σ and the lags are taken as they are."""

    spec: AirDataSpec

    def draw(self, seed: int) -> AirDataSpec:
        """One installation's errors from ``seed`` (numpy ``default_rng``; a field order fixed
        by :data:`_DRAWN`)."""
        z = np.random.default_rng(int(seed)).standard_normal(len(_DRAWN))
        values = {f.name: getattr(self.spec, f.name) for f in fields(AirDataSpec)}
        for name, zz in zip(_DRAWN, z):
            values[name] = float(zz) * values[name]
        return AirDataSpec(**values)


TYPICAL = AirDataErrors(AirDataSpec(
    static_pressure_bias_pa=10.0, tas_scale=0.002, temperature_bias_k=0.5,
    static_position_error=0.005, static_position_error_per_rad=0.02,
    impact_pressure_scale=0.001, impact_pressure_bias_pa=5.0, pressure_noise_pa=1.0,
    static_lag_s=0.2, pitot_lag_s=0.05, temperature_lag_s=1.0,
    alpha_bias_rad=math.radians(0.25), alpha_scale=0.03, beta_bias_rad=math.radians(0.25),
    beta_scale=0.03, vane_noise_rad=math.radians(0.05)))
"""A transport aircraft's air data after calibration, 1σ. Static-source residual position error
c_pe = 0.5 % of q_c (Gracey, *Measurement of Aircraft Speed and Altitude*, NASA RP-1046, 1980:
uncorrected flush ports 1-5 % of q_c; a corrected system's residual is what the RVSM altimetry
budget allows — FAA AC 91-85B: mean altimetry system error ≤ 80 ft and mean + 3σ ≤ 200 ft: at
FL350/M0.8, q_c ≈ 12 kPa, 0.5 % is 60 Pa or 16 m, 1σ), with an α slope of 0.02 per rad; static
and impact-pressure transducers 10 Pa and 5 Pa bias, 0.1 % scale, 1 Pa noise (digital ADC
transducers of 0.01-0.02 % of full scale); total-temperature probe 0.5 K (the recovery-correction
uncertainty quoted for Rosemount/Goodrich 102-series probes), 1 s response; residual Mach scale
0.2 %; vanes 0.25° bias, 3 % scale (upwash calibration residual), 0.05° noise; pneumatic lags
0.2 s static, 0.05 s pitot (Gracey ch. 14: lag constants of 0.1-1 s for static systems)."""

PRESETS = {"none": None, "typical": TYPICAL}
"""``air_data.errors`` names."""


class _Lag:
    """First-order lag y' = (x - y)/τ, exact for x held over the step (τ = 0: none)."""

    def __init__(self, tau_s: float):
        self.tau_s, self.y, self.t = tau_s, None, None

    def __call__(self, t_s: float, x: float) -> float:
        if self.tau_s <= 0.0 or self.y is None:
            self.y, self.t = x, t_s
            return x
        a = math.exp(-max(t_s - self.t, 0.0) / self.tau_s)
        self.y, self.t = x + a * (self.y - x), t_s
        return self.y


class AirDataComputer:
    """The air-data computer: :meth:`update` turns the true state into :class:`AirData`.

    Parameters
    ----------
    spec : its errors (default: none)
    seed : seed of its white noise
    """

    def __init__(self, spec: AirDataSpec = AirDataSpec(), seed: int = 0):
        self.spec = spec
        self._perfect = spec == AirDataSpec()
        self._rng = np.random.default_rng(int(seed))
        self._lag_ps, self._lag_qc = _Lag(spec.static_lag_s), _Lag(spec.pitot_lag_s)
        self._lag_tt = _Lag(spec.temperature_lag_s)
        self._prev: tuple[float, float] | None = None      # (t_s, altitude error m)

    @classmethod
    def from_spec(cls, block: dict | None, seed: int = 0) -> "AirDataComputer":
        """From a scenario's ``air_data`` mapping ``{errors: none | typical, seed: N}``
        (``None``: error-free); ``block['seed']`` wins over ``seed``.

        Raises
        ------
        ConfigError : an unknown key or preset
        """
        block = dict(block or {})
        unknown = sorted(set(block) - {"errors", "seed"})
        if unknown:
            raise ConfigError(f"field 'air_data.{unknown[0]}': unknown (allowed: errors, seed)")
        name = block.get("errors", "none")
        if name not in PRESETS:
            raise ConfigError(f"field 'air_data.errors': {name!r} is not one of "
                              f"{', '.join(PRESETS)}")
        sd = int(block.get("seed", seed))
        model = PRESETS[name]
        spec = AirDataSpec() if model is None else model.draw(sd)
        return cls(spec, seed=np.random.SeedSequence([sd, 1]).generate_state(1)[0])

    def _pressures(self, truth: AircraftState, ps: float) -> tuple[float, float]:
        """Measured (p_s, q_c), Pa: position error, transducers, noise, then the line lags."""
        sp = self.spec
        m2 = truth.mach * truth.mach
        qc = ps * ((1.0 + 0.5 * (GAMMA - 1.0) * m2) ** (1.0 / _K) - 1.0)
        n1, n2 = (self._rng.standard_normal(2) * sp.pressure_noise_pa if sp.pressure_noise_pa
                  else (0.0, 0.0))
        ps_m = (ps + qc * (sp.static_position_error + sp.static_position_error_per_rad
                           * truth.alpha_rad) + sp.static_pressure_bias_pa + n1)
        qc_m = (ps + qc - ps_m) * (1.0 + sp.impact_pressure_scale) + sp.impact_pressure_bias_pa + n2
        return self._lag_ps(truth.t_s, ps_m), self._lag_qc(truth.t_s, qc_m)

    def _vanes(self, truth: AircraftState) -> tuple[float, float]:
        sp = self.spec
        n1, n2 = (self._rng.standard_normal(2) * sp.vane_noise_rad if sp.vane_noise_rad
                  else (0.0, 0.0))
        return (truth.alpha_rad * (1.0 + sp.alpha_scale) + sp.alpha_bias_rad + n1,
                truth.beta_rad * (1.0 + sp.beta_scale) + sp.beta_bias_rad + n2)

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
        ps_m, qc_m = self._pressures(truth, ps)
        qc_m = max(qc_m, 0.0)
        mach = math.sqrt(2.0 / (GAMMA - 1.0) * ((qc_m / ps_m + 1.0) ** _K - 1.0))
        mach *= 1.0 + sp.tas_scale
        tt = self._lag_tt(truth.t_s, ts * (1.0 + 0.5 * (GAMMA - 1.0) * truth.mach ** 2)
                          + sp.temperature_bias_k)
        ts_m = tt / (1.0 + 0.5 * (GAMMA - 1.0) * mach * mach)
        tas = mach * math.sqrt(GAMMA * R_JPKGK * ts_m)
        cas = A0_MPS * math.sqrt(2.0 / (GAMMA - 1.0) * ((qc_m / P0_PA + 1.0) ** _K - 1.0))
        h_p = float(altitude_of_pressure_m(ps_m))
        dh = h_p - float(altitude_of_pressure_m(ps))
        vs = truth.vs_mps
        if self._prev is not None and truth.t_s > self._prev[0]:
            vs += (dh - self._prev[1]) / (truth.t_s - self._prev[0])
        self._prev = (truth.t_s, dh)
        alpha, beta = self._vanes(truth)
        return AirData(truth.t_s, tas, cas, mach, h_p, truth.alt_m + dh, vs, ps_m, ts_m, alpha,
                       beta)


__all__ = ["AirDataSpec", "AirDataErrors", "AirDataComputer", "TYPICAL", "PRESETS"]
