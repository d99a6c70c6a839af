"""Seed 001's identification in one flight: the per-flight face of
:mod:`fms_testbed.navigation.identification`, and the fault-tolerant estimator.

:class:`TwoStageFdi` and :class:`SensorComparator` hold one realisation (R = 1) of
:class:`~.identification.two_stage.TwoStage` and :class:`~.identification.sensor.SensorPairTest`
— the same rules over arrays the Monte-Carlo engine runs on R realisations — and turn what
changed at each step into events. Each unit i gives a comparison vector y_i (position E, N, U m
relative to a common point, velocity E, N, U m/s, roll, pitch, heading rad — its
filter-corrected output) and per-channel σ_i (:func:`channel_sigmas`).

:class:`FaultTolerantEstimator` is seed 001's estimator ż = Φ(ẑ) + K (y − H ẑ) around the units'
filters: the channel test |y_i − ŷ_i| ≤ ε_i (eq. 8), a failed channel's gain row zeroed (the
baro channel latched out; no altitude measurement → the vertical channel frozen and left out of
the comparisons) and the adaptive variant (eq. 7): a component whose residual fails is switched
off (a_i = 0, H̃ = A H) and replaced by artificial noise ζ, and the covariance-trace divergence
test resets the unit's filter.
"""

from __future__ import annotations

import math

import numpy as np

from fms_testbed.navigation.identification.rules import MAJORITY, PAIRS, pair_flags, vote
from fms_testbed.navigation.identification.sensor import SensorPairTest
from fms_testbed.navigation.identification.tuning import FdiTuning
from fms_testbed.navigation.identification.two_stage import BY_TABLE, TwoStage
from fms_testbed.sensors.sins.analysis import SinsOptions, initial_map, step_discrete
from fms_testbed.sensors.sins.analysis import system_matrix as sins_F

VERTICAL_CHANNELS = (2, 5)
"""Comparison channels of the vertical channel: position U and velocity U."""

VERTICAL_STATES = (2, 5, 21)
"""Filter states of the vertical channel: δp_U, δV_U and the baro bias (when there is one)."""

_MASK_VERTICAL = np.ones(9, bool)
_MASK_VERTICAL[list(VERTICAL_CHANNELS)] = False


def channel_sigmas(P: np.ndarray, unmodelled_var: tuple[float, float] = (0.0, 0.0),
                   roll_rad: float = 0.0, pitch_rad: float = 0.0,
                   load_factor: float = 1.0) -> np.ndarray:
    """σ of the 9 comparison channels of one unit (m, m/s, rad).

    Position (3), velocity (3) and roll, pitch, heading (ε components as small angles; roll and
    pitch take the larger tilt σ) from the filter covariance ``P``, plus the attitude error the
    filter does not model: a misaligned or mis-scaled accelerometer triad reads the specific
    force f with an error of about √var_a |f|, absorbed into the tilt; a gyro triad turns a
    rotation away from the aligned attitude into an error of about √var_g × |rotation|. With
    n = |f|/g the load factor and φ, θ roll and pitch (rad)::

        σ_tilt² = P_tilt + var_a n² + var_g (φ² + θ²),   σ_ψ² = P_ψ + var_g (φ² + θ²)

    Parameters
    ----------
    P : (n ≥ 9, n ≥ 9) filter covariance (position m², velocity (m/s)², ε rad²)
    unmodelled_var : (accelerometer, gyro) scale-factor + 2 × misalignment variance per axis,
        dimensionless (:func:`unmodelled_variances`)
    roll_rad, pitch_rad : the unit's attitude, rad;  load_factor : |f| / g
    """
    var_a, var_g = unmodelled_var
    d = np.sqrt(np.maximum(np.asarray(P, float).diagonal()[:9], 0.0))
    d[6] = d[7] = max(d[6], d[7])
    rot2 = var_g * (roll_rad ** 2 + pitch_rad ** 2)
    d[6:8] = np.sqrt(d[6:8] ** 2 + var_a * load_factor ** 2 + rot2)
    d[8] = math.sqrt(d[8] ** 2 + rot2)
    return d


