"""`track.geojson` / `track.kml` for Google Earth and QGIS: the files parse, every coordinate
lies where the flight was (lon/lat not swapped, altitude MSL in m), one KML placemark per leg,
the navigation track only when it differs from the truth, and `Results.save` writes both."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from fms_testbed.data import scenarios_dir
from fms_testbed.run import run_scenario
from fms_testbed.viz.geojson import track_collection, track_points, write_track_geojson
from fms_testbed.viz.kml import leg_name, write_track_kml

KML = "{http://www.opengis.net/kml/2.2}"
MARGIN_DEG = 0.02     # the designed path lies within ~1 NM of where the aircraft flew


@pytest.fixture(scope="module")
def approach():
    """KJFK R04RY flown on truth (a 3-leg approach, ~165 s)."""
    return run_scenario({"aircraft": "737", "name": "kjfk-r04ry",
                         "procedure": {"airport": "KJFK", "procedure": "R04RY"}}, progress=False)


@pytest.fixture(scope="module")
def sins_approach():
    return run_scenario(scenarios_dir() / "approach-kbfi-h14rz-sins.yaml", progress=False)


def _bounds(df):
    return (df["lon_deg"].min(), df["lon_deg"].max(), df["lat_deg"].min(), df["lat_deg"].max(),
            df["alt_m"].min(), df["alt_m"].max())


def _within(coords, b, margin=1e-7, alt=True):
    """Every (lon, lat[, alt]) within the bounds (files round to 1e-7 deg and 0.1 m)."""
    c = np.asarray(coords, dtype=float)
    ok = ((c[:, 0] >= b[0] - margin) & (c[:, 0] <= b[1] + margin)
          & (c[:, 1] >= b[2] - margin) & (c[:, 1] <= b[3] + margin))
    if alt:
        ok &= (c[:, 2] >= b[4] - 0.05) & (c[:, 2] <= b[5] + 0.05)
    return bool(ok.all())


def _kml_folders(path):
    root = ET.parse(path).getroot()
    out = {}
    for f in root.iter(f"{KML}Folder"):
        out[f.find(f"{KML}name").text] = f.findall(f"{KML}Placemark")
    return out


def _coords(pm):
    el = next(pm.iter(f"{KML}coordinates"))
    return [tuple(float(x) for x in p.split(",")) for p in el.text.split()]


def test_geojson_track_has_the_designed_path_and_the_flown_3d_track(approach, tmp_path):
    res = approach
    path = res.procedure.path.path
    f = write_track_geojson(tmp_path / "track.geojson", res.df, res.summary, path)
    fc = json.loads(f.read_text())
    layers = [ft["properties"]["layer"] for ft in fc["features"]]
    assert layers.count("designed path") == len(path.segments)
    assert "navigation solution" not in layers               # truth navigation: same track
    b = _bounds(res.df)
    flown = next(ft for ft in fc["features"] if ft["properties"]["layer"] == "flown (truth)")
    coords = flown["geometry"]["coordinates"]
    assert all(len(c) == 3 for c in coords) and _within(coords, b)
    # one point a second of flight, plus the last one
    dur = res.df["t_s"].iloc[-1] - res.df["t_s"].iloc[0]
    assert abs(len(coords) - (dur + 1)) <= 2
    for ft in fc["features"]:
        if ft["properties"]["layer"] == "designed path":
            assert _within(ft["geometry"]["coordinates"], b, MARGIN_DEG, alt=False)


def test_kml_has_one_placemark_per_leg_and_an_absolute_flown_track(approach, tmp_path):
    res = approach
    path = res.procedure.path.path
    f = write_track_kml(tmp_path / "track.kml", res.df, res.summary, path)
    folders = _kml_folders(f)
    legs = folders["designed path"]
    assert [pm.find(f"{KML}name").text for pm in legs] == [leg_name(lg) for lg in path.legs]
    assert [pm.find(f"{KML}name").text for pm in legs][-1] == "3 TF RW04R"
    b = _bounds(res.df)
    for pm in legs:
        assert _within(_coords(pm), b, MARGIN_DEG, alt=False)
    flight = {pm.find(f"{KML}name").text: pm for pm in folders["flight"]}
    assert set(flight) == {"flown (truth)", "start", "end"}
    track = flight["flown (truth)"]
    assert next(track.iter(f"{KML}altitudeMode")).text == "absolute"
    c = _coords(track)
    assert _within(c, b) and len(c) == len(track_points(res.df))


def test_a_sins_flight_adds_the_navigation_track(sins_approach, tmp_path):
    res = sins_approach
    path = res.procedure.path.path
    layers = [ft["properties"]["layer"] for ft in
              track_collection(res.df, res.summary, path)["features"]]
    assert "navigation solution" in layers
    folders = _kml_folders(write_track_kml(tmp_path / "t.kml", res.df, res.summary, path))
    nav = next(pm for pm in folders["flight"]
               if pm.find(f"{KML}name").text == "navigation solution")
    c = np.asarray(_coords(nav))
    d = res.df.dropna(subset=["nav_lat_deg"])
    assert np.allclose(c[0, :2], [d["nav_lon_deg"].iloc[0], d["nav_lat_deg"].iloc[0]])
    assert np.allclose(c[-1, :2], [d["nav_lon_deg"].iloc[-1], d["nav_lat_deg"].iloc[-1]])


def test_run_of_a_plain_scenario_writes_the_flown_track(tmp_path):
    res = run_scenario(scenarios_dir() / "demo.yaml", progress=False)
    res.save(tmp_path / "demo", plots=False)
    assert res.summary["tracks"] == ["track.geojson", "track.kml"]
    folders = _kml_folders(tmp_path / "demo" / "track.kml")
    assert "designed path" not in folders
    track = next(pm for pm in folders["flight"] if pm.find(f"{KML}name").text == "flown (truth)")
    assert _within(_coords(track), _bounds(res.df))
    fc = json.loads((tmp_path / "demo" / "track.geojson").read_text())
    assert [ft["properties"]["layer"] for ft in fc["features"]] == ["flown (truth)"]


def test_paths_rebuilt_in_flight_are_numbered_as_legs_of_the_whole_procedure(tmp_path):
    """KDLS DALLS1 RW13: the CA ends at its altitude in flight and the rest is rebuilt; the
    rebuilt legs keep their numbers in the procedure (VR=1, CA=2, DF=3)."""
    res = run_scenario({"aircraft": "737", "name": "dalls1",
                        "procedure": {"airport": "KDLS", "procedure": "DALLS1", "runway": "13"}},
                       progress=False)
    assert res.flown_paths, "no path rebuilt in flight"
    path = res.procedure.path.path
    folders = _kml_folders(write_track_kml(tmp_path / "t.kml", res.df, res.summary, path,
                                           tuple(res.flown_paths)))
    names = [pm.find(f"{KML}name").text for pm in folders["rebuilt in flight"]]
    assert len(names) == sum(len(fp.path.legs) for fp in res.flown_paths)
    whole = {leg_name(lg) for lg in path.legs}
    for n in names:
        assert n.startswith("rebuild ") and n.split(": ", 1)[1] in whole, (n, whole)
