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
001 (:mod:`.fdi`) runs, and the output is the mean of the units in use — with three units
weighted by the reference description's ranking (:func:`~.reference_description.rank_weights`)
once it has distances — (unit 0 alone for one
unit) with the filters' position covariance (``pos_cov_enu_m2``) and ANP. Logged columns
(``NavSolution.errors``): ``anp_m`` (95 % horizontal radius of P, m), ``nav_mode``
(:data:`~.monitor.NAV_MODES`), ``ins_used`` (bit mask of the units in use),
``nse_{east,north,up}_m`` (output - truth, truth side), ``att_err_{roll,pitch,heading}_deg``
(output - truth), ``sigma_heading_deg`` (filter) and, with identification,
``nse_vote_{east,north}_m`` (the majority-voting baseline on the raw outputs: the units
flown free beside them, :meth:`InsGnssNavigation._vote_raw`) and ``fdi_nu`` (ν12 + 2 ν13 + 4 ν23).
Events (``events``: faults injected, gate rejections, detection, isolation, exclusion,
reconfiguration) go to ``summary.json``; faults come from scenario events (:meth:`inject`).

Seeds: ``navigation.seed`` or the run seed → :func:`~.ins_bank.derive_seeds` → one stream each
for the GNSS receiver, the baro and every INS unit (in that order: adding a unit changes no other
realisation).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import ValidationError

from fms_testbed.config.navigation import InsGnssBlock
from fms_testbed.config.yamlfile import validation_message
from fms_testbed.core.contracts import NavigationSourceBase
from fms_testbed.core.earth import radii_and_derivatives, radii_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import G0_MPS2
from fms_testbed.navigation.inertial.bank import StrapdownBank, set_lever_arm
from fms_testbed.navigation.ins_bank import InsBank, derive_seeds
from fms_testbed.navigation.faults import check_fault, inject
from fms_testbed.navigation.fdi import (FaultTolerantEstimator, FdiTuning, FreeEnvelope,
                                        SensorComparator, TwoStageFdi, channel_mask,
                                        channel_sigmas, declared_sensor_noise)
from fms_testbed.navigation.ins_filter import FilterTuning, GroupResult, InsGnssFilter, _w_eb
from fms_testbed.navigation.prediction import PredictionInterval, can_share_prediction
from fms_testbed.navigation.monitor import DEFAULT_ALERT_DELAY_S
from fms_testbed.navigation.recording import SensorRecorder
from fms_testbed.navigation.reference_description import ReferenceDescriptionMonitor, rank_weights
from fms_testbed.sensors.baro import BaroAltimeter, BaroSpec
from fms_testbed.sensors.gnss import GnssReceiver, GnssSpec, Interval, OutlierBurst, Ramp
from fms_testbed.sensors.sins.analysis import horizontal_radius
from fms_testbed.sensors.sins.euler import eps_to_euler_errors_scalar
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
        tuple(Ramp(_interval(r), tuple(r.rate_mps)) for r in block.ramps),
        tuple(block.antenna_lever_arm_m), block.time_tag_error_s, block.time_tag_sigma_s)


def baro_spec(block) -> BaroSpec | None:
    """:class:`BaroSpec` (SI) from a validated ``navigation.baro`` block (None: no baro)."""
    if block is None:
        return None
    return BaroSpec(block.markov_sigma_m, block.markov_tau_s, block.white_sigma_m, block.rate_hz,
                    math.inf if block.failed_from_s is None else block.failed_from_s)


