"""N strapdown INS units on their own IMUs, behind the INS-bank interface the filter drives
(:class:`~fms_testbed.navigation.bank.InsBankLike`).

Truth side: one :class:`~fms_testbed.sensors.imu.synthesis.ImuSynthesizer`-equivalent state
makes the error-free increments at the IMU position from JSBSim's per-frame samples; each unit
adds its own sensor errors (:class:`~fms_testbed.sensors.imu.errors.ImuErrors`) and mechanises
the result (:mod:`.strapdown`), all in one compiled call per navigation step
(:func:`~.strapdown.bank_step`). Each unit starts from its own alignment (:mod:`.alignment`).

Seeds: one per unit (:func:`fms_testbed.navigation.ins_bank.derive_seeds`); each unit spawns its
turn-on, slow-noise and white-noise streams from it (:class:`~fms_testbed.sensors.imu.errors.ImuErrors`)
and an alignment stream ``SeedSequence([seed, 1])``, so units never share random numbers and
the numbers of one do not depend on the others. Noise is drawn in blocks in the order it is
used: the same seed gives the same run.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.navigation.inertial.alignment import ALIGNMENTS, align, initial_errors_applied
from fms_testbed.navigation.inertial.strapdown import (N_OUT, N_T, N_U, T_MEAN, U_A, U_COMP, U_E,
                                                       U_MEAN, U_RES, U_W,
                                                       bank_step, correct_row, nav_errors,
                                                       output_row, outputs, vertical_aid,
                                                       vertical_gains)
from fms_testbed.sensors.imu.errors import (N_SLOW, ImuErrorParams, ImuErrors, imu_error_params,
                                            layout_33)
from fms_testbed.core.earth import earth_rate_ned
from fms_testbed.sensors.imu.kinematics import euler_to_quat, qconj, qrot
from fms_testbed.sensors.imu.synthesis import frame_properties, sample_of, start_row
from fms_testbed.sensors.sins.presets import ImuModel, ImuSpec, imu_model, load_imu

_BLOCK = 1024
"""Frames of white noise (and steps of slow-state noise) drawn at once per unit."""
_AXIS = {"x": 0, "y": 1, "z": 2}


def _p0_var(imu) -> np.ndarray:
    """The 33-state initial variances of an IMU (its ``initial`` block in states 0..8)."""
    if isinstance(imu, ImuModel):
        return imu.p0_var
    return imu_model(imu).p0_var if isinstance(imu, ImuSpec) else load_imu(imu).p0_var


def _solution(t_s: float, o: np.ndarray) -> NavSolution:
    return NavSolution(t_s, o[0], o[1], o[2], o[3:6], o[6], o[7], o[8], {})


class StrapdownBank:
    """Strapdown INS units (see the module docstring and :class:`~..bank.InsBankLike`).

    Parameters
    ----------
    imus : one IMU per unit: a preset name, YAML path, mapping, spec or model
        (:func:`~fms_testbed.sensors.imu.errors.imu_error_params`)
    seeds : one seed per unit
    lever_arm_m : IMU position relative to the CG, body axes x forward, y right, z down, m
        (the aircraft file's ``imu_lever_arm_m``)
    alignment : ``stationary`` (levelling + gyrocompassing at rest, :mod:`.alignment`) or
        ``gnss_heading`` (in-air levelling, GNSS heading)
    alignment_s : duration of the stationary alignment, s
    heading_sigma_deg : 1σ of the GNSS heading of a ``gnss_heading`` start, deg
    """

    def __init__(self, imus: list, seeds: list[int], lever_arm_m=(0.0, 0.0, 0.0),
                 alignment: str = "stationary", alignment_s: float = 300.0,
                 heading_sigma_deg: float = 0.5):
        if len(imus) != len(seeds):
            raise ValueError("one seed per INS unit")
        if alignment not in ALIGNMENTS:
            raise ValueError(f"alignment {alignment!r}: expected one of {', '.join(ALIGNMENTS)}")
        self.params: list[ImuErrorParams] = [imu_error_params(m) for m in imus]
        self._p0 = [_p0_var(m) for m in imus]
        self.imu = ImuErrors(self.params, seeds)
        self.seeds = [int(s) for s in seeds]
        self.lever = np.ascontiguousarray(lever_arm_m, dtype=float).reshape(3)
        self.use_rates = bool(np.any(self.lever != 0.0))
        self.frame_properties = frame_properties(self.lever)
        self.alignment, self.alignment_s = alignment, float(alignment_s)
        self.heading_sigma_rad = math.radians(heading_sigma_deg)
        n = len(seeds)
        self.rows: np.ndarray | None = None           # the units' states
        # one array for the kernel; the IMU's errors, the compensation and the means are views
        self.U = np.zeros((n, N_U))
        self.U[:, U_E:U_A] = self.imu.E
        self.imu.E = self.U[:, U_E:U_A]
        self.imu.res = self.U[:, U_RES:U_COMP]
        self.comp = self.U[:, U_COMP:U_MEAN]          # bias compensation fed back (b_a, b_g)
        self.mean = self.U[:, U_MEAN:U_W]             # f̄, ω̄ of the last step (compensated)
        self.last_w = self.U[:, U_W:]                 # compensated rate of the last frame
        self.T = np.zeros(N_T)                        # the IMU's error-free state and means
        self.truth_row = self.T[:T_MEAN]
        self.true_mean = self.T[T_MEAN:]
        self.fed_back = np.zeros((n, 15))
        self.stuck: dict[int, NavSolution] = {}
        self._out = np.zeros((n, N_OUT))
        self._truth: AircraftState | None = None
        self._white = np.zeros((n, 0, 6))
        self._wpos = 0
        self._slow = np.zeros((0, n, N_SLOW))
        self._spos = 0
        self._coef_key: tuple | None = None
        self._vgain: tuple | None = None              # (τ s, k1, k2, k3) of the baro loop
        self._vacc = np.zeros((n, 1))                 # its acceleration corrections, m/s²

    def __len__(self) -> int:
        return len(self.params)

    # -- noise ------------------------------------------------------------------------------
    def _noise(self, n_frames: int) -> tuple[np.ndarray, int, np.ndarray]:
        """(white buffer (n, m, 6), its first row for this step, this step's slow-state normals
        (n, 30)), drawn ``_BLOCK`` at a time per unit in the order they are used."""
        w0 = self._wpos
        if w0 + n_frames > self._white.shape[1]:
            m = max(_BLOCK, n_frames)
            rest = self._white[:, w0:]
            fresh = np.stack([g.standard_normal((m, 6)) for g in self.imu.rng_white])
            self._white = np.ascontiguousarray(np.concatenate([rest, fresh], axis=1))
            w0 = 0
        self._wpos = w0 + n_frames
        if self._spos >= self._slow.shape[0]:
            self._slow = np.ascontiguousarray(np.stack(
                [g.standard_normal((_BLOCK, N_SLOW)) for g in self.imu.rng_slow], axis=1))
            self._spos = 0
        zs = self._slow[self._spos]
        self._spos += 1
        return self._white, w0, zs

    # -- stepping ---------------------------------------------------------------------------
    def _coefficients(self, step_s: float, frame_s: float) -> None:
        """Refresh the kernel's copies of the slow states' one-step a, s, the white σ per frame
        and the quanta when the step, the frame time or the IMU's parameters changed."""
        key = (step_s, frame_s, self.imu.version)
        if key == self._coef_key:
            return
        self.imu.pack_rows(self.U, step_s, frame_s)
        self._coef_key = key

    def _start(self, truth: AircraftState) -> None:
        """Start the IMU at ``truth`` and align every unit."""
        self.truth_row[:] = start_row(truth, self.lever)
        rows = []
        for i, s in enumerate(self.seeds):
            rng = np.random.default_rng(np.random.SeedSequence([s, 1]))
            row = align(self.alignment, self.imu, i, self.truth_row, truth, rng,
                        self.alignment_s, self.heading_sigma_rad)
            initial_errors_applied(row, self._p0[i], rng)
            rows.append(row)
        self.rows = np.array(rows)
        q = euler_to_quat(truth.roll_rad, truth.pitch_rad, truth.heading_rad)
        w_ie = qrot(qconj(q), earth_rate_ned(truth.lat_rad))
        self.mean[:, 3:] = np.array([truth.p_rps, truth.q_rps, truth.r_rps]) + w_ie
        self.last_w[:] = self.mean[:, 3:]
        outputs(self.rows, self.lever, self.last_w, self._out)

    def update(self, truth: AircraftState, frames: np.ndarray | None = None) -> list[NavSolution]:
        """Advance every unit to ``truth.t_s`` over ``frames`` (the JSBSim samples of
        :attr:`frame_properties` since the last call; ``None``: the true state is the step's
        only sample) and return their indicated solutions (the first call aligns and starts)."""
        if self.rows is None:
            self._start(truth)
        else:
            if frames is None:
                frames = sample_of(truth)[None, :]
            n_f = frames.shape[0]
            dt = (truth.t_s - self._truth.t_s) / n_f
            if dt <= 0.0:
                raise ValueError(f"StrapdownBank.update: time did not advance ({truth.t_s} s)")
            self._coefficients(n_f * dt, dt)
            white, w0, zs = self._noise(n_f)
            self._out = np.empty((len(self), N_OUT))
            bank_step(frames if frames.flags.c_contiguous else np.ascontiguousarray(frames), dt,
                      self.lever, self.use_rates, self.T, self.rows, self.U, zs, white, w0,
                      self._out)
        self._truth = truth
        t = truth.t_s
        o = self._out
        out = [NavSolution(t, *r[:3], o[i, 3:6], *r[6:], {}) for i, r in enumerate(o.tolist())]
        for i, held in self.stuck.items():
            out[i] = replace(held, t_s=t)
        return out

    def output(self, i: int, truth: AircraftState) -> NavSolution:
        """Unit ``i``'s current indicated solution at ``truth.t_s`` (after a correction)."""
        if i in self.stuck:
            return replace(self.stuck[i], t_s=truth.t_s)
        o = np.empty(N_OUT)
        outputs(self.rows[i:i + 1], self.lever, self.last_w[i:i + 1], o[None, :])
        return _solution(truth.t_s, o)

    def correct(self, i: int, dx: np.ndarray) -> None:
        """Feed back a filter estimate (15,: δp ENU m, δV ENU m/s, ε E/N/U rad, b_a m/s², b_g
        rad/s; indicated minus true) into unit ``i``: its state (:func:`~.strapdown.correct_row`)
        and its bias compensation."""
        dx = np.asarray(dx, float)
        correct_row(self.rows[i], np.ascontiguousarray(dx[:9]), self.lever, self.last_w[i])
        self.comp[i] += dx[9:15]
        self.fed_back[i] += dx[:15]

    def take_fed_back(self) -> np.ndarray:
        """(n, 15) the corrections fed back to each unit since the last call, then zeroed."""
        out = self.fed_back.copy()
        self.fed_back[:] = 0.0
        return out

    def freeze(self, i: int, last: NavSolution) -> None:
        """Unit ``i``'s output sticks at ``last`` from now on (a stuck-output fault)."""
        self.stuck[i] = last

    def measured(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Unit ``i``'s compensated measured (f m/s², ω_ib rad/s), body, averaged over the last
        step: ΣΔv_c / T, ΣΔθ_c / T (before the first step: no force and the true rate
        ω_eb + C_n^b ω_ie^n of the start)."""
        return self.mean[i, :3].copy(), self.mean[i, 3:].copy()

    def aid_vertical(self, alt_m, dt_s: float, tau_s: float = 60.0) -> None:
        """Damp every unit's vertical channel with a baro altitude: one step of a third-order
        loop (:func:`~.strapdown.vertical_gains`, poles at -1/``tau_s``) on the error between
        each unit's indicated altitude and ``alt_m`` (m, the package's sea-level datum; a
        scalar or one per unit) over ``dt_s`` (s, the time since the last reading). Not for a
        unit under a filter that already uses the baro."""
        if self._vgain is None or self._vgain[0] != tau_s:
            self._vgain = (tau_s, *vertical_gains(tau_s, float(self.rows[0, 0])))
        k1, k2, k3 = self._vgain[1:]
        alt = np.broadcast_to(np.asarray(alt_m, float), (len(self),))
        for i in range(len(self)):
            o = np.empty(N_OUT)
            output_row(self.rows[i], self.lever, self.last_w[i], o)
            vertical_aid(self.rows[i], o[2] - alt[i], k1, k2, k3, self._vacc[i], dt_s)

    def sensor_errors(self, truth: AircraftState, dt_s: float) -> np.ndarray:
        """(n, 6) each unit's raw IMU output minus the error-free one, averaged over the last
        step (accelerometer m/s², gyro rad/s): the :class:`~..ins_bank.InsBank` method of the
        same name (``truth`` and ``dt_s`` are not needed here: the step is the last update's)."""
        return self.mean + self.comp - self.true_mean

    def errors(self, i: int) -> np.ndarray:
        """Unit ``i``'s true errors (33,) at the last update: navigation errors (indicated
        minus true, :func:`~.strapdown.nav_errors`) and its sensor errors in the 33-state
        layout, biases less the compensation fed back."""
        t = self._truth
        o = np.empty(N_OUT)
        err = np.empty(33)
        q_true = euler_to_quat(t.roll_rad, t.pitch_rad, t.heading_rad)
        q_ind = output_row(self.rows[i], self.lever, self.last_w[i], o)
        nav_errors(o, q_ind, t.lat_rad, t.lon_rad, t.alt_m,
                   np.asarray(t.v_enu_mps, float), q_true, err[:9])
        err[9:] = layout_33(self.imu.E[i])
        err[9:15] -= self.comp[i]
        return err

    def inject(self, i: int, fault: dict) -> str:
        """Apply a truth-side fault to unit ``i`` (the :mod:`fms_testbed.navigation.faults`
        kinds ``gyro_bias_step`` (``axis``, ``size_dph``), ``accel_bias_step`` (``axis``,
        ``size_ug``), ``drift_scale`` (``factor``), ``stuck``); returns what changed.

        Raises
        ------
        ValueError : another kind
        """
        kind = fault["kind"]
        if kind == "gyro_bias_step":
            self.imu.step_bias(i, "gyro", _AXIS[fault["axis"]], fault["size_dph"] * DPH_RPS)
            return f"gyro {fault['axis']} bias {fault['size_dph']:+g} deg/h"
        if kind == "accel_bias_step":
            self.imu.step_bias(i, "accel", _AXIS[fault["axis"]], fault["size_ug"] * 1e-6 * G0_MPS2)
            return f"accelerometer {fault['axis']} bias {fault['size_ug']:+g} ug"
        if kind == "drift_scale":
            ex = self.imu.scale_gyro_drift(i, fault["factor"])
            return (f"gyro drift x{fault['factor']:g} of declared ({ex[0] / DPH_RPS:.3g} deg/h "
                    "excess per axis)")
        if kind == "stuck":
            self.freeze(i, self.output(i, self._truth))
            return "output stuck"
        raise ValueError(f"fault kind {kind!r} is not an INS fault")


def set_lever_arm(bank: StrapdownBank, lever_arm_m) -> None:
    """Place a bank's IMU at ``lever_arm_m`` (3,) m from the CG, body axes, before its first
    update (the aircraft file's ``imu_lever_arm_m``).

    Parameters
    ----------
    bank : the strapdown bank;  lever_arm_m : (3,) x forward, y right, z down, m

    Raises
    ------
    ValueError : the bank has started
    """
    if bank.rows is not None:
        raise ValueError("set_lever_arm: the bank has started")
    bank.lever = np.ascontiguousarray(lever_arm_m, dtype=float).reshape(3)
    bank.use_rates = bool(np.any(bank.lever != 0.0))
    bank.frame_properties = frame_properties(bank.lever)


__all__ = ["StrapdownBank", "set_lever_arm"]
