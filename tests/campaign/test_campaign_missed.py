"""``missed`` in a condition set: accepted, part of the canonical form (the case id), passed to
approach cases only."""

from fms_testbed.campaign.conditions import command_line_sets, make_conditions


def test_missed_enters_the_canonical_form_and_only_when_set():
    a = make_conditions({"name": "calm"}, "x")
    b = make_conditions({"name": "calm", "missed": True}, "x")
    assert b.missed and not a.missed
    assert '"missed":true' in b.canonical() and "missed" not in a.canonical()
    assert a.canonical() != b.canonical()
    # a default name says so
    assert make_conditions({"missed": True}, "x").name.endswith("missed")
    sets = command_line_sets([None], [{"source": "truth"}], missed=True)
    assert [s.missed for s in sets] == [True]


def test_missed_reaches_approach_cases_only():
    from fms_testbed.campaign.cases import Case

    cond = make_conditions({"name": "calm", "missed": True}, "x")
    mk = lambda t: Case("0" * 16, "KDEN", t, "I16R", "", "", "737", "", cond, 0, "")  # noqa: E731
    assert mk("APPROACH").scenario("db.dat")["procedure"]["missed"] is True
    assert "missed" not in mk("SID").scenario("db.dat")["procedure"]
