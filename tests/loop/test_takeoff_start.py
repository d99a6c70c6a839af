"""SIDs started with a takeoff roll (``procedure.start: takeoff``, loop/takeoff.py): real SIDs
of the FAA CIFP (cycle 2301; skipped, with the reason, when it is not beside the repository)
and of the embedded excerpt, flown from rest on the threshold to the end of the procedure,
and the refusals.

Ground-roll bands: the roll is V_lof² / (2 ā). The JSBSim 737 at its 48,534 kg accelerates at
0.31 g at 10 s (fx 3.0 m/s², measured) falling toward ~0.25 g at rotation (thrust lapse,
drag); lift-off comes between VR (145 kt) and V2 + 10 kt (160 kt): 800-1,400 m, asserted
800-1,600 m. The c172p: the POH ground roll is 890 ft (271 m) at 2,400 lb, sea level, 15 °C;
the model is lighter (853 kg) but rotates at the POH's 55 KIAS unscaled: 150-400 m.
"""

from __future__ import annotations


import numpy as np
import pytest
import yaml

from fms_testbed.cli import main
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import FT_M
from fms_testbed.data import aircraft_dir, scenarios_dir
from fms_testbed.loop.procedure import prepare
from fms_testbed.loop.takeoff import HANDOVER_HEIGHT_M
from fms_testbed.run import fly_procedure

SID = {"airport": "KSEA", "procedure": "BANGR9", "runway": "RW16L", "transition": "ARRIE"}



_CACHE: dict = {}


def _fly(db, aircraft: str, wind=None, **proc):
    key = (id(db), aircraft, wind, tuple(sorted(proc.items())))
    if key not in _CACHE:
        raw = {"aircraft": aircraft, "procedure": {"start": "takeoff", **proc}}
        if wind:
            raw["wind"] = {"from_deg": wind[0], "speed_kt": wind[1]}
        scn, spec, fp, d = prepare(raw, db=db)
        _CACHE[key] = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
    return _CACHE[key]


def _common_checks(res, cfg):
    s, df = res.summary, res.df
    assert s["status"] == "ok", s["reason"]
    assert s["sequencing"]["completed"]
    to = s["takeoff"]
    assert to["start"] == "takeoff" and to["runway"] == "RW16L"
    assert s["trim"]["tas_mps"] == 0.0                        # started at rest
    assert df["tas_mps"].iloc[0] < 1.0
    t = to["times_s"]
    # the order of the events of a takeoff
    assert t["rotate"] < t["liftoff"] < t["handover"]
    assert t["v2"] < t["handover"] and to["time_to_v2_s"] == t["v2"]
    ev = to["events"]
    assert ev["rotate"]["cas_mps"] == pytest.approx(to["vr_cas_mps"], abs=1.0)
    assert ev["handover"]["height_m"] >= HANDOVER_HEIGHT_M
    assert to["der_height_m"] >= 35 * FT_M                    # the screen height at the DER
    # on the centreline: nose wheel and rudder on the ground, bank in the air
    assert to["max_centreline_dev_ground_m"] < 2.0 and to["max_centreline_dev_air_m"] < 10.0
    # the ground roll is on the wheels with the takeoff flaps and the gear down
    roll = df[df["t_s"] < t["rotate"]]
    assert (roll["gear_pos_norm"] > 0.99).all()
    assert np.allclose(roll["flap_pos_norm"], cfg.takeoff.flaps_norm, atol=0.01)
    assert roll["agl_m"].between(0.5, 4.0).all()
    e = s["errors"]["fte"]["all"]
    assert e["p95_m"] <= 150.0, e
    return to


def test_737_takes_off_and_flies_a_real_cifp_sid(cifp):
    cfg = load_aircraft("737")
    res = _fly(cifp, "737", **SID)
    to = _common_checks(res, cfg)
    assert 800.0 <= to["ground_roll_m"] <= 1600.0, to
    assert to["time_to_v2_s"] < 45.0
    assert "gear_up" in to["times_s"]
    df = res.df
    # LNAV (the procedure guidance steering) from 400 ft, before the vertical handover
    t = to["times_s"]
    assert t["liftoff"] < t["lnav"] <= t["handover"]
    assert to["events"]["lnav"]["height_m"] >= 400 * FT_M
    assert df.loc[(df["t_s"] >= t["lnav"]) & (df["t_s"] < t["handover"]), "leg_code"].notna().all()
    assert df.loc[df["t_s"] >= to["handover_s"], "gear_pos_norm"].max() < 0.01


def test_c172p_takes_off_and_flies_a_real_cifp_sid(cifp):
    cfg = load_aircraft("c172p")
    res = _fly(cifp, "c172p", climb_top_ft=6000.0, **SID)
    to = _common_checks(res, cfg)
    assert 150.0 <= to["ground_roll_m"] <= 400.0, to
    assert "gear_up" not in to["times_s"]                       # fixed gear