def declared_sensor_noise(imus: list, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The declared unit performance the sensor-level thresholds are built from.

    Parameters
    ----------
    imus : each unit's declared :class:`~fms_testbed.sensors.sins.presets.ImuModel`
    dt_s : sample interval, s (unused: the densities are per second)

    Returns
    -------
    (q_white (n, 6): accelerometer VRW² ((m/s²)²·s) and gyro ARW² (rad²/s) densities,
    sf_var (n, 2): accelerometer and gyro scale-factor + 2 × misalignment variance)
    """
    q = np.array([np.r_[imu.q_psd[3:6], imu.q_psd[6:9]] for imu in imus])
    sf = np.array([unmodelled_variances(imu) for imu in imus])
    return q, sf


def unmodelled_variances(imu) -> tuple[float, float]:
    """(accelerometer, gyro) scale-factor + 2 × misalignment variance per axis of ``imu``, a
    declared :class:`~fms_testbed.sensors.sins.presets.ImuModel`, dimensionless: the 33-state errors
    the filters do not carry."""
    p = imu.p0_var
    return (float(p[15:18].mean() + 2.0 * p[21:27].mean()),
            float(p[18:21].mean() + 2.0 * p[27:33].mean()))


def channel_mask(vertical_frozen: bool) -> np.ndarray:
    """(9,) bool: the comparison channels in use — all, or all but the vertical ones when
    ``vertical_frozen`` (seed 001: no altitude → the vertical channel is excluded)."""
    return _MASK_VERTICAL.copy() if vertical_frozen else np.ones(9, bool)


def majority(nu) -> int | None:
    """Table 1: the failed unit's index for ``nu`` = (ν12, ν13, ν23), None when it names none."""
    return MAJORITY.get(tuple(int(v) for v in nu))


def residual_ok(nu: np.ndarray, S: np.ndarray, k: float) -> np.ndarray:
    """Seed 001's channel test |y_i − ŷ_i| ≤ ε_i, ε_i = k √S_ii, per measurement component (eq. 8).

    Parameters
    ----------
    nu : (m,) innovations y − H ẑ (measurement units);  S : (m, m) their covariance
    k : threshold in σ
    """
    return np.abs(nu) <= k * np.sqrt(np.diag(S))


def frozen_states(n_states: int, vertical: bool) -> np.ndarray:
    """(``n_states``,) bool gain-row mask of ż = Φ(ẑ) + K (y − H ẑ): rows of a frozen channel are zeroed
    (those states keep their prediction); ``vertical`` freezes :data:`VERTICAL_STATES`."""
    m = np.zeros(n_states, bool)
    if vertical:
        m[[s for s in VERTICAL_STATES if s < n_states]] = True
    return m


def switch_components(nu: np.ndarray, S: np.ndarray, scale: np.ndarray, R: np.ndarray,
                      tuning: FdiTuning = FdiTuning()) -> tuple[np.ndarray, bool]:
    """The adaptive variant's component switching for one measurement group (seed 001, eq. 7).

    a_i = 1 when |ν_i| ≤ ε_i = k_residual √S⁰_ii, else 0, with S⁰ the innovation covariance at
    the nominal R (S⁰ = S − (scale − 1) R on the diagonal); A = diag(a): the component's row of
    H̃ = A H is switched off and its measurement replaced by artificial white noise ζ of
    variance ``switch_noise`` × R_ii (R̃ = A R + (I − A) ζ), which leaves K's column for it
    ≈ 0. Divergence test: every component failing and νᵀν > γ tr(S⁰) — the filter no longer
    explains any of its measurements (an outlier burst lets some through).

    Parameters
    ----------
    nu : (m,) innovations;  S : (m, m) their covariance (with the R used)
    scale : (m,) the R multipliers in use (1: switched on)
    R : (m, m) nominal measurement covariance (measurement units²)
    tuning : ``k_residual``, ``switch_noise``, ``diverge_gamma``

    Returns
    -------
    (new multipliers (m,): 1 or ``switch_noise``, diverging)
    """
    nu = np.asarray(nu, float)
    s0 = np.diag(S) - (np.asarray(scale, float) - 1.0) * np.diag(R)
    ok = np.abs(nu) <= tuning.k_residual * np.sqrt(np.maximum(s0, 0.0))
    new = np.where(ok, 1.0, tuning.switch_noise)
    diverging = bool(not ok.any() and float(nu @ nu) > tuning.diverge_gamma * float(s0.sum()))
    return new, diverging


def _event(t_s, unit, kind, stage, reason) -> dict:
    return {"t_s": round(float(t_s), 3), "unit": unit, "kind": kind, "stage": stage,
            "reason": reason}


class _State:
    """The view :attr:`TwoStageFdi.state` gives: ``used`` — the units the output uses."""

    def __init__(self, core: TwoStage):
        self._core = core

    @property
    def used(self) -> list[bool]:
        """Units in the output (in use and not isolated)."""
        return [bool(u) for u in self._core.output_units[0]]


class TwoStageFdi:
    """Seed 001's two-stage identification of one flight's N = 2 or 3 units.

    Parameters
    ----------
    n_units : number of INS units;  tuning : thresholds

    Attributes
    ----------
    core : the :class:`~.identification.two_stage.TwoStage` of one realisation
    state : its view (``state.used``);  nu, flags : (ν12, ν13, ν23) of the last update, with
        persistence and sensor level, and of that instant's output comparison
    """

    def __init__(self, n_units: int, tuning: FdiTuning = FdiTuning()):
        self.n, self.tuning = n_units, tuning
        self.core = TwoStage(1, n_units, tuning)
        self.state = _State(self.core)

    @property
    def nu(self) -> tuple:
        """(ν12, ν13, ν23) of the last update."""
        return tuple(int(v) for v in self.core.nu[0])

    @property
    def flags(self) -> tuple:
        """The last output comparison of the instant (no persistence)."""
        return tuple(int(v) for v in self.core.flags[0])

    def add_innovation(self, i: int, t_s: float, nis: float, dim: int) -> None:
        """Record unit ``i``'s GNSS innovation statistic (NIS of a group of dimension ``dim``)."""
        n = np.zeros((1, self.n))
        d = np.zeros((1, self.n), np.int64)
        n[0, i], d[0, i] = nis, dim
        self.core.add_innovation(t_s, n, d)

    def update(self, t_s: float, y: list[np.ndarray], sig: list[np.ndarray],
               nu_sensor: tuple = (0, 0, 0), mask: np.ndarray | None = None) -> list[dict]:
        """Run both stages at ``t_s`` (s) on the units' comparison vectors ``y`` and σ ``sig``
        (channels in ``mask``) and the sensor-level pair verdicts ``nu_sensor``; return the
        events (detected, isolated, excluded, reconfigured)."""
        c = self.core
        c.update(t_s, np.asarray(y, float)[None], np.asarray(sig, float)[None],
                 np.asarray(nu_sensor, bool)[None], mask)
        ev = []
        if c.new_detect[0]:
            where = "outputs" if c.flags[0].any() else "sensors"
            ev.append(_event(t_s, "ins", "detected", "pairwise",
                             f"(ν12, ν13, ν23) = {self.nu} ({where})"))
        if c.new_estimate_failed[0]:
            ev.append(_event(t_s, "fms", "detected", "estimator",
                             "estimate Ẑ outside its prediction Ẑ_p: prediction restarted"))
        for u in np.flatnonzero(c.new_isolate[0]):
            ev.append(_event(t_s, f"ins{u + 1}", "isolated", "pairwise",
                             f"majority table {self.nu}"))
        for u in np.flatnonzero(c.new_exclude[0]):
            why = ("stage 2: outside the estimate and its prediction (1 1 0)"
                   if c.excluded_by[0, u] == BY_TABLE else "innovation test failed alone")
            ev.append(_event(t_s, f"ins{u + 1}", "excluded", "estimator", why))
        if c.new_isolate[0].any() or c.new_exclude[0].any():
            left = [f"ins{j + 1}" for j in np.flatnonzero(c.output_units[0])]
            stage = "estimator" if c.new_exclude[0].any() else "pairwise"
            ev.append(_event(t_s, "fms", "reconfigured", stage,
                             "output from " + (", ".join(left) or "none")))
        return ev

    def vote(self, y: list[np.ndarray], sig: list[np.ndarray],
             mask: np.ndarray | None = None, flags=None) -> list[int]:
        """Majority voting: the units table 1 of this instant's comparison of ``y`` (σ ``sig``,
        channels ``mask``) does not name — no persistence, no estimator, no memory. ``flags``:
        that comparison's (ν12, ν13, ν23) when already made."""
        if flags is None:
            f = pair_flags(np.asarray(y, float)[None], np.asarray(sig, float)[None],
                           self.tuning.k_pair, mask=mask)
        else:
            f = np.asarray(flags, bool)[None]
        return [int(i) for i in np.flatnonzero(vote(f, self.n)[0])]


class SensorComparator:
    """Stage 1 at sensor level in one flight (:class:`~.identification.sensor.SensorPairTest`
    with R = 1).

    Parameters
    ----------
    n_units : 2 or 3;  q_white : (n, 6) white-noise densities (accel (m/s²)²·s, gyro rad²/s)
    dt_s : sample interval, s;  sf_var : (n, 2) declared scale-factor + 2 × misalignment
        variance (accelerometer, gyro) per unit;  tuning : thresholds and windows
    """

    def __init__(self, n_units: int, q_white: np.ndarray, dt_s: float, sf_var: np.ndarray,
                 tuning: FdiTuning = FdiTuning()):
        self.n, self.tuning, self.pairs = n_units, tuning, [p for p in PAIRS if p[1] < n_units]
        self.test = SensorPairTest(1, n_units, q_white, dt_s, sf_var, tuning)

    @property
    def last_z(self) -> np.ndarray:
        """(pairs, 6) the last test statistics Δ / σ_Δ."""
        return self.test.last_z[0]

    def update(self, t_s: float, errs: np.ndarray, f_mps2, w_rps) -> tuple:
        """Add the units' raw-output errors (n, 6) at ``t_s`` (s) with the measured specific
        force (3,) m/s² and rate (3,) rad/s; return (ν12, ν13, ν23)."""
        errs = np.asarray(errs, float)
        if errs.ndim != 2 or errs.shape[0] < self.n or errs.shape[1] < 6:
            raise ValueError(f"sensor errors of shape {errs.shape}, not ({self.n}, 6)")
        return tuple(int(v) for v in self.test.update(errs[None], f_mps2, w_rps)[0])


class FreeEnvelope:
    """The declared covariance of a free inertial solution (no aiding, no feedback) along the
    route flown: the majority-voting baseline's σ_free.

    P(t₀) = A diag(p0) Aᵀ (the 33-state model's initial map, stationary alignment), then every
    ``step_s``: P ← Φ P Φᵀ + Q_k with (Φ, Q_k) of the 33-state model (free vertical channel) at
    the integrated solution and the measured specific force and rate.

    Parameters
    ----------
    imu : the units' declared IMU model;  step_s : propagation step, s
    """

    def __init__(self, imu, step_s: float = 1.0):
        self.imu, self.step_s = imu, float(step_s)
        self.P: np.ndarray | None = None
        self._t_s: float | None = None

    def update(self, t_s: float, lat_rad: float, alt_m: float, v_enu_mps, rpy_rad,
               f_b_mps2, w_eb_rps) -> None:
        """Start at the first call; propagate once ``step_s`` (s) has passed since the last
        propagation (F held over the step at this call's state: lat rad, alt m, V ENU m/s,
        roll/pitch/heading rad, measured f m/s² and ω_eb rad/s, body)."""
        opts = SinsOptions(vertical="free")
        if self.P is None:
            A = initial_map(lat_rad, rpy_rad, self.imu, SinsOptions())
            self.P, self._t_s = (A * self.imu.p0_var) @ A.T, float(t_s)
            return
        dt = float(t_s) - self._t_s
        if dt < self.step_s - 1e-9:
            return
        F = sins_F(lat_rad, alt_m, np.asarray(v_enu_mps, float), tuple(rpy_rad),
                   np.asarray(w_eb_rps, float), np.asarray(f_b_mps2, float), self.imu, opts)
        phi, qk = step_discrete(F, self.imu, dt, opts)
        P = phi @ self.P @ phi.T + qk
        self.P, self._t_s = 0.5 * (P + P.T), float(t_s)

    def sigma(self) -> np.ndarray:
        """(9,) σ of the comparison channels of a free unit (position ENU m, velocity m/s, roll
        and pitch — the larger tilt σ — and heading rad)."""
        d = np.sqrt(np.maximum(self.P.diagonal()[:9], 0.0))
        d[6] = d[7] = max(d[6], d[7])
        return d


_GROUP_STATES = {"gnss_pos": (0, 1, 2), "gnss_vel": (3, 4, 5), "baro": (2,)}
"""Filter states each measurement group measures directly (the rows of H with a 1)."""


class FaultTolerantEstimator:
    """Seed 001's fault-tolerant estimator around the units' filters.

    The channel test |y_i − ŷ_i| ≤ ε_i on every measurement component (eq. 8); a unit's baro
    channel failing ``baro_fails`` times in ``baro_window_s`` is latched out (its gain row
    zeroed for good); a unit without an altitude measurement has its vertical channel frozen
    (:func:`frozen_states` on the filter's ``frozen`` mask) and left out of the comparisons
    (:meth:`mask`). With ``adaptive`` the variant of eq. 7 runs: :func:`switch_components` on
    every group, and ``diverge_count`` consecutive divergent updates of a group reset its
    filter's covariance along the measured states (P_jj += max(ν_j² − S_jj, 0)), an event.

    With ``component_channels`` the GNSS groups are corrected per component (eq. 8): a component
    failing |y_i − ŷ_i| ≤ ε_i = k_residual √S_ii has its gain column zeroed while the others are
    used, and on a unit without another altitude channel (no baro, or its baro excluded) a failed
    vertical component also zeroes the gain rows of :data:`VERTICAL_STATES` — ẑ_H, Ŵ_Z and the
    baro bias keep their prediction — and the vertical comparison channels are dropped until
    the vertical components pass again (``vertical_held``).

    Parameters
    ----------
    filters : the units' filters (their public ``frozen`` mask, ``r_scale``, ``channel_test``
        and ``hold_vertical`` are set)
    tuning : thresholds;  adaptive : run the adaptive variant
    component_channels : the per-component channel test (False: the filters' group gate)
    """

    def __init__(self, filters: list, tuning: FdiTuning = FdiTuning(), adaptive: bool = False,
                 component_channels: bool = True):
        self.filters, self.tuning, self.adaptive = filters, tuning, bool(adaptive)
        n = len(filters)
        self.baro_excluded = [False] * n
        self.vertical_frozen = [False] * n
        self.vertical_held = [False] * n
        self._held_by: list[set] = [set() for _ in range(n)]
        self._baro_fails: list[list[float]] = [[] for _ in range(n)]
        self._diverging = [dict() for _ in range(n)]
        self.set_component_channels(component_channels)

    def set_component_channels(self, on: bool) -> None:
        """Switch the per-component channel test of every filter on or off."""
        self.component_channels = bool(on)
        for i in range(len(self.filters)):
            self._set_channels(i)

    def _set_channels(self, i: int) -> None:
        f = self.filters[i]
        if not hasattr(f, "channel_test"):
            return
        f.channel_test = self.tuning.k_residual if self.component_channels else 0.0
        no_alt = getattr(f, "baro", None) is None or self.baro_excluded[i]
        f.hold_vertical = frozen_states(f.frozen.size, True) if no_alt else None

    def _unit(self, i: int, sensor: str) -> str:
        return sensor if len(self.filters) == 1 else f"{sensor}@ins{i + 1}"

    def check(self, i: int, t_s: float, groups: list) -> list[dict]:
        """Residual tests of unit ``i``'s measurement groups (:class:`.ins_filter.GroupResult`)
        at ``t_s`` (s); returns the events (baro channel excluded, divergence reset)."""
        ev: list[dict] = []
        for g in groups:
            if g.name.startswith("gnss"):
                ev += self._hold(i, t_s, g)
            if g.name == "baro" and not self.baro_excluded[i]:
                ev += self._baro(i, t_s, residual_ok(g.innovation, g.S, self.tuning.k_residual))
            f = self.filters[i]
            if self.adaptive and g.name in getattr(f, "r_scale", {}):
                f.r_scale[g.name], div = switch_components(
                    g.innovation, g.S, f.r_scale[g.name], f.nominal_r(g.name), self.tuning)
                ev += self._divergence(i, t_s, g, div)
        return ev

    def _baro(self, i: int, t_s: float, ok: np.ndarray) -> list[dict]:
        buf = self._baro_fails[i]
        if not ok.all():
            buf.append(t_s)
        while buf and buf[0] < t_s - self.tuning.baro_window_s:
            buf.pop(0)
        if len(buf) < self.tuning.baro_fails:
            return []
        self.baro_excluded[i] = True
        self._set_channels(i)
        return [_event(t_s, self._unit(i, "baro"), "excluded", "estimator",
                       f"baro residual beyond {self.tuning.k_residual:g}σ {len(buf)} times in "
                       f"{self.tuning.baro_window_s:g} s: its gain row zeroed")]

    def _hold(self, i: int, t_s: float, g) -> list[dict]:
        """Track unit ``i``'s vertical hold from a GNSS group's per-component result ``g``;
        returns the ``reconfigured`` event of a change."""
        f = self.filters[i]
        if g.components is None and not g.used:
            return []                              # nothing used: no verdict on the vertical
        failed = (g.components is not None and not g.components[2]
                  and getattr(f, "hold_vertical", None) is not None)
        (self._held_by[i].add if failed else self._held_by[i].discard)(g.name)
        held = bool(self._held_by[i])
        if held == self.vertical_held[i]:
            return []
        self.vertical_held[i] = held
        return [_event(t_s, self._unit(i, "ins"), "reconfigured", "estimator",
                       f"vertical channel held and excluded: {g.name} U failed its channel test"
                       if held else "vertical channel released: GNSS U passes its channel test")]

    def _divergence(self, i: int, t_s: float, g, diverging: bool) -> list[dict]:
        count = self._diverging[i].get(g.name, 0) + 1 if diverging else 0
        self._diverging[i][g.name] = count
        if count < self.tuning.diverge_count:
            return []
        self._diverging[i][g.name] = 0
        f = self.filters[i]
        states = _GROUP_STATES.get(g.name, ())
        excess = np.maximum(np.asarray(g.innovation) ** 2 - np.diag(g.S), 0.0)
        for s, e in zip(states, excess):
            f.P[s, s] += e
        return [_event(t_s, self._unit(i, g.name.split("_")[0]), "reset", "adaptive",
                       f"{g.name} diverging {self.tuning.diverge_count} times (νᵀν > "
                       f"{self.tuning.diverge_gamma:g} tr S): covariance reset along it")]

    def set_vertical(self, i: int, t_s: float, has_altitude: bool) -> list[dict]:
        """Freeze (``has_altitude`` False) or release unit ``i``'s vertical channel; returns the
        ``reconfigured`` event of a change."""
        frozen = not has_altitude
        if frozen == self.vertical_frozen[i]:
            return []
        self.vertical_frozen[i] = frozen
        f = self.filters[i]
        if hasattr(f, "frozen"):
            f.frozen[:] = frozen_states(f.frozen.size, frozen)
        return [_event(t_s, self._unit(i, "ins"), "reconfigured", "estimator",
                       "vertical channel frozen and excluded: no altitude measurement"
                       if frozen else "vertical channel released: altitude measured")]

    def mask(self, used: list[bool] | None = None) -> np.ndarray:
        """Comparison channels: the vertical ones out when a unit in use has it frozen."""
        live = range(len(self.filters)) if used is None else [i for i, u in enumerate(used) if u]
        return channel_mask(any(self.vertical_frozen[i] or self.vertical_held[i] for i in live))


__all__ = ["FaultTolerantEstimator", "FdiTuning", "FreeEnvelope", "MAJORITY", "SensorComparator", "TwoStageFdi",
           "VERTICAL_CHANNELS", "VERTICAL_STATES", "channel_mask", "channel_sigmas",
           "declared_sensor_noise", "frozen_states", "majority", "residual_ok",
           "switch_components", "unmodelled_variances"]
