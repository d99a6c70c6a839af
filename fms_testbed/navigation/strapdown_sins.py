"""Free-inertial SINS on the strapdown truth side: one unit mechanising its own IMU's measured
increments (:class:`~fms_testbed.navigation.inertial.bank.StrapdownBank`), the vertical channel
baro-aided or free — the ``truth_model: strapdown`` form of ``navigation: {source: sins}``.

Scenario keys (the ``sins`` block's): ``imu``, ``seed``, ``vertical`` (``baro``: a third-order
loop on an error-free baro altitude with its poles at -1/``baro_tau_s``,
:func:`~fms_testbed.navigation.inertial.strapdown.vertical_gains`; ``free``), ``baro_tau_s``,
``alignment`` (``stationary`` or ``gnss_heading``), ``truth_model: strapdown``. The linear
model's discretisation keys (``method``, ``tol``, ``dt_s``, ``matrices_*``) have no meaning here
and are accepted unchanged. Logged columns: those of
:meth:`~fms_testbed.navigation.sins.SinsNavigation.solution` (output - truth, the unit's sensor
biases), from the unit's true errors (:meth:`StrapdownBank.errors`).
"""

from __future__ import annotations

import math

from fms_testbed.core.contracts import NavigationSourceBase
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.navigation.inertial.bank import StrapdownBank, set_lever_arm
from fms_testbed.navigation.ins_bank import derive_seeds
from fms_testbed.sensors.sins.presets import load_imu


class StrapdownSinsNavigation(NavigationSourceBase):
    """A free-inertial strapdown INS (module docstring).

    Parameters
    ----------
    bank : a one-unit strapdown bank;  vertical : ``baro`` or ``free``
    baro_tau_s : time constant of the baro loop, s
    """

    truth_model = "strapdown"

    def __init__(self, bank: StrapdownBank, vertical: str = "baro", baro_tau_s: float = 60.0):
        self.bank, self.vertical, self.baro_tau_s = bank, vertical, float(baro_tau_s)
        self.frame_properties = tuple(bank.frame_properties)
        self._t_prev: float | None = None

    def install_imu(self, lever_arm_m) -> None:
        """The IMU's position from the CG (the aircraft file's ``imu_lever_arm_m``, body axes,
        m), set before the first update."""
        set_lever_arm(self.bank, lever_arm_m)
        self.frame_properties = tuple(self.bank.frame_properties)

    @classmethod
    def from_spec(cls, spec: dict, seed: int | None = None) -> "StrapdownSinsNavigation":
        """Build from a ``sins`` block with ``truth_model: strapdown`` (``spec['seed']`` wins).

        Raises
        ------
        ConfigError : a bad ``vertical`` or ``alignment``, a missing ``imu``
        """
        if "imu" not in spec:
            raise ConfigError("navigation.imu: missing (a preset name, a .yaml path or a mapping)")
        vertical = str(spec.get("vertical", "baro"))
        if vertical not in ("baro", "free"):
            raise ConfigError(f"navigation.vertical: baro or free, got {vertical!r}")
        alignment = str(spec.get("alignment", "stationary"))
        if alignment not in ("stationary", "gnss_heading"):
            raise ConfigError("navigation.alignment: stationary or gnss_heading with "
                              f"truth_model strapdown, got {alignment!r}")
        tau = float(spec.get("baro_tau_s", 60.0))
        if not tau > 0:
            raise ConfigError(f"navigation.baro_tau_s: must be > 0 s, got {tau}")
        sd = spec.get("seed", seed)
        seeds = derive_seeds(0 if sd is None else int(sd), 3)     # as ins_gnss: [GNSS, baro, INS]
        bank = StrapdownBank([load_imu(spec["imu"])], seeds[2:], alignment=alignment)
        return cls(bank, vertical, tau)

    def update(self, truth: AircraftState, frames=None) -> NavSolution:
        """Advance the unit to ``truth.t_s`` over ``frames``; aid its vertical channel with the
        (error-free) baro altitude; return its output and the logged errors."""
        out = self.bank.update(truth, frames)[0]
        if self.vertical == "baro" and self._t_prev is not None and truth.t_s > self._t_prev:
            self.bank.aid_vertical(truth.alt_m, truth.t_s - self._t_prev, self.baro_tau_s)
            out = self.bank.output(0, truth)
        self._t_prev = truth.t_s
        e = self.bank.errors(0)
        errs = {
            "nse_east_m": e[0], "nse_north_m": e[1], "nse_up_m": e[2],
            "ve_err_mps": e[3], "vn_err_mps": e[4], "vu_err_mps": e[5],
            "att_err_roll_deg": math.degrees(out.roll_rad - truth.roll_rad),
            "att_err_pitch_deg": math.degrees(out.pitch_rad - truth.pitch_rad),
            "att_err_heading_deg": math.degrees(math.remainder(
                out.heading_rad - truth.heading_rad, 2 * math.pi)),
            "bias_accel_x_ug": e[9] / G0_MPS2 * 1e6,
            "bias_gyro_x_dph": e[12] / DPH_RPS, "bias_gyro_z_dph": e[14] / DPH_RPS,
        }
        return NavSolution(truth.t_s, out.lat_rad, out.lon_rad, out.alt_m, out.v_enu_mps,
                           out.roll_rad, out.pitch_rad, out.heading_rad, errs)


__all__ = ["StrapdownSinsNavigation"]
