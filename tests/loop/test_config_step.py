"""Flaps and gear on the approach schedule and in a go-around (loop/steps.py ConfigStep)."""

from types import SimpleNamespace

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.units import KT_MPS
from fms_testbed.loop.steps import ConfigStep, Targets, flap_index_for_cas


class _Aircraft:
    def __init__(self):
        self.calls = []

    def configure(self, flap_cmd_norm=None, gear_down=None):
        self.calls.append((flap_cmd_norm, gear_down))


def _s(t, cas_kt, agl_ft=3000.0, vs=-3.5):
    return SimpleNamespace(t_s=t, cas_mps=cas_kt * KT_MPS, tas_mps=cas_kt * KT_MPS,
                           agl_m=agl_ft * 0.3048, vs_mps=vs)


def test_approach_schedule_then_go_around():
    ap = load_aircraft("737").approach
    ac, ev = _Aircraft(), []
    step = ConfigStep(ap, ac, 0, False, ev)
    tg = Targets(speed_kind="tas", speed_mps=140 * KT_MPS)
    step(_s(0, 215), tg, False)                     # above every selection speed: clean
    assert step.k == 0 and not ac.calls
    step(_s(1, 199), tg, False)                     # below flaps 1 (200 kt)
    assert ap.flaps[step.k].name == "1"
    step(_s(2, 169), tg, False)                     # 5 and 15 at once, gear with 15
    assert ap.flaps[step.k].name == "15" and step.gear_down
    tg.speed_mps = 160 * KT_MPS
    step(_s(3, 150), tg, False)                     # target above flaps 30's 155 kt: stays
    assert ap.flaps[step.k].name == "15"
    tg.speed_mps = 140 * KT_MPS
    step(_s(4, 150), tg, False)
    assert step.k == ap.index(ap.landing_flap)
    step(_s(5, 120), tg, False)                     # never past landing
    assert step.k == ap.index(ap.landing_flap)
    step(_s(6, 140, vs=-3.0), tg, True)             # go-around: flaps 15, gear still down
    assert ap.flaps[step.k].name == "15" and step.gear_down
    step(_s(7, 142, vs=5.0), tg, True)              # positive rate: gear up
    assert not step.gear_down
    step(_s(8, 176), tg, True)                      # 170 + 5 kt: flaps 5
    assert ap.flaps[step.k].name == "5"
    step(_s(9, 215), tg, True)
    assert step.k == 0
    details = [e["detail"] for e in ev]
    assert details[:4] == ["flaps 1", "flaps 15", "gear down", "flaps 30"]
    assert "go-around" in details and details[-1] == "flaps UP"
    assert ac.calls[-1] == (0.0, False)


def test_gear_by_height_and_fixed_gear():
    ap = load_aircraft("737").approach
    ac = _Aircraft()
    step = ConfigStep(ap, ac, 0, False)
    step(_s(0, 210, agl_ft=1900), Targets(), False)   # below 2,000 ft: gear down though clean
    assert step.gear_down and step.k == 0 and ac.calls == [(0.0, True)]
    c172 = load_aircraft("c172p").approach
    ac2 = _Aircraft()
    step2 = ConfigStep(c172, ac2, 0, False)
    step2(_s(0, 60, agl_ft=100), Targets(), False)
    assert ac2.calls and all(g is None for _, g in ac2.calls)   # the gear is never moved


def test_start_detent_follows_the_schedule():
    ap = load_aircraft("737").approach
    assert flap_index_for_cas(ap, 210 * KT_MPS) == 0
    assert ap.flaps[flap_index_for_cas(ap, 165 * KT_MPS)].name == "15"
    assert flap_index_for_cas(ap, 100 * KT_MPS) == ap.index(ap.landing_flap)
