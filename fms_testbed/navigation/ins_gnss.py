"""INS/GNSS navigation source: INS unit(s), a GNSS receiver and a baro on the truth side, and a
loosely coupled error-state Kalman filter per INS (:mod:`.ins_filter`) — what guidance flies on.

Scenario block (``navigation:``, validated by :class:`~fms_testbed.config.navigation.InsGnssBlock`)::

    source: ins_gnss
    imu: STIM300                 # preset, .yaml path or mapping (every unit)
    n_ins: 1
    seed: 7                      # optional; otherwise the run seed
    gnss: {rate_hz: 1, latency_s: 0.1, pos_markov_sigma_m: [1, 1, 2], ...,
           outages: [{start_s: 300, end_s: 360}], outliers: [...], ramps: [...]}
    baro: {markov_sigma_m: 5, markov_tau_s: 1800, white_sigma_m: 0.5, rate_hz: 10}   # or null
    filter: {gate_sigma: 5, unmodelled_tau_s: 100, method: picard}
    alert_delay_s: 2

One :meth:`InsGnssNavigation.update` per navigation step: the INS units advance (truth ⊕ their
errors), each filter predicts over the step, the baro reading and any delivered GNSS fix are
used (innovation-gated, Joseph form), the INS block of each estimate is fed back to its unit at
every GNSS update, and the output is unit 0's corrected solution with the filter's position
covariance (``pos_cov_enu_m2``) and ANP. Logged columns (``NavSolution.errors``): ``anp_m``
(95 % horizontal radius of P, m), ``nav_mode`` (:data:`~.monitor.NAV_MODES`), ``ins_used`` (bit
mask of the units the output uses), ``nse_{east,north,up}_m`` (output - truth, truth side),
``att_err_{roll,pitch,heading}_deg`` (output - truth) and ``sigma_heading_deg`` (filter). Events
(``events``: GNSS groups rejected by the gate / accepted again) go to ``summary.json``.

Seeds: ``navigation.seed`` or the run seed → :func:`~.ins_bank.derive_seeds` → one stream per INS
unit, the GNSS receiver and the baro.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import ValidationError

from fms_testbed.config.navigation import InsGnssBlock
from fms_testbed.config.yamlfile import validation_message
from fms_testbed.core.earth import radii_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.ins_bank import InsBank, derive_seeds
from fms_testbed.navigation.ins_filter import FilterTuning, GroupResult, InsGnssFilter
from fms_testbed.navigation.monitor import DEFAULT_ALERT_DELAY_S
from fms_testbed.sensors.baro import BaroAltimeter, BaroSpec
from fms_testbed.sensors.gnss import GnssReceiver, GnssSpec, Interval, OutlierBurst, Ramp
from fms_testbed.sensors.sins.analysis import horizontal_radius
from fms_testbed.sensors.sins.euler import eps_to_euler_errors
from fms_testbed.sensors.sins.presets import load_imu

_BUFFER_S = 2.0          # INS outputs kept for the GNSS latency, s


def _interval(b) -> Interval:
    return Interval(b.start_s, math.inf if b.end_s is None else b.end_s)


def gnss_spec(block) -> GnssSpec:
    """:class:`GnssSpec` (SI) from a validated ``navigation.gnss`` block."""
    return GnssSpec(
        tuple(block.pos_markov_sigma_m), block.pos_markov_tau_s, tuple(block.pos_white_sigma_m),
        tuple(block.vel_markov_sigma_mps), block.vel_markov_tau_s,
        tuple(block.vel_white_sigma_mps), block.rate_hz, block.latency_s,
        tuple(_interval(o) for o in block.outages),
        tuple(OutlierBurst(_interval(o), o.sigma_m) for o in block.outliers),
        tuple(Ramp(_interval(r), tuple(r.rate_mps)) for r in block.ramps))


def baro_spec(block) -> BaroSpec | None:
    """:class:`BaroSpec` (SI) from a validated ``navigation.baro`` block (None: no baro)."""
    if block is None:
        return None
    return BaroSpec(block.markov_sigma_m, block.markov_tau_s, block.white_sigma_m, block.rate_hz,
                    math.inf if block.failed_from_s is None else block.failed_from_s)


def corrected(sol: NavSolution, dx9: np.ndarray) -> tuple[float, float, float, np.ndarray,
                                                          float, float, float]:
    """(lat rad, lon rad, alt m, V (3,) m/s, roll, pitch, heading rad): an INS output minus an
    estimated error (δp ENU m, δV m/s, ε rad; Euler errors by paper eq. 6.10)."""
    rm, rn = radii_m(sol.lat_rad)
    h = sol.alt_m
    d_roll, d_pitch, d_head = eps_to_euler_errors(dx9[6], dx9[7], dx9[8], sol.pitch_rad,
                                                  sol.heading_rad)
    return (sol.lat_rad - dx9[1] / (rm + h),
            sol.lon_rad - dx9[0] / ((rn + h) * math.cos(sol.lat_rad)), h - dx9[2],
            np.asarray(sol.v_enu_mps, float) - dx9[3:6], sol.roll_rad - float(d_roll),
            sol.pitch_rad - float(d_pitch), (sol.heading_rad - float(d_head)) % (2 * math.pi))


class InsGnssNavigation:
    """INS/GNSS navigation source; see the module docstring for the scenario keys.

    Parameters
    ----------
    bank : the INS units;  receiver : the GNSS receiver;  baro : the baro (or None)
    filters : one filter per unit;  alert_delay_s : RNP-alert persistence, s
    """

    def __init__(self, bank: InsBank, receiver: GnssReceiver, baro: BaroAltimeter | None,
                 filters: list[InsGnssFilter], alert_delay_s: float = DEFAULT_ALERT_DELAY_S):
        self.bank, self.receiver, self.baro, self.filters = bank, receiver, baro, filters
        self.alert_delay_s = float(alert_delay_s)
        self.events: list[dict] = []
        self._prev_truth: AircraftState | None = None
        self._prev_ins: list[NavSolution] = []
        self._buffer: list[list[NavSolution]] = [[] for _ in filters]
        self._gate_open = {"gnss_pos": True, "gnss_vel": True}
        self._last_fix_used_s = -math.inf
        self.last_groups: list[GroupResult] = []
        self.nis_log: list[tuple[float, str, float, int]] = []   # (t_s, group, NIS, dim)

    @classmethod
    def from_spec(cls, spec: dict, seed: int | None = None) -> "InsGnssNavigation":
        """Build from a scenario's ``navigation`` mapping (``spec['seed']`` wins over ``seed``).

        Raises
        ------
        ConfigError : unknown key or bad value (named ``navigation.<key>``), unknown IMU
        """
        try:
            b = InsGnssBlock.model_validate(spec)
        except ValidationError as err:
            msg = validation_message("navigation", err)
            raise ConfigError(msg.replace("navigation: field '", "field 'navigation.", 1)) from None
        imu = load_imu(b.imu)
        sd = b.seed if b.seed is not None else (0 if seed is None else int(seed))
        seeds = derive_seeds(sd, b.n_ins + 2)
        g, br = gnss_spec(b.gnss), baro_spec(b.baro)
        tuning = FilterTuning(b.filter.gate_sigma, b.filter.unmodelled_tau_s, b.filter.method)
        bank = InsBank([imu] * b.n_ins, seeds[:b.n_ins], method=b.filter.method)
        filters = [InsGnssFilter(imu, g, br, tuning) for _ in range(b.n_ins)]
        baro = BaroAltimeter(br, seeds[-1]) if br is not None else None
        src = cls(bank, GnssReceiver(g, seeds[-2]), baro, filters,
                  DEFAULT_ALERT_DELAY_S if b.alert_delay_s is None else b.alert_delay_s)
        src.seed = sd
        return src

    # -- one navigation step -------------------------------------------------------------
    def _ins_at(self, i: int, t_s: float) -> NavSolution | None:
        for sol in reversed(self._buffer[i]):
            if abs(sol.t_s - t_s) <= 1e-6:
                return sol
        return None

    def _gate_events(self, t_s: float, groups: list[GroupResult]) -> None:
        for g in groups:
            if g.name not in self._gate_open:
                continue
            was = self._gate_open[g.name]
            if was and not g.used:
                self.events.append({"t_s": round(t_s, 3), "unit": "gnss", "kind": "detected",
                                    "stage": "innovation_gate",
                                    "reason": f"{g.name} rejected: max |ν|/σ "
                                              f"{np.max(np.abs(g.innovation) / np.sqrt(np.diag(g.S))):.1f}"})
            elif not was and g.used:
                self.events.append({"t_s": round(t_s, 3), "unit": "gnss", "kind": "reconfigured",
                                    "stage": "innovation_gate", "reason": f"{g.name} accepted again"})
            self._gate_open[g.name] = g.used

    def update(self, truth: AircraftState) -> NavSolution:
        """Advance to ``truth.t_s``: INS, prediction, baro, GNSS, feedback; return the output."""
        ins = self.bank.update(truth)
        t = truth.t_s
        prev = self._prev_truth
        for i, f in enumerate(self.filters):
            if prev is None:
                f.initialise(ins[i])
            elif t > prev.t_s:
                f.predict(self._prev_ins[i], prev, t - prev.t_s)
            buf = self._buffer[i]
            buf.append(ins[i])
            while buf and buf[0].t_s < t - _BUFFER_S:
                buf.pop(0)
        reading = self.baro.update(truth) if self.baro is not None else None
        if reading is not None:
            for i, f in enumerate(self.filters):
                f.baro_update(reading, ins[i])
        fixes = self.receiver.update(truth)
        for fix in fixes:
            groups = []
            for i, f in enumerate(self.filters):
                at = self._ins_at(i, fix.t_s)
                if at is None:
                    continue
                g = f.gnss_update(fix, at)
                if i == 0:
                    groups = g
                    for r in g:
                        self.nis_log.append((fix.t_s, r.name, r.nis, r.innovation.size))
                if any(r.used for r in g):
                    self.bank.correct(i, f.take_feedback())
                    ins[i] = self.bank.output(i, truth)
                    self._buffer[i][-1] = ins[i]
            if groups:
                self._gate_events(t, groups)
                self.last_groups = groups
                if groups[0].used:
                    self._last_fix_used_s = fix.t_s
        self._prev_truth, self._prev_ins = truth, ins
        return self.solution(truth, ins)

    def solution(self, truth: AircraftState, ins: list[NavSolution]) -> NavSolution:
        """Unit 0's corrected output, its covariance, ANP and the logged columns."""
        f = self.filters[0]
        lat, lon, alt, v, roll, pitch, hdg = corrected(ins[0], f.x[:9])
        P = f.P
        anp = horizontal_radius(P[0, 0], P[1, 1], P[0, 1])
        rm, rn = radii_m(truth.lat_rad)
        mode = 0 if truth.t_s - self._last_fix_used_s <= 2.0 * self.receiver.period_s + \
            self.receiver.spec.latency_s + 1e-6 else 1
        errors = {
            "anp_m": anp, "nav_mode": float(mode), "ins_used": 1.0,
            "nse_east_m": (lon - truth.lon_rad) * (rn + truth.alt_m) * math.cos(truth.lat_rad),
            "nse_north_m": (lat - truth.lat_rad) * (rm + truth.alt_m),
            "nse_up_m": alt - truth.alt_m,
            "att_err_roll_deg": math.degrees(roll - truth.roll_rad),
            "att_err_pitch_deg": math.degrees(pitch - truth.pitch_rad),
            "att_err_heading_deg": math.degrees(math.remainder(hdg - truth.heading_rad,
                                                               2 * math.pi)),
            "sigma_heading_deg": math.degrees(math.sqrt(max(P[8, 8], 0.0))),
        }
        return NavSolution(truth.t_s, lat, lon, alt, v, roll, pitch, hdg, errors,
                           pos_cov_enu_m2=P[:3, :3].copy())


__all__ = ["InsGnssNavigation", "baro_spec", "corrected", "gnss_spec"]
