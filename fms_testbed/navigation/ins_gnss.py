"""INS/GNSS navigation source: INS unit(s), a GNSS receiver and a baro on the truth side, and a
loosely coupled error-state Kalman filter per INS (:mod:`.ins_filter`) — what guidance flies on.

Scenario block (``navigation:``, validated by :class:`~fms_testbed.config.navigation.InsGnssBlock`)::

    source: ins_gnss
    imu: STIM300                 # preset, .yaml path or mapping (every unit)
    n_ins: 1
    seed: 7                      # optional; otherwise the run seed
    gnss: {rate_hz: 1, latency_s: 0.1, pos_markov_sigma_m: [1, 1, 2], ...,
           outages: [{start_s: 300, end_s: 360}], outliers: [...], ramps: [...]}
    baro: {markov_sigma_m: 5, markov_tau_s: 1800, white_sigma_m: 0.5, rate_hz: 1}   # or null
    filter: {gate_sigma: 5, unmodelled_tau_s: 20, method: picard}
    alert_delay_s: 2

One :meth:`InsGnssNavigation.update` per navigation step: the INS units advance (truth ⊕ their
errors), each filter predicts over the step, any delivered GNSS fix is used (innovation-gated,
delayed-measurement correction, Joseph form) and the INS block of each estimate is fed back to
its unit, then the baro reading; with two or three units the two-stage identification of seed
001 (:mod:`.fdi`) runs, and the output is the mean of the units in use (unit 0 alone for one
unit) with the filters' position covariance (``pos_cov_enu_m2``) and ANP. Logged columns
(``NavSolution.errors``): ``anp_m`` (95 % horizontal radius of P, m), ``nav_mode``
(:data:`~.monitor.NAV_MODES`), ``ins_used`` (bit mask of the units in use),
``nse_{east,north,up}_m`` (output - truth, truth side), ``att_err_{roll,pitch,heading}_deg``
(output - truth), ``sigma_heading_deg`` (filter) and, with identification,
``nse_vote_{east,north}_m`` (the majority-voting baseline) and ``fdi_nu`` (ν12 + 2 ν13 + 4 ν23).
Events (``events``: faults injected, gate rejections, detection, isolation, exclusion,
reconfiguration) go to ``summary.json``; faults come from scenario events (:meth:`inject`).

Seeds: ``navigation.seed`` or the run seed → :func:`~.ins_bank.derive_seeds` → one stream each
for the GNSS receiver, the baro and every INS unit (in that order: adding a unit changes no other
realisation).
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
from fms_testbed.core.units import G0_MPS2
from fms_testbed.navigation.ins_bank import InsBank, derive_seeds
from fms_testbed.navigation.faults import check_fault, inject
from fms_testbed.navigation.fdi import (FaultTolerantEstimator, FdiTuning, SensorComparator,
                                        TwoStageFdi,
                                        channel_sigmas, declared_sensor_noise)
from fms_testbed.navigation.ins_filter import (FilterTuning, GroupResult, InsGnssFilter, enu_difference_m,
                                               predict_filters)
from fms_testbed.navigation.monitor import DEFAULT_ALERT_DELAY_S
from fms_testbed.navigation.reference_description import ReferenceDescriptionMonitor
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


def _mean_solution(sols: list[tuple]) -> tuple:
    """Mean of corrected solutions (lat, lon, alt, V, roll, pitch, heading); circular mean of
    heading."""
    if len(sols) == 1:
        return sols[0]
    a = list(zip(*sols))
    hdg = math.atan2(sum(math.sin(h) for h in a[6]), sum(math.cos(h) for h in a[6]))
    n = len(sols)
    return (sum(a[0]) / n, sum(a[1]) / n, sum(a[2]) / n, sum(a[3]) / n, sum(a[4]) / n,
            sum(a[5]) / n,
            hdg % (2 * math.pi))


class InsGnssNavigation:
    """INS/GNSS navigation source; see the module docstring for the scenario keys.

    Parameters
    ----------
    bank : the INS units;  receiver : the GNSS receiver;  baro : the baro (or None)
    filters : one filter per unit;  alert_delay_s : RNP-alert persistence, s
    fdi : the two-stage identification over the units (None: one unit, or no monitoring)
    """

    def __init__(self, bank: InsBank, receiver: GnssReceiver, baro: BaroAltimeter | None,
                 filters: list[InsGnssFilter], alert_delay_s: float = DEFAULT_ALERT_DELAY_S,
                 fdi: TwoStageFdi | None = None):
        self.bank, self.receiver, self.baro, self.filters = bank, receiver, baro, filters
        self.alert_delay_s = float(alert_delay_s)
        self.fdi = fdi
        # seed 001's fault-tolerant estimator (channel tests, baro exclusion, vertical freezing)
        self.ft = FaultTolerantEstimator(filters, fdi.tuning if fdi is not None else FdiTuning())
        # Zaitseva's reference-description monitor (three units; set by from_spec)
        self.refdesc: ReferenceDescriptionMonitor | None = None
        self.comparator: SensorComparator | None = None     # built at the second step (dt)
        # each unit's declared (accelerometer, gyro) scale-factor + misalignment variance: the
        # attitude error its filter does not model, in the comparison σ (.fdi.channel_sigmas)
        self._unmodelled_var = [(float(a), float(g)) for a, g in
                                declared_sensor_noise([f.imu for f in filters], 1.0)[1]]
        self.events: list[dict] = []
        self._prev_truth: AircraftState | None = None
        self._prev_ins: list[NavSolution] = []
        self._buffer: list[list[NavSolution]] = [[] for _ in filters]
        self._gate_open = [{"gnss_pos": True, "gnss_vel": True, "baro": True} for _ in filters]
        self._last_fix_used_s = -math.inf
        self._prev_sensor_t: float | None = None
        self.nis_log: list[tuple[float, str, float, int]] = []   # unit 0: (t_s, group, NIS, dim)
        self.fused = True        # one compiled prediction for all filters (False: one per filter)

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
        seeds = derive_seeds(sd, b.n_ins + 2)        # [GNSS, baro, INS 1, INS 2, ...]
        g, br = gnss_spec(b.gnss), baro_spec(b.baro)
        tuning = FilterTuning(b.filter.gate_sigma, b.filter.unmodelled_tau_s, b.filter.method)
        bank = InsBank([imu] * b.n_ins, seeds[2:], method=b.filter.method)
        filters = [InsGnssFilter(imu, g, br, tuning) for _ in range(b.n_ins)]
        baro = BaroAltimeter(br, seeds[1]) if br is not None else None
        fdi = TwoStageFdi(b.n_ins) if b.n_ins > 1 else None
        src = cls(bank, GnssReceiver(g, seeds[0]), baro, filters,
                  DEFAULT_ALERT_DELAY_S if b.alert_delay_s is None else b.alert_delay_s, fdi)
        src.seed = sd
        if b.n_ins == 3:
            src.refdesc = ReferenceDescriptionMonitor([f.imu for f in filters])
        return src

    # -- faults ----------------------------------------------------------------------------
    def check_fault(self, fault: dict) -> None:
        """Raise ConfigError when a scenario fault names a unit this source does not have."""
        check_fault(fault, len(self.bank), self.baro is not None)

    def inject(self, fault: dict, t_s: float) -> None:
        """Inject a scenario fault at ``t_s`` (s) on the truth side
        (:mod:`fms_testbed.navigation.faults`); logs a ``fault_injected`` event."""
        self.events.append(inject(self, fault, t_s))

    # -- one navigation step ---------------------------------------------------------------
    def _ins_at(self, i: int, t_s: float) -> NavSolution | None:
        for sol in reversed(self._buffer[i]):
            if abs(sol.t_s - t_s) <= 1e-6:
                return sol
        return None

    def _gate_events(self, i: int, t_s: float, groups: list[GroupResult]) -> None:
        for g in groups:
            sensor = "baro" if g.name == "baro" else "gnss"
            unit = sensor if len(self.filters) == 1 else f"{sensor}@ins{i + 1}"
            was = self._gate_open[i][g.name]
            if was and not g.used:
                r = np.max(np.abs(g.innovation) / np.sqrt(np.diag(g.S)))
                self.events.append({"t_s": round(t_s, 3), "unit": unit, "kind": "detected",
                                    "stage": "innovation_gate",
                                    "reason": f"{g.name} rejected: max |ν|/σ {r:.1f}"})
            elif not was and g.used:
                self.events.append({"t_s": round(t_s, 3), "unit": unit, "kind": "reconfigured",
                                    "stage": "innovation_gate", "reason": f"{g.name} accepted again"})
            self._gate_open[i][g.name] = g.used

    def update(self, truth: AircraftState) -> NavSolution:
        """Advance to ``truth.t_s``: INS, prediction, GNSS (feedback), baro, identification;
        return the output."""
        ins = self.bank.update(truth)
        t = truth.t_s
        prev = self._prev_truth
        if prev is None:
            for i, f in enumerate(self.filters):
                f.initialise(ins[i])
        elif t > prev.t_s:
            if self.fused:
                predict_filters(self.filters, self._prev_ins, prev, t - prev.t_s)
            else:
                for i, f in enumerate(self.filters):
                    f.predict(self._prev_ins[i], prev, t - prev.t_s)
        for i in range(len(self.filters)):
            buf = self._buffer[i]
            buf.append(ins[i])
            while buf and buf[0].t_s < t - _BUFFER_S:
                buf.pop(0)
        for fix in self.receiver.update(truth):
            for i, f in enumerate(self.filters):
                at = self._ins_at(i, fix.t_s)
                if at is None:
                    continue
                self.events += self.ft.set_vertical(i, t, True)      # altitude measured
                groups = f.gnss_update(fix, at)
                self.events += self.ft.check(i, t, groups)
                for r in groups:
                    if i == 0:
                        self.nis_log.append((fix.t_s, r.name, r.nis, r.innovation.size))
                    if self.fdi is not None:
                        self.fdi.add_innovation(i, t, r.nis, r.innovation.size)
                if any(r.used for r in groups):
                    self.bank.correct(i, f.take_feedback())
                    ins[i] = self.bank.output(i, truth)
                    self._buffer[i][-1] = ins[i]
                    self._last_fix_used_s = fix.t_s
                self._gate_events(i, t, groups)
        reading = self.baro.update(truth) if self.baro is not None else None
        if reading is not None:
            for i, f in enumerate(self.filters):
                if self.ft.baro_excluded[i]:
                    continue                       # the baro channel's gain column is zero
                g = f.baro_update(reading, ins[i])
                self._gate_events(i, t, [g])
                self.events += self.ft.check(i, t, [g])
        self._prev_truth, self._prev_ins = truth, ins
        return self.solution(truth, ins)

    def _sensor_pairs(self, truth: AircraftState) -> tuple:
        """Sensor-level stage 1 on the units' raw IMU outputs over the last step."""
        prev = self._prev_sensor_t
        self._prev_sensor_t = truth.t_s
        if prev is None or truth.t_s <= prev:
            return (0, 0, 0)
        dt = truth.t_s - prev
        if self.comparator is None:
            q, sf = declared_sensor_noise([f.imu for f in self.filters], dt)
            self.comparator = SensorComparator(len(self.bank), q, dt, sf, self.fdi.tuning)
        return self.comparator.update(truth.t_s, self.bank.sensor_errors(truth, dt),
                                      truth.f_body_mps2, (truth.p_rps, truth.q_rps, truth.r_rps))

    def _comparison(self, sols: list[tuple]) -> list[np.ndarray]:
        """Comparison vectors y_i (position ENU m from unit 0's, velocity, roll, pitch, heading)."""
        lat0, lon0, h0 = sols[0][0], sols[0][1], sols[0][2]
        out = []
        for s in sols:
            y = np.empty(9)
            y[:3] = enu_difference_m(s[0], s[1], s[2], lat0, lon0, h0)
            y[3:6] = s[3]
            y[6], y[7], y[8] = s[4], s[5], s[6]
            out.append(y)
        return out

    def _reference_description(self, truth: AircraftState, ins: list[NavSolution],
                               sols: list[tuple], used: list[int], extra: dict) -> list[int]:
        """Run the reference-description monitor against the integrated solution of the units
        in ``used``; log its output (``nse_ref_*``, ``ins_used_ref``, ``refdesc_d_ins*``) and
        return the units both it and the two-stage identification keep (``used`` if none)."""
        base = used or list(range(len(sols)))
        P_int = sum(self.filters[i].P for i in base) / len(base)
        self.events += self.refdesc.update(truth, ins, _mean_solution([sols[i] for i in base]),
                                           P_int, [f.P for f in self.filters],
                                           self.bank.take_fed_back())
        ref_used = [i for i in range(len(sols)) if self.refdesc.used[i]]
        ref = _mean_solution([sols[i] for i in ref_used])
        rm, rn = radii_m(truth.lat_rad)
        extra["nse_ref_east_m"] = ((ref[1] - truth.lon_rad) * (rn + truth.alt_m)
                                   * math.cos(truth.lat_rad))
        extra["nse_ref_north_m"] = (ref[0] - truth.lat_rad) * (rm + truth.alt_m)
        extra["ins_used_ref"] = float(sum(1 << i for i in ref_used))
        for i, d in enumerate(self.refdesc.d):
            extra[f"refdesc_d_ins{i + 1}"] = float(d)
        both = [i for i in used if i in ref_used]
        return both or used

    def solution(self, truth: AircraftState, ins: list[NavSolution]) -> NavSolution:
        """The output: the mean of the units in use (unit 0 alone without identification), the
        mean of their covariances, ANP, and the logged columns."""
        sols = [corrected(ins[i], f.x[:9]) for i, f in enumerate(self.filters)]
        used = list(range(len(sols)))
        extra: dict[str, float] = {}
        coasting = (math.isfinite(self._last_fix_used_s)      # not before the first fix
                    and truth.t_s - self._last_fix_used_s > 2.0 * self.receiver.period_s
                    + self.receiver.spec.latency_s + 1e-6)
        for i in range(len(self.filters)):         # no altitude measurement: vertical frozen
            has_alt = not coasting or (self.baro is not None and not self.ft.baro_excluded[i])
            self.events += self.ft.set_vertical(i, truth.t_s, has_alt)
        if self.fdi is not None:
            y = self._comparison(sols)
            n_load = float(np.linalg.norm(truth.f_body_mps2)) / G0_MPS2
            sig = [channel_sigmas(f.P, self._unmodelled_var[i], sols[i][4], sols[i][5], n_load)
                   for i, f in enumerate(self.filters)]
            mask = self.ft.mask(self.fdi.state.used)
            self.events += self.fdi.update(truth.t_s, y, sig, self._sensor_pairs(truth), mask)
            used = [i for i, u in enumerate(self.fdi.state.used) if u]
            voted = self.fdi.vote(y, sig, mask)
            vote = _mean_solution([sols[i] for i in voted])
            rm, rn = radii_m(truth.lat_rad)
            extra = {"ins_used_vote": float(sum(1 << i for i in voted)),
                     "nse_vote_east_m": (vote[1] - truth.lon_rad) * (rn + truth.alt_m)
                     * math.cos(truth.lat_rad),
                     "nse_vote_north_m": (vote[0] - truth.lat_rad) * (rm + truth.alt_m),
                     "fdi_nu": float(self.fdi.nu[0] + 2 * self.fdi.nu[1] + 4 * self.fdi.nu[2])}
        if self.refdesc is not None:
            used = self._reference_description(truth, ins, sols, used, extra)
        valid = bool(used)
        pick = used if valid else [int(np.argmin([np.trace(f.P[:3, :3]) for f in self.filters]))]
        lat, lon, alt, v, roll, pitch, hdg = _mean_solution([sols[i] for i in pick])
        P = (self.filters[pick[0]].P if len(pick) == 1
             else sum(self.filters[i].P for i in pick) / len(pick))
        anp = horizontal_radius(P[0, 0], P[1, 1], P[0, 1])
        rm, rn = radii_m(truth.lat_rad)
        coast = truth.t_s - self._last_fix_used_s > 2.0 * self.receiver.period_s + \
            self.receiver.spec.latency_s + 1e-6
        mode = 2 if not valid else (1 if coast else 0)
        errors = {
            "anp_m": anp, "nav_mode": float(mode),
            "ins_used": float(sum(1 << i for i in used)),
            "nse_east_m": (lon - truth.lon_rad) * (rn + truth.alt_m) * math.cos(truth.lat_rad),
            "nse_north_m": (lat - truth.lat_rad) * (rm + truth.alt_m),
            "nse_up_m": alt - truth.alt_m,
            "att_err_roll_deg": math.degrees(roll - truth.roll_rad),
            "att_err_pitch_deg": math.degrees(pitch - truth.pitch_rad),
            "att_err_heading_deg": math.degrees(math.remainder(hdg - truth.heading_rad,
                                                               2 * math.pi)),
            "sigma_heading_deg": math.degrees(math.sqrt(max(P[8, 8], 0.0))),
            **extra,
        }
        return NavSolution(truth.t_s, lat, lon, alt, v, roll, pitch, hdg, errors,
                           pos_cov_enu_m2=P[:3, :3].copy(), valid=valid)


__all__ = ["InsGnssNavigation", "baro_spec", "corrected", "gnss_spec"]
