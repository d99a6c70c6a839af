"""A rebuild on changed conditions that is not continuous is refused and the plan kept.

KBFI RNAV (RNP) Z 14R via ZUVEN (embedded database), 737, truth navigation, a 12 kt wind from
309° that the plan does not know (forecast calm): at 60 s the wind trigger fires mid-way along
the first TF; the rest rebuilt from there joined the RF JAMRO 127° off its tangent (built 33.8°
of its 97.7°) and was flown as two 360° loops while TSE, measured on the rebuilt path, read
5 m and the flight `ok`. Now that rebuild is refused with its reason and the approach is flown
as planned (a later rebuild on a straight leg is fine)."""

import math

import numpy as np

from fms_testbed.run import run_scenario

SCN = {"name": "rebuild-continuity", "aircraft": "737",
       "wind": {"from_deg": 309, "speed_kt": 12},
       "forecast": {"wind": {"from_deg": 0, "speed_kt": 0}},
       "procedure": {"db": "embedded", "airport": "KBFI", "procedure": "H14RZ",
                     "transition": "ZUVEN"}}


def test_a_discontinuous_rebuild_is_refused_and_the_plan_flown(tmp_path):
    import yaml
    f = tmp_path / "scn.yaml"
    f.write_text(yaml.safe_dump(SCN))
    res = run_scenario(f, progress=False)
    s = res.summary
    kept = [e for e in s["guidance_events"] if e["kind"] == "condition"
            and "not continuous" in e["detail"] and "plan is kept" in e["detail"]]
    assert kept and kept[0]["t_s"] < 70.0
    assert s["status"] == "ok" and s["duration_s"] < 420.0          # 379 s; the loops took 778 s
    df = res.df
    turned = np.unwrap(np.radians(df.track_deg.to_numpy()))
    assert abs(math.degrees(turned.max() - turned.min())) < 200.0   # no 360° loop
