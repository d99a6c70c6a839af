"""Navigation faults injected on the truth side when a scenario event fires (``events[].fault``,
:class:`fms_testbed.config.scenario.Fault`). The filters are not told; what they see is the
sensors' changed behaviour.

=================== ====== ==================================================================
kind                unit   what changes (from the event's time)
=================== ====== ==================================================================
gyro_bias_step      insN   the unit's gyro bias on ``axis`` steps by ``size_dph`` (deg/h)
accel_bias_step     insN   the accelerometer bias on ``axis`` steps by ``size_ug`` (µg)
drift_scale         insN   the gyro drift becomes ``factor`` × its declared value: an excess
                           drift (factor - 1) × declared σ on every axis, and the drift's
                           random intensity × factor²
stuck               insN   the unit's output freezes at its last value
gnss_outliers       gnss   outlier burst of ``sigma_m`` per axis for ``duration_s``
gnss_ramp           gnss   position error ramp of ``rate_mps`` (E, N, U)
gnss_outage         gnss   no fix for ``duration_s`` (default: to the end)
baro_failure        baro   the baro output freezes (stuck static port)
=================== ====== ==================================================================
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.sensors.gnss import Interval, OutlierBurst, Ramp

_AXIS = {"x": 0, "y": 1, "z": 2}


def check_fault(fault: dict, n_ins: int, has_baro: bool) -> None:
    """Raise :class:`ConfigError` when ``fault`` names a unit the source does not have."""
    unit = fault["unit"]
    if unit.startswith("ins") and int(unit[3:]) > n_ins:
        raise ConfigError(f"events.fault.unit: {unit} but navigation.n_ins is {n_ins}")
    if unit == "baro" and not has_baro:
        raise ConfigError("events.fault.unit: baro but navigation.baro is null")


def inject(source, fault: dict, t_s: float) -> dict:
    """Apply ``fault`` (a validated ``Fault`` as a mapping) to ``source`` (an
    :class:`~fms_testbed.navigation.ins_gnss.InsGnssNavigation`) at ``t_s`` (s); return the
    ``fault_injected`` event."""
    check_fault(fault, len(source.bank), source.baro is not None)
    kind, unit = fault["kind"], fault["unit"]
    end = t_s + fault["duration_s"] if "duration_s" in fault else math.inf
    if unit.startswith("ins"):
        # the same fault on the unit flown free for the majority-voting baseline, if any
        banks = [source.bank] + [b for b in [getattr(source, "free_bank", None)] if b is not None]
        what = [_inject_ins(source, b, int(unit[3:]) - 1, fault) for b in banks][0]
    elif kind == "baro_failure":
        source.baro.spec = replace(source.baro.spec, failed_from_s=t_s)
        what = "static port stuck"
    else:
        rx = source.receiver
        sp = rx.spec
        if kind == "gnss_outliers":
            rx.spec = replace(sp, outliers=sp.outliers + (OutlierBurst(Interval(t_s, end),
                                                                        fault["sigma_m"]),))
            what = f"outliers sigma {fault['sigma_m']:g} m"
        elif kind == "gnss_ramp":
            rx.spec = replace(sp, ramps=sp.ramps + (Ramp(Interval(t_s), tuple(fault["rate_mps"])),))
            what = f"ramp {fault['rate_mps']} m/s"
        else:
            rx.spec = replace(sp, outages=sp.outages + (Interval(t_s, end),))
            what = "outage"
    return {"t_s": round(t_s, 3), "unit": unit, "kind": "fault_injected", "stage": "truth",
            "reason": f"{kind}: {what}"}


def _inject_ins(source, bank, i: int, fault: dict) -> str:
    """Apply an INS fault to unit ``i`` of ``bank`` (a strapdown bank applies it to the unit's
    IMU itself; the linear twin to its error state); return what changed."""
    kind = fault["kind"]
    if hasattr(bank, "inject"):
        return bank.inject(i, fault)
    u = bank.units[i]
    if kind == "gyro_bias_step":
        u.x[12 + _AXIS[fault["axis"]]] += fault["size_dph"] * DPH_RPS
        return f"gyro {fault['axis']} bias {fault['size_dph']:+g} deg/h"
    if kind == "accel_bias_step":
        u.x[9 + _AXIS[fault["axis"]]] += fault["size_ug"] * 1e-6 * G0_MPS2
        return f"accelerometer {fault['axis']} bias {fault['size_ug']:+g} ug"
    if kind == "drift_scale":
        f = fault["factor"]
        sigma = np.sqrt(source.filters[i].imu.p0_var[12:15])
        u.x[12:15] += (f - 1.0) * sigma
        q = u.imu.q_psd.copy()
        q[12:15] *= f * f
        u.replace_imu(replace(u.imu, q_psd=q))
        return (f"gyro drift x{f:g} of declared ({(f - 1) * sigma[0] / DPH_RPS:.3g} deg/h "
                f"excess per axis)")
    bank.freeze(i, bank.output(i, source._prev_truth))                  # stuck
    return "output stuck"


__all__ = ["check_fault", "inject"]
