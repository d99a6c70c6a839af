"""The aircraft files' approach block: detents against the JSBSim models' own flap traverse,
Vapp scaling, validation."""

import xml.etree.ElementTree as ET
from pathlib import Path

import jsbsim
import pytest
from pydantic import ValidationError

from fms_testbed.config.aircraft import ApproachSettings, list_aircraft, load_aircraft


def _traverse_norm(model: str) -> list[float]:
    """The flap kinematic's settings of a wheel model, normalised by its last (JSBSim scales a
    normalised command by the last setting)."""
    root = ET.parse(Path(jsbsim.get_default_root_dir()) / "aircraft" / model
                    / f"{model}.xml").getroot()
    kin = next(k for k in root.iter("kinematic")
               if k.findtext("input", "").strip() == "fcs/flap-cmd-norm")
    pos = [float(s.findtext("position")) for s in kin.iter("setting")]
    return [p / pos[-1] for p in pos]


@pytest.mark.parametrize("name", list_aircraft())
def test_detents_are_the_models_own(name):
    cfg = load_aircraft(name)
    ap = cfg.approach
    assert ap is not None and ap.source
    settings = _traverse_norm(cfg.jsbsim_model)
    for f in ap.flaps:
        assert min(abs(f.cmd_norm - s) for s in settings) < 1e-3, (name, f.name)
        assert f.select_cas_mps <= f.max_cas_mps
    land = ap.flaps[ap.index(ap.landing_flap)]
    # Vapp below the landing detent's placard and selection speeds
    assert ap.vapp_cas_mps < land.select_cas_mps <= land.max_cas_mps


def test_vapp_scales_with_the_square_root_of_mass():
    ap = load_aircraft("737").approach
    assert ap.vapp_cas_mps_at(None) == ap.vapp_cas_mps
    assert ap.vapp_cas_mps_at(ap.mass_ref_kg * 1.21) == pytest.approx(1.1 * ap.vapp_cas_mps)


def test_bad_approach_blocks_are_refused():
    base = load_aircraft("737").approach.model_dump()
    with pytest.raises(ValidationError, match="landing_flap"):
        ApproachSettings.model_validate({**base, "landing_flap": "45"})
    flaps = list(reversed(base["flaps"]))
    with pytest.raises(ValidationError, match="from up to landing"):
        ApproachSettings.model_validate({**base, "flaps": flaps})
    with pytest.raises(ValidationError, match="go together"):
        ApproachSettings.model_validate({**base, "gear_down_height_m": None})
    f0 = dict(base["flaps"][1], select_cas_mps=200.0)
    with pytest.raises(ValidationError, match="above max_cas_mps"):
        ApproachSettings.model_validate({**base, "flaps": [base["flaps"][0], f0]})