def test_takeoff_from_the_embedded_excerpt():
    """KJFK DEEZZ5 RW31L (embedded: no CIFP needed), the 737."""
    res = _fly(None, "737", airport="KJFK", procedure="DEEZZ5", runway="31L",
               transition="CANDR")
    s = res.summary
    assert s["status"] == "ok", s["reason"]
    assert 800.0 <= s["takeoff"]["ground_roll_m"] <= 1600.0
    assert s["takeoff"]["max_centreline_dev_ground_m"] < 2.0
    # LNAV steers before the vertical handover, so the first turn (971 m past the runway
    # end, 110° left) is flown from its start (handed over whole there: overshot by 172 m)
    assert s["errors"]["fte"]["all"]["max_m"] < 50.0, s["errors"]["fte"]["all"]
    # no push-over at the handover (0.53 g when handed over 30 kt below the climb speed)
    df = res.df
    t_h = s["takeoff"]["handover_s"]
    near = df[(df["t_s"] > t_h - 5) & (df["t_s"] < t_h + 30)]
    assert near["ny"].min() > 0.65


@pytest.mark.parametrize("wind", [(40.0, 15.0), (121.0, 10.0)], ids=["crosswind", "tailwind"])
def test_takeoff_in_wind_holds_the_centreline(wind):
    """KJFK RW31L (true bearing 301°): 15 kt from 040° (99° right of the nose), 10 kt straight
    tailwind (at rest it would put alpha at 180°: the wind comes in once rolling, so no
    envelope alarm)."""
    res = _fly(None, "737", wind=wind, airport="KJFK", procedure="DEEZZ5", runway="31L",
               transition="CANDR")
    s = res.summary
    assert s["status"] == "ok", s["reason"]
    assert s["takeoff"]["max_centreline_dev_ground_m"] < 3.0
    assert s["takeoff"]["max_centreline_dev_air_m"] < 30.0
    assert 800.0 <= s["takeoff"]["ground_roll_m"] <= 1800.0


def test_takeoff_is_refused_for_a_star(capsys, tmp_path):
    rc = main(["fly", "--scenario", str(scenarios_dir() / "star-kjfk-parch3.yaml"),
               "--takeoff", "--no-plots", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert "procedure.start" in err and "STAR" in err and "Traceback" not in err
    assert len(err.splitlines()) == 1


def test_takeoff_is_refused_without_a_runway():
    with pytest.raises(ConfigError, match=r"procedure\.start.*runway"):
        prepare({"aircraft": "737", "procedure": {"airport": "KJFK", "procedure": "DEEZZ5",
                                                  "transition": "CANDR", "start": "takeoff"}})


def test_takeoff_is_refused_for_an_aircraft_without_takeoff_settings(tmp_path):
    raw = yaml.safe_load((aircraft_dir() / "737.yaml").read_text())
    raw.pop("takeoff")
    path = tmp_path / "no-takeoff.yaml"
    path.write_text(yaml.safe_dump(raw))
    with pytest.raises(ConfigError, match="has no takeoff settings"):
        prepare({"aircraft": str(path), "procedure": {
            "airport": "KJFK", "procedure": "DEEZZ5", "runway": "31L", "start": "takeoff"}})


def test_start_must_be_airborne_or_takeoff():
    with pytest.raises(ConfigError, match=r"procedure\.start"):
        prepare({"aircraft": "737", "procedure": {"airport": "KJFK", "procedure": "DEEZZ5",
                                                  "runway": "31L", "start": "catapult"}})


def test_a_takeoff_that_cannot_rotate_ends_diverged_at_the_runway_end(tmp_path):
    """VR far above what the 737 reaches on KJFK 31L (4,423 m): the flight ends ``diverged``
    with the reason, not ``ok`` and not a hang."""
    raw = yaml.safe_load((aircraft_dir() / "737.yaml").read_text())
    raw["takeoff"].update(vr_cas_mps=150.0, v2_cas_mps=155.0)
    path = tmp_path / "737-no-rotation.yaml"
    path.write_text(yaml.safe_dump(raw))
    scn, spec, fp, d = prepare({"aircraft": str(path), "procedure": {
        "airport": "KJFK", "procedure": "DEEZZ5", "runway": "31L", "transition": "CANDR",
        "start": "takeoff"}})
    res = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
    s = res.summary
    assert s["status"] == "diverged"
    assert "takeoff: still on the wheels at the runway end" in s["reason"]
    assert "liftoff" not in s["takeoff"]["times_s"]
    assert res.df["t_s"].iloc[-1] < 120.0
