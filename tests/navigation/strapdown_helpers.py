"""A JSBSim flight with turns and climbs, flown on truth, with a strapdown bank riding along on
the per-frame samples (the bank sees only what its IMU would; the flight is not affected)."""

from __future__ import annotations

from functools import lru_cache
from unittest.mock import patch

import numpy as np

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.config.scenario import parse_scenario
from fms_testbed.loop.flight import Flight
from fms_testbed.navigation.inertial.bank import StrapdownBank
from fms_testbed.navigation.truth import TruthNavigation

EVENTS = [{"t_s": 20, "heading_deg": 200}, {"t_s": 90, "alt_m": 3800},
          {"t_s": 200, "heading_deg": 20}, {"t_s": 260, "tas_kmh": 480},
          {"t_s": 330, "alt_m": 3200}, {"t_s": 400, "heading_deg": 300},
          {"t_s": 480, "heading_deg": 120}, {"t_s": 500, "alt_m": 4000}]


def scenario(duration_s: float) -> dict:
    """A 737 at 3000 m, 47° N: heading changes of 110-180°, climbs and descents of 600-800 m,
    a speed change (the events up to ``duration_s``)."""
    return {"aircraft": "737", "duration_s": duration_s, "hold": True, "vertical_law": "coupled",
            "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400,
                        "heading_deg": 90},
            "events": [e for e in EVENTS if e["t_s"] < duration_s]}


class BankProbe(TruthNavigation):
    """Truth navigation that drives a bank with the frames and keeps its errors and the true
    states (every ``every`` calls)."""

    def __init__(self, bank, every: int = 10, keep_frames: bool = False):
        self.bank, self.every = bank, every
        self.frame_properties = bank.frame_properties
        self.log: list[tuple[float, np.ndarray]] = []
        self.calls: list = []
        self.keep_frames = keep_frames
        self._n = 0

    def update(self, truth, frames=None):
        self.bank.update(truth, frames)
        if self.keep_frames:
            self.calls.append((truth, None if frames is None else frames.copy()))
        if self._n % self.every == 0:
            self.log.append((truth.t_s, np.array([self.bank.errors(i)
                                                  for i in range(len(self.bank))])))
        self._n += 1
        return super().update(truth)


def fly_with(bank, duration_s: float, keep_frames: bool = False) -> BankProbe:
    """Fly :func:`scenario` on truth with ``bank`` riding along; returns the probe."""
    probe = BankProbe(bank, keep_frames=keep_frames)
    with patch("fms_testbed.loop.flight.make_source", lambda spec, seed=None: probe):
        fl = Flight(parse_scenario(scenario(duration_s)), cfg=load_aircraft("737"),
                    progress=False)
    fl.run()
    return probe


@lru_cache(maxsize=4)
def error_free_flight(duration_s: float, lever: tuple = (0.0, 0.0, 0.0)) -> BankProbe:
    """:func:`fly_with` an error-free IMU (every declared error zero)."""
    return fly_with(StrapdownBank([{}], [1], lever_arm_m=lever), duration_s)


@lru_cache(maxsize=2)
def recorded_flight(duration_s: float) -> list:
    """The (truth, frames) of every navigation step of :func:`scenario` (frames with body rates)."""
    probe = fly_with(StrapdownBank([{}], [1], lever_arm_m=(1.0, 0.0, 0.0)), duration_s,
                     keep_frames=True)
    return probe.calls
