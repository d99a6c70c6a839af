"""Aircraft configuration files: every shipped file loads; bad files give one-line errors."""

from __future__ import annotations

import pytest
import yaml

from fms_testbed.config.aircraft import list_aircraft, load_aircraft, load_aircraft_file
from fms_testbed.core.errors import ConfigError
from fms_testbed.data import aircraft_dir

SHIPPED = list_aircraft()


def test_the_three_categories_are_shipped():
    cats = {load_aircraft(n).category for n in SHIPPED}
    assert {"narrow-body", "business-jet", "light"} <= cats
    assert {"737", "global5000", "c172p"} <= set(SHIPPED)


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_config_is_valid(name):
    cfg = load_aircraft(name)
    assert cfg.limits.cas_min_mps < cfg.limits.cas_max_mps
    assert len(cfg.envelope) >= 3
    assert cfg.coupled_law is not None


def _write(tmp_path, mutate):
    raw = yaml.safe_load((aircraft_dir() / "737.yaml").read_text())
    mutate(raw)
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(raw))
    return p


@pytest.mark.parametrize("mutate, field", [
    (lambda r: r["limits"].update(bank_max_deg=80), "limits.bank_max_deg"),
    (lambda r: r["inner_loops"]["ny"].update(kq=1.0), "inner_loops.ny.kq"),
    (lambda r: r["limits"].update(cas_min_mps="fast"), "limits.cas_min_mps"),
    (lambda r: r.pop("jsbsim_model"), "jsbsim_model"),
    (lambda r: r["inner_loops"].update(frames_per_update=0), "inner_loops.frames_per_update"),
    (lambda r: r["inner_loops"].update(frames_per_update=1.5), "inner_loops.frames_per_update"),
])
def test_bad_config_names_file_and_field(tmp_path, mutate, field):
    p = _write(tmp_path, mutate)
    with pytest.raises(ConfigError) as exc:
        load_aircraft_file(p)
    msg = str(exc.value)
    assert str(p) in msg and field in msg and "\n" not in msg


def test_unknown_aircraft_lists_the_shipped_ones():
    with pytest.raises(ConfigError, match="737"):
        load_aircraft("concorde-x")
