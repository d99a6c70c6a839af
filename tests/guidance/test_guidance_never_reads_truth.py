"""Guidance flies on the navigation solution and the air data, never on the true state: while
its ``update`` runs, every attribute of every true state raises (the slot descriptors of
:class:`~fms_testbed.core.state.AircraftState` are swapped for raising ones), and whole
procedures are flown that way — a SID from the runway in a wind the plan does not know (LNAV in
the takeoff climb, the changed-conditions rebuild, heading legs) and an ILS with its missed
approach (go-around speeds, the hold)."""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import fields

import pytest

from fms_testbed.core.state import AircraftState
from fms_testbed.loop.flight import Flight
from fms_testbed.loop.procedure import prepare_procedure
from fms_testbed.run import results_of


class TruthRead(AssertionError):
    """Guidance read the true state."""


def _raising(name: str) -> property:
    def get(self):
        raise TruthRead(f"guidance read truth.{name}")
    return property(get)


@contextmanager
def truth_poisoned():
    """Every AircraftState attribute read raises inside the block."""
    names = [f.name for f in fields(AircraftState)]
    saved = {n: AircraftState.__dict__[n] for n in names}
    try:
        for n in names:
            setattr(AircraftState, n, _raising(n))
        yield
    finally:
        for n, d in saved.items():
            setattr(AircraftState, n, d)


def _fly_poisoned(raw: dict):
    scn, proc = prepare_procedure(raw)
    flight = Flight(scn, procedure=proc, progress=False)
    g = flight.guidance
    inner = g.update
    calls = [0]

    def update(dt_s, nav, air):
        assert not isinstance(nav, AircraftState) and not isinstance(air, AircraftState)
        with truth_poisoned():
            out = inner(dt_s, nav, air)
        calls[0] += 1
        return out

    g.update = update
    flight.run()
    return results_of(flight), calls[0]


def test_the_poison_bites():
    s = AircraftState(*([0.0] * 8), None, *([0.0] * 12), None, 0.0, 0.0, 0.0, 0.0)
    with truth_poisoned():
        with pytest.raises(TruthRead):
            _ = s.tas_mps
    assert s.tas_mps == 0.0


def test_a_sid_from_the_runway_in_an_unplanned_wind_is_flown_without_truth():
    res, calls = _fly_poisoned({
        "aircraft": "737", "wind": {"from_deg": 250, "speed_kt": 25}, "forecast": {"calm": True},
        "procedure": {"airport": "KJFK", "procedure": "DEEZZ5", "runway": "31L",
                      "transition": "CANDR", "start": "takeoff"}})
    s = res.summary
    assert s.status == "ok", s.reason
    assert s.sequencing.completed and calls > 5000
    kinds = {e.kind for e in s.guidance_events}
    assert "rebuild" in kinds                      # the measured wind differs from the plan
    assert s.takeoff.times_s["lnav"] < s.takeoff.times_s["handover"]


def test_an_approach_with_its_missed_approach_is_flown_without_truth():
    res, calls = _fly_poisoned({
        "aircraft": "737", "procedure": {"airport": "KJFK", "procedure": "I13L",
                                         "transition": "KMCHI", "missed": True}})
    s = res.summary
    assert s.sequencing.completed, s.reason
    assert any(e.kind == "config" and e.detail == "go-around" for e in s.guidance_events)
    assert calls > 1000