@njit(cache=True)
def _corrected_many(O, DX):
    """:func:`corrected` for k units at once, and their comparison vectors.

    O (k, 9): the units' outputs [lat rad, lon rad, alt m, V E N U m/s, roll, pitch, heading
    rad]; DX (k, 9): their filters' estimated errors [δp ENU m, δV m/s, ε rad]. Returns (C, Y):
    C (k, 9) the corrected outputs in the layout of O, Y (k, 9) the comparison vectors of
    seed 001's stage 1 (position ENU m from unit 0's corrected position, velocity, roll, pitch,
    heading)."""
    k = O.shape[0]
    C = np.empty((k, 9))
    Y = np.empty((k, 9))
    two_pi = 2.0 * math.pi
    for i in range(k):
        lat, h = O[i, 0], O[i, 2]
        rm, rn, _, _ = radii_and_derivatives(lat)
        d_roll, d_pitch, d_head = eps_to_euler_errors_scalar(DX[i, 6], DX[i, 7], DX[i, 8],
                                                             O[i, 7], O[i, 8])
        C[i, 0] = lat - DX[i, 1] / (rm + h)
        C[i, 1] = O[i, 1] - DX[i, 0] / ((rn + h) * math.cos(lat))
        C[i, 2] = h - DX[i, 2]
        for j in range(3):
            C[i, 3 + j] = O[i, 3 + j] - DX[i, 3 + j]
        C[i, 6] = O[i, 6] - d_roll
        C[i, 7] = O[i, 7] - d_pitch
        C[i, 8] = (O[i, 8] - d_head) % two_pi
    for i in range(k):
        rm, rn, _, _ = radii_and_derivatives(C[i, 0])
        Y[i, 0] = (C[i, 1] - C[0, 1]) * (rn + C[i, 2]) * math.cos(C[i, 0])
        Y[i, 1] = (C[i, 0] - C[0, 0]) * (rm + C[i, 2])
        Y[i, 2] = C[i, 2] - C[0, 2]
        for j in range(3, 9):
            Y[i, j] = C[i, j]
    return C, Y


def corrected(sol: NavSolution, dx9: np.ndarray) -> tuple[float, float, float, np.ndarray,
                                                          float, float, float]:
    """(lat rad, lon rad, alt m, V (3,) m/s, roll, pitch, heading rad): an INS output minus an
    estimated error (δp ENU m, δV m/s, ε rad; Euler errors by paper eq. 6.10, the scalar form of
    :func:`~fms_testbed.sensors.sins.euler.eps_to_euler_errors`) — one unit of
    :func:`_corrected_many`."""
    O = np.array([[sol.lat_rad, sol.lon_rad, sol.alt_m, *sol.v_enu_mps, sol.roll_rad,
                   sol.pitch_rad, sol.heading_rad]])
    c = _corrected_many(O, np.asarray(dx9, float)[None, :9])[0][0]
    return c[0], c[1], c[2], c[3:6], c[6], c[7], c[8]


@njit(cache=True)
def _mean_rows(C, units):
    """The mean of rows ``units`` of C (k, 9) corrected outputs (:func:`_corrected_many`
    layout), heading by its circular mean."""
    m = np.zeros(9)
    sh = ch = 0.0
    for i in units:
        for j in range(8):
            m[j] += C[i, j]
        sh += math.sin(C[i, 8])
        ch += math.cos(C[i, 8])
    n = units.size
    for j in range(8):
        m[j] /= n
    m[8] = math.atan2(sh, ch) % (2.0 * math.pi)
    return m


def _mean_solution(C: np.ndarray, units: list[int]) -> tuple:
    """(lat rad, lon rad, alt m, V (3,) m/s, roll, pitch, heading rad): the mean of the corrected
    outputs ``C`` (k, 9) of ``units`` (circular mean of heading; one unit: its own)."""
    c = C[units[0]] if len(units) == 1 else _mean_rows(C, np.array(units, np.int64))
    return c[0], c[1], c[2], c[3:6], c[6], c[7], c[8]


def weighted_solution(C: np.ndarray, units: list[int], w: np.ndarray) -> tuple:
    """(lat rad, lon rad, alt m, V (3,) m/s, roll, pitch, heading rad): Σ w_i C_i over ``units``
    of the corrected outputs ``C`` (k, 9) with weights ``w`` (summing to 1), heading by the
    weighted circular mean atan2(Σ w sin ψ, Σ w cos ψ).

    Parameters
    ----------
    C : (k, 9) corrected outputs (:func:`_corrected_many` layout);  units : their rows
    w : (len(units),) weights, dimensionless
    """
    rows = C[units]
    c = np.empty(9)
    c[:8] = w @ rows[:, :8]
    c[8] = math.atan2(w @ np.sin(rows[:, 8]), w @ np.cos(rows[:, 8])) % (2.0 * math.pi)
    return c[0], c[1], c[2], c[3:6], c[6], c[7], c[8]


