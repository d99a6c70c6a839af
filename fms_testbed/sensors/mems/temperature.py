"""Temperature profiles of a static gyro test and the hysteresis state they drive.

A profile is the sensor temperature, °C, on a uniform time grid (``step_s``, 1 s by default):
``warmup`` (self-heating after switch-on: T = T_amb + ΔT (1 - e^{-t/τ})), ``ramp`` (a chamber
thermal cycle room → high → low → room over the run), ``constant``, or a CSV file with columns ``t_s`` and
``temperature_degC``. The hysteresis of the zero signal is a play (backlash) operator on the
temperature: the operator's output follows T with a dead band of ± w, and the normalised state
h = (T - play_w(T)) / w ∈ [-1, 1] is +1 on a heating branch and -1 on a cooling one.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fms_testbed.core.errors import UserError
from fms_testbed.sensors.mems.preset import MemsSpec

PROFILE_NAMES = ("warmup", "ramp", "constant")
STEP_S = 1.0
"""Grid of the built-in profiles, s (temperature changes over minutes)."""


@dataclass(frozen=True)
class TemperatureProfile:
    """Sensor temperature on a uniform grid: ``t_s`` (n,) s from switch-on, ``temp_degC`` (n,)."""

    t_s: np.ndarray
    temp_degC: np.ndarray
    name: str

    def at(self, t_s: np.ndarray) -> np.ndarray:
        """Temperature, °C, at the times ``t_s`` (s; linear interpolation, held at the ends)."""
        return np.interp(t_s, self.t_s, self.temp_degC)

    @property
    def duration_s(self) -> float:
        """Last time of the profile, s."""
        return float(self.t_s[-1])

    @property
    def swing_degC(self) -> float:
        """Temperature range covered, °C (max - min)."""
        return float(self.temp_degC.max() - self.temp_degC.min())


def _grid(duration_s: float, step_s: float) -> np.ndarray:
    if not duration_s > 0:
        raise UserError(f"temperature profile: duration must be > 0 s, got {duration_s}")
    n = int(np.ceil(duration_s / step_s)) + 1
    return np.linspace(0.0, (n - 1) * step_s, n)


def warmup_profile(duration_s: float, ambient_degC: float, self_heating_degC: float,
                   time_constant_s: float, step_s: float = STEP_S) -> TemperatureProfile:
    """Switch-on warm-up T(t) = T_amb + ΔT (1 - exp(-t / τ)).

    Parameters
    ----------
    duration_s : length, s
    ambient_degC : ambient (and switch-on) temperature, °C
    self_heating_degC : final internal temperature rise ΔT, °C
    time_constant_s : thermal time constant τ, s
    step_s : grid step, s
    """
    t = _grid(duration_s, step_s)
    return TemperatureProfile(t, ambient_degC + self_heating_degC * -np.expm1(-t / time_constant_s),
                              "warmup")


def ramp_profile(duration_s: float, low_degC: float, high_degC: float, start_degC: float,
                 soak_s: float = 0.0, step_s: float = STEP_S) -> TemperatureProfile:
    """Chamber thermal cycle: a soak, then start → high → low → start at a constant rate.

    Parameters
    ----------
    duration_s : length, s
    low_degC, high_degC : the cycle's extremes, °C
    start_degC : switch-on, soak and final temperature, °C (between the extremes)
    soak_s : time held at ``start_degC`` before the cycle, s (< ``duration_s``)
    step_s : grid step, s
    """
    if not low_degC <= start_degC <= high_degC:
        raise UserError(f"ramp profile: start {start_degC} degC outside [{low_degC}, {high_degC}]")
    if not 0.0 <= soak_s < duration_s:
        raise UserError(f"ramp profile: soak {soak_s} s must be in [0, {duration_s}) s")
    t = _grid(duration_s, step_s)
    knots_degC = np.array([start_degC, high_degC, low_degC, start_degC])
    travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(knots_degC)))])
    frac = np.clip((t - soak_s) / (t[-1] - soak_s), 0.0, 1.0)
    return TemperatureProfile(t, np.interp(frac * travel[-1], travel, knots_degC), "ramp")


def constant_profile(duration_s: float, temp_degC: float, step_s: float = STEP_S
                     ) -> TemperatureProfile:
    """A constant temperature ``temp_degC`` (°C) for ``duration_s`` (s) on a ``step_s`` (s) grid."""
    t = _grid(duration_s, step_s)
    return TemperatureProfile(t, np.full(t.size, float(temp_degC)), "constant")


def read_profile(path: str | Path, duration_s: float | None = None) -> TemperatureProfile:
    """Read a CSV profile and put it on a 1-s grid.

    Parameters
    ----------
    path : CSV file with header ``t_s,temperature_degC`` (s from switch-on, °C)
    duration_s : length of the test it must cover, s (None: not checked)

    Raises
    ------
    UserError : unreadable file, missing column, non-numeric value, time not increasing, or the
        profile shorter than the test (file, line and field named).
    """
    p = Path(path)
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"{p}: cannot read temperature profile: "
                        f"{getattr(exc, 'strerror', None) or exc}") from None
    need = ("t_s", "temperature_degC")
    if not rows or any(k not in rows[0] for k in need):
        raise UserError(f"{p}: temperature profile needs a header with columns "
                        f"{', '.join(need)} and at least two rows")
    try:
        t = np.array([float(r["t_s"]) for r in rows])
        temp = np.array([float(r["temperature_degC"]) for r in rows])
    except (TypeError, ValueError):
        bad = next(i for i, r in enumerate(rows) if not _is_number(r["t_s"])
                   or not _is_number(r["temperature_degC"]))
        raise UserError(f"{p}: line {bad + 2}: t_s and temperature_degC must be numbers") from None
    if t.size < 2 or not np.all(np.isfinite(t)) or not np.all(np.isfinite(temp)):
        raise UserError(f"{p}: temperature profile needs at least two finite rows")
    if t[0] != 0.0 or np.any(np.diff(t) <= 0):
        raise UserError(f"{p}: field t_s must start at 0 s and increase strictly")
    if duration_s is not None and t[-1] < duration_s:
        raise UserError(f"{p}: the profile covers {t[-1]:g} s but the test lasts {duration_s:g} s")
    grid = _grid(t[-1], STEP_S)
    grid = grid[grid <= t[-1]]
    return TemperatureProfile(grid, np.interp(grid, t, temp), p.stem)


def _is_number(s) -> bool:
    try:
        float(s)
    except (TypeError, ValueError):
        return False
    return True


def profile_for(option: str | Path, spec: MemsSpec, duration_s: float) -> TemperatureProfile:
    """The profile a test asks for.

    Parameters
    ----------
    option : ``warmup`` | ``ramp`` | ``constant`` (built from the preset's ``temperature``
        block) or the path of a CSV profile
    spec : the preset
    duration_s : length of the test, s
    """
    t = spec.temperature
    name = str(option)
    if name == "warmup":
        return warmup_profile(duration_s, t.warmup_ambient_degC, t.warmup_self_heating_degC,
                              t.warmup_time_constant_s)
    if name == "ramp":
        return ramp_profile(duration_s, *t.operating_range_degC, t.constant_degC, t.ramp_soak_s)
    if name == "constant":
        return constant_profile(duration_s, t.constant_degC)
    if Path(name).suffix.lower() != ".csv":
        raise UserError(f"temperature profile {name!r}: expected {', '.join(PROFILE_NAMES)} "
                        "or a .csv file (columns t_s, temperature_degC)")
    return read_profile(name, duration_s)


def hysteresis_state(temp_degC: np.ndarray, width_degC: float) -> np.ndarray:
    """Normalised hysteresis state h = (T - play_w(T)) / w ∈ [-1, 1] of a play operator.

    The operator starts relaxed (output = the first temperature, h = 0: the sensor has rested
    unpowered at that temperature) and follows p_k = clip(p_{k-1}, T_k - w, T_k + w).

    Parameters
    ----------
    temp_degC : (n,) temperature samples, °C (a profile grid: the loop runs once per sample)
    width_degC : half-width w of the dead band, °C
    """
    temp = np.asarray(temp_degC, float)
    out = np.empty_like(temp)
    p = float(temp[0])
    w = float(width_degC)
    for i, x in enumerate(temp.tolist()):
        if p < x - w:
            p = x - w
        elif p > x + w:
            p = x + w
        out[i] = p
    return (temp - out) / w
