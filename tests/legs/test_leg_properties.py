"""Leg-type properties are class attributes of the leg classes, one table code -> class.

The expected sets are derived here from the ARINC-424 naming of the path terminators (first
letter: C course, V heading, F from a fix, H hold, ...; second letter: what ends the leg — A
altitude, D DME distance, R radial, F fix, M manual, I intercept, C distance), independently
of how the classes set them.
"""

from __future__ import annotations

import pytest

from fms_testbed.legs.base import Leg
from fms_testbed.legs.types import LEG_TYPES


def _codes(attr):
    return {c for c, cls in LEG_TYPES.items() if getattr(cls, attr)}


def test_heading_legs_are_the_v_legs():
    assert _codes("heading_leg") == {c for c in LEG_TYPES if c[0] == "V"}


def test_conditional_legs_end_at_an_altitude_dme_distance_or_radial_from_a_course():
    assert _codes("conditional") == {c for c in LEG_TYPES if c[0] in "CFV" and c[1] in "ADR"}


def test_altitude_terminated_legs_end_with_a():
    assert _codes("altitude_terminated") == {c for c in LEG_TYPES if c[1] == "A"}


def test_legs_ending_at_their_fix_are_the_to_fix_legs_and_the_holds():
    assert _codes("ends_at_fix") == {c for c in LEG_TYPES if c[1] == "F" or c[0] == "H"}


def test_holds_and_course_reversals():
    assert _codes("hold") == {c for c in LEG_TYPES if c[0] == "H"}
    assert _codes("course_reversal") == _codes("hold") | {"PI"}


def test_coded_arcs_give_their_radius_and_tolerance():
    assert {c: LEG_TYPES[c].arc_centre for c in _codes("arc_centre")} == {"RF": "fix",
                                                                         "AF": "navaid"}
    for c in _codes("arc_centre"):
        assert LEG_TYPES[c].radius_tol_m > 0


def test_a_leg_has_a_coded_path_exactly_when_its_class_builds_one():
    """pde_reference (the documented coded path) and coded_path (the builder of it) agree: no
    leg type documents a reference it does not build, or builds one it does not document."""
    for code, cls in LEG_TYPES.items():
        builds = cls.coded_path.__func__ is not Leg.coded_path.__func__
        assert builds == (cls.pde_reference is not None), code


def test_pde_is_defined_for_every_leg_type_with_a_coded_path():
    """The issue's list: TF, CF, RF, AF, the F* courses and the holds; DF, IF, PI and the
    C*/V* legs from the present position have none."""
    assert _codes("pde_reference") == {"TF", "CF", "RF", "AF", "FA", "FC", "FD", "FM",
                                       "HA", "HF", "HM"}


def test_a_new_leg_type_is_one_class_and_two_classes_for_one_code_are_refused():
    class ZZ(Leg):
        code = "ZZ"
        heading_leg = True

    try:
        assert LEG_TYPES["ZZ"] is ZZ and ZZ.heading_leg and not ZZ.conditional
        with pytest.raises(TypeError, match="two leg classes for ZZ"):
            type("ZZ2", (Leg,), {"code": "ZZ"})
    finally:
        del LEG_TYPES["ZZ"]