def alignment_s(bank) -> float | None:
    """The stationary alignment's duration (s) of a strapdown bank, whose white-noise means are
    in the initial errors; None for another bank or alignment.

    Parameters
    ----------
    bank : the INS bank
    """
    if isinstance(bank, StrapdownBank) and bank.alignment == "stationary":
        return bank.alignment_s
    return None


class InsGnssNavigation(NavigationSourceBase):
    """INS/GNSS navigation source; see the module docstring for the scenario keys.

    Parameters
    ----------
    bank : the INS units;  receiver : the GNSS receiver;  baro : the baro (or None)
    filters : one filter per unit;  alert_delay_s : RNP-alert persistence, s
    fdi : the two-stage identification over the units (None: one unit, or no monitoring)
    """

    #: per-frame JSBSim samples the truth side needs (none: it reads the outer-step state)
    frame_properties: tuple[tuple[str, float], ...] = ()

    def __init__(self, bank: InsBank, receiver: GnssReceiver, baro: BaroAltimeter | None,
                 filters: list[InsGnssFilter], alert_delay_s: float = DEFAULT_ALERT_DELAY_S,
                 fdi: TwoStageFdi | None = None):
        self.bank, self.receiver, self.baro, self.filters = bank, receiver, baro, filters
        self.frame_properties = tuple(bank.frame_properties)
        self.truth_model = "strapdown" if isinstance(bank, StrapdownBank) else "linear"
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
        self._anp_key: tuple | None = None
        self._mean_P_cache: dict[tuple, tuple] = {}
        self._anp = math.nan
        self._interval: PredictionInterval | None = None      # built at the first step
        self.recorder: SensorRecorder | None = None   # navigation.record_sensors (its tables)
        # the majority-voting baseline's raw outputs: the same units flown free (no feedback;
        # the same IMU errors, seeds and faults) and their declared envelope (set by from_spec)
        self.free_bank: InsBank | None = None
        self.free_env: FreeEnvelope | None = None
        self._free_out: list[NavSolution] = []

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
        tuning = FilterTuning(b.filter.gate_sigma, b.filter.unmodelled_tau_s, b.filter.method,
                              b.filter.predict_interval_s, b.filter.predict_rotation_deg,
                              b.filter.reset_after)
        def make_bank():
            if b.truth_model == "strapdown":
                return StrapdownBank([imu] * b.n_ins, seeds[2:], alignment=b.alignment)
            return InsBank([imu] * b.n_ins, seeds[2:], method=b.filter.method,
                           matrices_dt_s=b.matrices_dt_s,
                           matrices_rotation_deg=b.matrices_rotation_deg)
        bank = make_bank()
        filters = [InsGnssFilter(imu, g, br, tuning) for _ in range(b.n_ins)]
        baro = BaroAltimeter(br, seeds[1]) if br is not None else None
        fdi = TwoStageFdi(b.n_ins) if b.n_ins > 1 else None
        src = cls(bank, GnssReceiver(g, seeds[0]), baro, filters,
                  DEFAULT_ALERT_DELAY_S if b.alert_delay_s is None else b.alert_delay_s, fdi)
        src.seed = sd
        if b.n_ins > 1:
            src.free_bank, src.free_env = make_bank(), FreeEnvelope(imu)
        src.ft.adaptive = b.adaptive
        src.truth_model = b.truth_model
        if b.record_sensors:
            src.recorder = SensorRecorder(b.imu, dict(spec.get("gnss") or {}))
        if b.n_ins == 3:
            src.refdesc = ReferenceDescriptionMonitor([f.imu for f in filters])
        return src

    def install_imu(self, lever_arm_m) -> None:
        """The IMU's position from the CG (the aircraft file's ``imu_lever_arm_m``, body axes,
        m), set before the first update; the linear model has none."""
        if isinstance(self.bank, StrapdownBank):
            set_lever_arm(self.bank, lever_arm_m)
            if self.free_bank is not None:
                set_lever_arm(self.free_bank, lever_arm_m)
            self.frame_properties = tuple(self.bank.frame_properties)

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

    def _predict(self, prev: AircraftState, truth: AircraftState, ins: list[NavSolution],
                 boundary: bool) -> None:
        """Propagate the filters over the step from ``prev`` to ``truth`` (``ins``: the INS
        outputs at its end): added to the current interval
        (:class:`~.prediction.PredictionInterval`), which is discretised and applied when
        ``boundary`` (a measurement now, or a GNSS epoch: the delayed correction needs a step
        boundary at a fix's time of validity) or when it has reached
        ``filter.predict_interval_s``; every step and one filter at a time (F at the step's
        start) when they cannot share the call or ``fused`` is off (the reference path)."""
        dt_s = truth.t_s - prev.t_s
        meas = [self.bank.measured(i) for i in range(len(self.filters))]
        if not self.fused or not can_share_prediction(self.filters):
            for i, f in enumerate(self.filters):
                f.predict(self._prev_ins[i], meas[i][0], meas[i][1], dt_s)
            return
        f_b = sum(m[0] for m in meas) / len(meas)
        w_ib = sum(m[1] for m in meas) / len(meas)
        iv = self._interval
        if iv is None or iv.filters is not self.filters:
            iv = self._interval = PredictionInterval(self.filters)
            iv.start(self._prev_ins, prev.t_s, f_b, w_ib)
        full = iv.add(f_b, w_ib, dt_s)
        if boundary or full:
            iv.flush(ins, truth.t_s, f_b, w_ib)

    def update(self, truth: AircraftState, frames=None) -> NavSolution:
        """Advance to ``truth.t_s``: INS, prediction, GNSS (feedback), baro, identification;
        return the output."""
        ins = self.bank.update(truth, frames)
        if self.free_bank is not None:
            self._free_out = self.free_bank.update(truth, frames)
        t = truth.t_s
        prev = self._prev_truth
        fixes = self.receiver.update(truth)
        reading = self.baro.update(truth) if self.baro is not None else None
        if self.recorder is not None:
            self.recorder.record(truth, prev, fixes, self.bank)
        if prev is None:
            for i, f in enumerate(self.filters):
                f.initialise(ins[i], alignment_s(self.bank))
            if self.recorder is not None:
                self.recorder.start(ins[0], self.filters[0].P, alignment_s(self.bank))
        elif t > prev.t_s:
            # an interval ends where a measurement is valid: at a GNSS epoch (the fix, delivered
            # later, is then used at the filters' time, its time of validity) and at a baro
            # reading
            self._predict(prev, truth, ins, reading is not None
                          or self.receiver.last_epoch_s == t)
        for i in range(len(self.filters)):
            buf = self._buffer[i]
            buf.append(ins[i])
            while buf and buf[0].t_s < t - _BUFFER_S:
                buf.pop(0)
        for fix in fixes:
            for i, f in enumerate(self.filters):
                at = self._ins_at(i, fix.t_s)
                if at is None:
                    continue
                self.events += self.ft.set_vertical(i, t, True)      # altitude measured
                groups = f.gnss_update(fix, at, _w_eb(at, self.bank.measured(i)[1]))
                self.events += self.ft.check(i, t, groups)
                for r in groups:
                    if i == 0:
                        self.nis_log.append((fix.t_s, r.name, r.nis, r.innovation.size))
                    if self.fdi is not None:
                        self.fdi.add_innovation(i, t, r.nis, r.innovation.size)
                if any(r.used for r in groups):
                    dx = f.take_feedback()                 # the estimate at the filter's time
                    iv = self._interval
                    if iv is not None and iv.filters is self.filters and iv.dt_s > 0.0:
                        dx = iv.ins_transition() @ dx      # ... carried to now
                    self.bank.correct(i, dx)
                    ins[i] = self.bank.output(i, truth)
                    self._buffer[i][-1] = ins[i]
                    self._last_fix_used_s = fix.t_s
                self._gate_events(i, t, groups)
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
        if isinstance(self.bank, StrapdownBank):
            # the units' raw measured outputs: their pair differences are those of the errors
            raw = self.bank.mean + self.bank.comp
            f, w = raw[0, :3], raw[0, 3:]
        else:
            # the linear twin: its units' outputs are truth ⊕ errors, the errors are what it has
            f, w = self.bank.measured(0)
            raw = self.bank.sensor_errors(truth, dt)
        return self.comparator.update(truth.t_s, raw, f, w)

    def _mean_P(self, units: list[int]) -> np.ndarray:
        """(9, 9): the mean over ``units`` of the filters' covariances of the navigation states
        (position, velocity, attitude; one unit: its own). Kept while the filters hold the same
        P arrays (a prediction or a correction replaces them)."""
        Ps = tuple(self.filters[i].P for i in units)
        c = self._mean_P_cache.get(tuple(units))
        if c is not None and all(a is b for a, b in zip(c[0], Ps)):
            return c[1]
        P = Ps[0][:9, :9]
        if len(Ps) > 1:
            P = P.copy()
            for Pi in Ps[1:]:
                P += Pi[:9, :9]
            P /= len(Ps)
        self._mean_P_cache[tuple(units)] = (Ps, P)
        return P

    def _anp_m(self, P: np.ndarray) -> float:
        """ANP (m): the 95 % horizontal radius of P (recomputed only when P's horizontal block
        changed since the last call — between prediction boundaries it does not)."""
        key = (P[0, 0], P[1, 1], P[0, 1])
        if key != self._anp_key:
            self._anp_key, self._anp = key, horizontal_radius(*key)
        return self._anp

    def _reference_description(self, truth: AircraftState, ins: list[NavSolution],
                               C: np.ndarray, used: list[int], extra: dict,
                               nse: tuple, means: dict) -> list[int]:
        """Run the reference-description monitor against the integrated solution of the units
        in ``used``; log its output (``nse_ref_*``, ``ins_used_ref``, ``refdesc_d_ins*``) and
        return the units both it and the two-stage identification keep (``used`` if none).
        ``nse``: (east m per rad of longitude, north m per rad of latitude) at the truth;
        ``means``: the mean solutions of sets of units computed this step (read and added to)."""
        base = used or list(range(len(C)))
        key = tuple(base)
        if key not in means:
            means[key] = _mean_solution(C, base)
        self.events += self.refdesc.update(truth, ins, means[key],
                                           self._mean_P(base), [f.P for f in self.filters],
                                           self.bank.take_fed_back())
        ref_used = [i for i in range(len(C)) if self.refdesc.used[i]]
        key = tuple(ref_used)
        if key not in means:
            means[key] = _mean_solution(C, ref_used)
        ref = means[key]
        extra["nse_ref_east_m"] = (ref[1] - truth.lon_rad) * nse[0]
        extra["nse_ref_north_m"] = (ref[0] - truth.lat_rad) * nse[1]
        extra["ins_used_ref"] = float(sum(1 << i for i in ref_used))
        for i, d in enumerate(self.refdesc.d):
            extra[f"refdesc_d_ins{i + 1}"] = float(d)
        both = [i for i in used if i in ref_used]
        return both or used

    def _vote_raw(self, C: np.ndarray) -> list[int]:
        """Majority voting on the raw outputs (the free units, no GNSS feedback): table 1 of
        this instant at ε_N = k_pair √2 σ_free on the horizontal and attitude channels (the free
        vertical channel excluded), σ_free from :class:`~.fdi.FreeEnvelope` along the
        integrated solution ``C`` (mean of the corrected outputs, :func:`_corrected_many`
        layout); the units it does not name."""
        free = self._free_out
        O = np.array([(s.lat_rad, s.lon_rad, s.alt_m, s.v_enu_mps[0], s.v_enu_mps[1],
                       s.v_enu_mps[2], s.roll_rad, s.pitch_rad, s.heading_rad) for s in free])
        _, Y = _corrected_many(O, np.zeros((len(free), 9)))
        m = _mean_rows(C, np.arange(len(C), dtype=np.int64))
        f_b, w_ib = self.bank.measured(0)
        env = self.free_env
        env.update(free[0].t_s, m[0], m[2], m[3:6], m[6:9], f_b, _w_eb(free[0], w_ib))
        sig = env.sigma()
        return self.fdi.vote(list(Y), [sig] * len(free), channel_mask(True))

    def solution(self, truth: AircraftState, ins: list[NavSolution]) -> NavSolution:
        """The output: the mean of the units in use (weighted by the reference description's
        ranking once it has distances; unit 0 alone without identification), the
        mean of their covariances, ANP, and the logged columns."""
        O = np.array([(s.lat_rad, s.lon_rad, s.alt_m, s.v_enu_mps[0], s.v_enu_mps[1],
                       s.v_enu_mps[2], s.roll_rad, s.pitch_rad, s.heading_rad) for s in ins])
        C, Y = _corrected_many(O, np.array([f.x[:9] for f in self.filters]))
        used = list(range(len(C)))
        extra: dict[str, float] = {}
        means: dict[tuple, tuple] = {}           # mean solution of a set of units, this step
        rm, rn = radii_m(truth.lat_rad)
        nse = ((rn + truth.alt_m) * math.cos(truth.lat_rad), rm + truth.alt_m)
        coast = (truth.t_s - self._last_fix_used_s > 2.0 * self.receiver.period_s
                 + self.receiver.spec.latency_s + 1e-6)
        coasting = math.isfinite(self._last_fix_used_s) and coast   # not before the first fix
        for i in range(len(self.filters)):         # no altitude measurement: vertical frozen
            has_alt = not coasting or (self.baro is not None and not self.ft.baro_excluded[i])
            if has_alt == self.ft.vertical_frozen[i]:
                self.events += self.ft.set_vertical(i, truth.t_s, has_alt)
        if self.fdi is not None:
            y = list(Y)
            n_load = math.sqrt(float(truth.f_body_mps2 @ truth.f_body_mps2)) / G0_MPS2
            sig = [channel_sigmas(f.P, self._unmodelled_var[i], C[i, 6], C[i, 7], n_load)
                   for i, f in enumerate(self.filters)]
            mask = self.ft.mask(self.fdi.state.used)
            self.events += self.fdi.update(truth.t_s, y, sig, self._sensor_pairs(truth), mask)
            used = [i for i, u in enumerate(self.fdi.state.used) if u]
            voted = self._vote_raw(C)
            vote = means[tuple(voted)] = _mean_solution(C, voted)
            extra = {"ins_used_vote": float(sum(1 << i for i in voted)),
                     "nse_vote_east_m": (vote[1] - truth.lon_rad) * nse[0],
                     "nse_vote_north_m": (vote[0] - truth.lat_rad) * nse[1],
                     "fdi_nu": float(self.fdi.nu[0] + 2 * self.fdi.nu[1] + 4 * self.fdi.nu[2])}
        if self.refdesc is not None:
            used = self._reference_description(truth, ins, C, used, extra, nse, means)
        valid = bool(used)
        if valid:
            pick = used
        elif self.refdesc is not None:      # none kept: the closest to its reference description
            pick = [int(self.refdesc.rank[0])]
        else:
            pick = [int(np.argmin([np.trace(f.P[:3, :3]) for f in self.filters]))]
        key = tuple(pick)
        d = None if self.refdesc is None else self.refdesc.d[pick]
        if d is not None and len(pick) > 1 and np.isfinite(d).all():
            # Zaitseva's ranking in the output: the units weighted by their distance to their
            # reference descriptions (the best-ranked weighs most)
            w = rank_weights(d)
            lat, lon, alt, v, roll, pitch, hdg = weighted_solution(C, pick, w)
            P = sum(wi * self.filters[i].P[:9, :9] for wi, i in zip(w, pick))
        else:
            if key not in means:
                means[key] = _mean_solution(C, pick)
            lat, lon, alt, v, roll, pitch, hdg = means[key]
            P = self._mean_P(pick)
        mode = 2 if not valid else (1 if coast else 0)
        errors = {
            "anp_m": self._anp_m(P), "nav_mode": float(mode),
            "ins_used": float(sum(1 << i for i in used)),
            "nse_east_m": (lon - truth.lon_rad) * nse[0],
            "nse_north_m": (lat - truth.lat_rad) * nse[1],
            "nse_up_m": alt - truth.alt_m,
            "att_err_roll_deg": math.degrees(roll - truth.roll_rad),
            "att_err_pitch_deg": math.degrees(pitch - truth.pitch_rad),
            "att_err_heading_deg": math.degrees(math.remainder(hdg - truth.heading_rad,
                                                               2 * math.pi)),
            "sigma_heading_deg": math.degrees(math.sqrt(max(P[8, 8], 0.0))),
            **extra,
        }
        return NavSolution(truth.t_s, lat, lon, alt, v, roll, pitch, hdg, errors,
                           pos_cov_enu_m2=P[:3, :3].copy(), valid=valid,
                           heading_sigma_rad=math.sqrt(max(P[8, 8], 0.0)))


__all__ = ["InsGnssNavigation", "baro_spec", "corrected", "gnss_spec", "weighted_solution"]
