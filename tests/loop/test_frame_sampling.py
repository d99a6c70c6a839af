"""Per-frame sampling for navigation sources whose sensors run at the JSBSim frame rate."""

from __future__ import annotations

import numpy as np
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.config.scenario import parse_scenario
from fms_testbed.core.state import NavSolution
from fms_testbed.loop.flight import Flight
from fms_testbed.navigation.truth import TruthNavigation

BASE = {"aircraft": "737", "duration_s": 3, "hold": True,
        "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400,
                    "heading_deg": 90}}


class Recorder(TruthNavigation):
    """Truth navigation that keeps every frame block it is handed."""

    frame_properties = (("simulation/sim-time-sec", 1.0), ("position/h-sl-ft", 0.3048))

    def __init__(self):
        self.calls = []

    def update(self, truth, frames=None) -> NavSolution:
        self.calls.append((truth.t_s, truth.alt_m, None if frames is None else frames.copy()))
        return super().update(truth)


def _fly_on_recorder(monkeypatch, scn, **kw):
    rec = Recorder()
    monkeypatch.setattr("fms_testbed.loop.flight.make_source", lambda spec, seed=None: rec)
    fl = Flight(scn, cfg=load_aircraft("737"), progress=False, **kw)
    fl.run()
    return fl, rec


def _check_blocks(fl, rec):
    assert rec.calls[0][2] is None                      # the first call: nothing sampled yet
    dt = fl.aircraft.dt_s
    t_all = []
    for (t, alt, frames), (t_prev, _, _) in zip(rec.calls[1:], rec.calls[:-1]):
        assert frames.shape == (fl.n_frames, 2)
        assert frames[-1, 0] == pytest.approx(t, abs=1e-9)        # last row: this step
        assert frames[-1, 1] == pytest.approx(alt, abs=1e-6)      # in SI (ft → m)
        assert np.allclose(np.diff(frames[:, 0]), dt)              # one row per frame
        assert frames[0, 0] == pytest.approx(t_prev + dt, abs=1e-9)
        t_all.extend(frames[:, 0])
    assert np.allclose(np.diff(t_all), dt)               # no frame missed or repeated
    return t_all


def test_every_frame_is_sampled_once_and_the_last_at_the_navigation_step(monkeypatch):
    fl, rec = _fly_on_recorder(monkeypatch, parse_scenario(BASE))
    _check_blocks(fl, rec)


def test_the_takeoff_and_the_airborne_phase_sample_one_stream_of_frames(monkeypatch):
    """A SID flown from the runway: the source sees every frame of the roll, the climb-out
    and the airborne phase after the handover, each once (the takeoff control runs its frames
    in chunks, the airborne phase in one block per outer step)."""
    from fms_testbed.loop.procedure import prepare_procedure

    scn, proc = prepare_procedure({"aircraft": "737", "duration_s": 110, "procedure": {
        "airport": "KJFK", "procedure": "DEEZZ5", "runway": "31L", "transition": "CANDR",
        "start": "takeoff"}})
    fl, rec = _fly_on_recorder(monkeypatch, scn, procedure=proc)
    handover = fl.takeoff.times_s["handover"]
    assert fl.phase.name == "airborne" and 0.0 < handover < 100.0
    t_all = _check_blocks(fl, rec)
    assert t_all[0] < handover < t_all[-1]
