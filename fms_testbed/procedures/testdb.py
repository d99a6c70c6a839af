"""The phase-1 test database (Danilin, seed 000): about 50 synthesised procedures with the
outcome each is designed to have, written beside it as a manifest.

Danilin's method flies a test database of ~50 synthesised procedures first; only when its
residual error rate is acceptable does the software go on to the integration phase (~100
airports, > 5,000 procedure flights). This module states that database: two synthetic
airports (``XTDA``, magnetic variation 0°; ``XTDB``, variation 10° E so its magnetic courses
must be turned true), their runways, VOR/DMEs and fixes, and SIDs, STARs and approaches that
together fly every one of the 23 path terminators and the leg combinations that matter
(CA→DF, VI/CI→CF intercepts, VA→VM, FM→HM, IF→AF, TF→RF→TF, PI then the final, hold entries
from each ICAO sector, CF after DF, every altitude descriptor, speed limits, fly-over and
fly-by), approaches with missed-approach legs (parsed, not flown: an approach ends at the
MAP), and deliberately miscoded procedures — Danilin's class 3, database coding errors — each
with what the monitor should say.

Every expectation is design intent, stated here before any flight (module
:data:`PROCEDURES`, field ``expect``); the campaign check (:mod:`fms_testbed.campaign.manifest`)
compares a run's outcomes with it. Expectation kinds:

* ``fly`` — a valid procedure: flown to its end with a status in ``status`` (``ok``) and the
  monitor's verdict in ``monitor`` (``ok``; ``corrected`` where a correction is designed in),
  the finding text matching ``says`` when given;
* ``refuse`` — a coding error the software must not fly: status ``impossible`` (the builder or
  the monitor refuses) or ``degraded`` (a record rejected, a sequence number repeated), the
  reason matching ``says``;
* ``flag`` — a coding error that can be flown but must be reported: whatever the flight's
  status, the monitor's findings (or the refusal's reason) match ``says``.

Geometry: every fix is placed by bearing (deg true) and distance (NM) from an airport or
another fix (:func:`world`), so the database is self-contained and parses with
:func:`~fms_testbed.procedures.database.load_database`.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

from fms_testbed.procedures.synth import (airport_record, leg_record, offset, runway_record,
                                          vor_record, waypoint_record)

MANIFEST_KIND = "fms-testbed-testdb-manifest"
"""``kind`` of a test-database manifest."""
MANIFEST_VERSION = 1

AIRPORTS = {"XTDA": (46.0, 8.0, 0.0), "XTDB": (46.0, 10.0, 10.0)}
"""Synthetic airports: ICAO → (lat deg, lon deg, magnetic variation deg, east positive)."""
RUNWAY_LENGTH_FT = 12000
"""Length of every runway, ft (the departure end is 2 NM beyond the threshold)."""
TDA, TDB = "XTDA", "XTDB"


def world() -> dict[str, tuple[float, float]]:
    """Every named point of the test database (lat deg, lon deg): airports, thresholds,
    VOR/DMEs (``TDV`` 10 NM north of XTDA, ``TDA`` on XTDA, ``TDB`` on XTDB) and fixes."""
    a = AIRPORTS[TDA][:2]
    b = AIRPORTS[TDB][:2]

    def at(brg: float, nm: float, frm=a):
        return offset(*frm, brg, nm)

    p = {"APT_A": a, "APT_B": b, "RW09": at(270, 1.0), "RW27": at(90, 1.0),
         "TDV": at(0, 10.0), "TDA": a, "TDB": b}
    p.update({
        "E12": at(90, 12), "E25": at(90, 25), "NE20": at(45, 20), "NE45": at(45, 45),
        "N30": at(0, 30), "N50": at(0, 50), "SE20": at(135, 20), "W15": at(270, 15),
        "W30": at(270, 30), "W12": at(270, 12), "NW15": at(315, 15), "S40": at(180, 40),
        "S25": at(180, 25), "SW15": at(225, 15), "SWI": offset(*at(180, 10), 270, 20),
        "IF09": at(270, 15), "FF09": at(270, 7), "IF27": at(90, 15), "FF27": at(90, 7),
        "SD27": at(90, 11), "PIE": at(90, 3), "PIF": at(270, 10),
    })
    p["E3"] = offset(*p["E12"], 45, 12)
    p["NE2"] = offset(*p["E25"], 0, 15)
    # STAR TF -> RF (3 NM, left, 90°) -> TF: south along 15 W, then east
    p["T2B"] = offset(*at(270, 15), 0, 10)
    p["T2X"] = offset(*p["T2B"], 90, 3)
    p["T2C"] = offset(*p["T2X"], 180, 3)
    p["T2D"] = offset(*p["T2C"], 90, 7)
    p["T2A"] = offset(*p["T2B"], 0, 20)
    # approach TF -> RF (3 NM, left) -> TF onto the 090 final at 12 W
    p["RFC"] = at(270, 12)
    p["RFX"] = offset(*p["RFC"], 0, 3)
    p["RFB"] = offset(*p["RFX"], 270, 3)
    p["RFA"] = offset(*p["RFB"], 0, 10)
    p["RFXE"] = offset(*p["RFX"], 90, 0.6)          # a centre 0.6 NM off (miscoded)
    # the same with a 1 NM radius (the monitor must slow the aircraft down: branch V,γ)
    p["RTC"] = at(270, 10)
    p["RTX"] = offset(*p["RTC"], 0, 1)
    p["RTB"] = offset(*p["RTX"], 270, 1)
    p["RTA"] = offset(*p["RTB"], 0, 10)
    # 12 NM DME arc about TDA, radial 330 to radial 270, flown left
    p["ARW1"] = at(330, 12)
    p["ARW2"] = at(270, 12)
    p["ARW2X"] = at(270, 14)                           # 2 NM off the arc (miscoded)
    # hold-entry arrivals at IF09 (right-hand hold, inbound 090). With θ = arrival track −
    # inbound course: direct θ ∈ [−70°, 110°], teardrop (110°, 180°], parallel (−180°, −70°)
    # (ICAO Doc 8168 sectors 3, 2, 1 for right turns): tracks 090 (θ 0), 300 (θ −150),
    # 240 (θ +150)
    p["HDX"] = offset(*p["IF09"], 270, 12)
    p["HPX"] = offset(*p["IF09"], 120, 12)
    p["HTX"] = offset(*p["IF09"], 60, 12)
    # XTDB, variation 10° E: runway 09 (magnetic) is 100° true
    p["RWB09"] = offset(*b, 280, 1.0)
    p["BE12"] = offset(*b, 100, 12)
    p["BE24"] = offset(*p["BE12"], 100, 12)
    return p


VORS = {"TDV": TDA, "TDA": TDA, "TDB": TDB}
"""VOR/DME ident → the airport whose variation it carries."""
RUNWAYS = {("XTDA", "RW09"): ("RW09", 90.0), ("XTDA", "RW27"): ("RW27", 270.0),
           ("XTDB", "RW09"): ("RWB09", 90.0)}
"""(airport, runway) → (point, magnetic bearing deg)."""


@dataclass(frozen=True)
class Leg:
    """One coded leg: path terminator and :func:`~.synth.leg_record` keywords (``seq`` forces
    a sequence number; ``corrupt`` = (column, text) overwrites columns of the written record)."""

    pt: str
    kw: dict = field(default_factory=dict)
    seq: int | None = None
    corrupt: tuple[int, str] | None = None


def _leg(pt: str, fix: str = "", seq: int | None = None, corrupt=None, **kw) -> Leg:
    """A leg; a ``fix`` that is a VOR gets section 'D ', a runway 'PG'."""
    if fix:
        kw["fix"] = fix
        if fix in VORS:
            kw.setdefault("fix_section", "D ")
        elif fix.startswith("RW"):
            kw.setdefault("fix_section", "PG")
    return Leg(pt, kw, seq, corrupt)


@dataclass(frozen=True)
class Part:
    """One database sequence: route type, transition ident, legs in order."""

    route_type: str
    transition: str
    legs: tuple[Leg, ...]


@dataclass(frozen=True)
class Expect:
    """What the procedure is designed to give (module docstring: the kinds)."""

    kind: str                          # 'fly' | 'refuse' | 'flag'
    status: tuple[str, ...] = ("ok",)
    monitor: tuple[str, ...] = ("ok",)
    says: str = ""                     # regex (case-insensitive) the findings/reason match
    defect_class: int | None = None    # Danilin class of the coding error planted (3)
    monitor_should_say: str = ""       # in words


@dataclass(frozen=True)
class TestProcedure:
    """One synthesised procedure: identity, purpose, its database sequences and expectation."""

    airport: str
    type: str                          # 'SID' | 'STAR' | 'APPROACH'
    ident: str
    purpose: str
    combos: tuple[str, ...]
    parts: tuple[Part, ...]
    expect: Expect

    @property
    def subsection(self) -> str:
        """ARINC-424 subsection: D SID, E STAR, F approach."""
        return {"SID": "D", "STAR": "E", "APPROACH": "F"}[self.type]

    def case_key(self) -> tuple[str, str]:
        """(runway, transition) the regression run flies with ``--combinations each``: the
        first runway and en-route transition (SID/STAR), the first approach transition."""
        if self.type == "APPROACH":
            trans = [p.transition for p in self.parts if p.route_type == "A"]
            return "", trans[0] if trans else ""
        rw = [p.transition for p in self.parts if p.transition.startswith("RW")]
        en = [p.transition for p in self.parts
              if p.transition not in ("", "ALL") and not p.transition.startswith("RW")]
        return (rw[0] if rw else ""), (en[0] if en else "")

    def flown_legs(self) -> list[str]:
        """Path terminators in flying order (SID: runway, common, en-route; STAR: en-route,
        common, runway; approach: transition, final) without an IF repeating the fix the
        previous part ends at, an approach cut at its first missed-approach leg."""
        rw = [p for p in self.parts if p.transition.startswith("RW")][:1]
        com = [p for p in self.parts if p.transition in ("", "ALL") and p.route_type != "A"][:1]
        en = [p for p in self.parts if p.transition not in ("", "ALL")
              and not p.transition.startswith("RW")][:1]
        if self.type == "SID":
            order = rw + com + en
        elif self.type == "STAR":
            order = en + com + rw
        else:
            order = [p for p in self.parts if p.route_type == "A"][:1] + com
        out: list[Leg] = []
        for part in order:
            legs = list(part.legs)
            if out and legs and legs[0].pt == "IF" and \
                    legs[0].kw.get("fix") == out[-1].kw.get("fix"):
                legs = legs[1:]
            out += legs
        if self.type == "APPROACH":
            cut = next((i for i, lg in enumerate(out)
                        if lg.kw.get("desc", "    ")[2:3] == "M"), len(out))
            out = out[:cut]
        return [lg.pt for lg in out]

    def coded_legs(self) -> list[str]:
        """Every coded path terminator of the procedure, missed approach included."""
        return [lg.pt for p in self.parts for lg in p.legs]


FLY = Expect("fly")
MAP = "G  M"          # runway fix, missed-approach point
MISSED = "  M "       # first leg of the missed approach
FAF = "E  F"
FLYOVER = "EY  "


def _sid(airport, ident, purpose, combos, legs, expect=FLY, runway="RW09", extra=()):
    return TestProcedure(airport, "SID", ident, purpose, tuple(combos),
                         (Part("1", runway, tuple(legs)),) + tuple(extra), expect)


def _star(ident, purpose, combos, parts, expect=FLY):
    return TestProcedure(TDA, "STAR", ident, purpose, tuple(combos), tuple(parts), expect)


def _app(ident, purpose, combos, final, trans=None, expect=FLY, route="R"):
    parts = ((Part("A", trans[0], tuple(trans[1])),) if trans else ()) + \
        (Part(route, "", tuple(final)),)
    return TestProcedure(TDA, "APPROACH", ident, purpose, tuple(combos), parts, expect)


def _final09(vpa=-3.1, missed=True):
    legs = [_leg("IF", "IF09", alt_desc="+", alt1_ft=4000, speed_kt=210, speed_desc="-"),
            _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
            _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=vpa)]
    if missed:
        legs += [_leg("CA", desc=MISSED, course_deg=90.0, alt_desc="+", alt1_ft=1500),
                 _leg("DF", "E12"), _leg("HM", "E12", turn="R", course_deg=270.0, time_min=1.0)]
    return legs


def _ca(course=90.0, alt=1000):
    return _leg("CA", course_deg=course, alt_desc="+", alt1_ft=alt)


def _refuse(says, should, status=("impossible",)):
    return Expect("refuse", status=status, monitor=(), says=says, defect_class=3,
                  monitor_should_say=should)


def _flag(says, should):
    return Expect("flag", status=(), monitor=(), says=says, defect_class=3,
                  monitor_should_say=should)


def _procedures() -> list[TestProcedure]:
    sids = [
        _sid(TDA, "DCADF1", "course to altitude, then direct to a fly-by fix, then TF",
             ["CA→DF", "DF→TF fly-by", "at or above", "between"],
             [_ca(alt=1500), _leg("DF", "NE20", alt_desc="+", alt1_ft=5000),
              _leg("TF", "N30", alt_desc="B", alt1_ft=10000, alt2_ft=8000)]),
        _sid(TDA, "DCFDF1", "CF after DF; an at-or-below cap, then an at-or-above",
             ["CA→DF", "DF→CF", "at or below", "at or above"],
             [_ca(alt=800), _leg("DF", "E12", alt_desc="-", alt1_ft=3000),
              _leg("CF", "E3", course_deg=45.0, alt_desc="+", alt1_ft=6000)]),
        _sid(TDA, "DVICF1", "heading to altitude, heading to intercept the next CF",
             ["VA→VI", "VI→CF intercept"],
             [_leg("VA", course_deg=90.0, alt_desc="+", alt1_ft=1000),
              _leg("VI", course_deg=180.0, turn="R"), _leg("CF", "SWI", course_deg=270.0)]),
        _sid(TDA, "DCICF1", "course to intercept the next CF",
             ["CA→CI", "CI→CF intercept"],
             [_ca(), _leg("CI", course_deg=200.0, turn="R"), _leg("CF", "SWI", course_deg=270.0)]),
        _sid(TDA, "DVAVM1", "heading to altitude, then vectors (manual termination)",
             ["VA→VM"],
             [_leg("VA", course_deg=90.0, alt_desc="+", alt1_ft=1200), _leg("VM", course_deg=45.0)]),
        _sid(TDA, "DCDDF1", "course to a DME distance of TDV, then direct",
             ["CD→DF"],
             [_leg("CD", course_deg=90.0, navaid="TDV", distance_nm=12.0), _leg("DF", "NE20")]),
        _sid(TDA, "DVDDF1", "heading to a DME distance of TDV, then direct",
             ["VD→DF"],
             [_leg("VD", course_deg=90.0, navaid="TDV", distance_nm=15.0), _leg("DF", "SE20")]),
        _sid(TDA, "DCRDF1", "course to the TDV 120 radial, then direct (CR: absent from FAA "
                            "data)", ["CR→DF"],
             [_leg("CR", course_deg=90.0, navaid="TDV", theta_deg=120.0), _leg("DF", "SE20")]),
        _sid(TDA, "DVRDF1", "heading to the TDV 150 radial, then direct",
             ["VR→DF"],
             [_leg("VR", course_deg=90.0, navaid="TDV", theta_deg=150.0), _leg("DF", "NE20")]),
        _sid(TDA, "DFADF1", "fix to altitude from a fix reached direct",
             ["CA→DF", "DF→FA", "FA→DF"],
             [_ca(), _leg("DF", "E12"), _leg("FA", "E12", course_deg=90.0, alt_desc="+",
                                       alt1_ft=6000), _leg("DF", "NE2")]),
        _sid(TDA, "DFCDF1", "track from a fix for 6 NM",
             ["DF→FC", "FC→DF"],
             [_ca(), _leg("DF", "E12"), _leg("FC", "E12", course_deg=90.0, distance_nm=6.0),
              _leg("DF", "NE2")]),
        _sid(TDA, "DFDDF1", "track from a fix to a DME distance (FD: absent from FAA data)",
             ["DF→FD", "FD→DF"],
             [_ca(), _leg("DF", "E12"), _leg("FD", "E12", course_deg=90.0, navaid="TDV",
                                       distance_nm=20.0), _leg("DF", "NE2")]),
        _sid(TDA, "DFMHM1", "track from a fix to manual termination, then a hold to manual "
                            "termination (direct entry)", ["DF→FM", "FM→HM", "HM direct entry"],
             [_ca(), _leg("DF", "E12"), _leg("FM", "E12", course_deg=90.0),
              _leg("HM", "E25", turn="R", course_deg=90.0, distance_nm=4.0)]),
        _sid(TDA, "DHADF1", "climb in a hold to an altitude, then on",
             ["DF→HA", "HA→DF", "HA direct entry"],
             [_ca(), _leg("DF", "E12"), _leg("HA", "E12", turn="R", course_deg=90.0, time_min=1.0,
                                       alt_desc="+", alt1_ft=9000), _leg("DF", "E25")]),
        _sid(TDA, "DHFTF1", "runway 27: one hold circuit (left turns), then TF",
             ["CA→DF", "DF→HF", "HF→TF", "left-hand hold"],
             [_ca(course=270.0, alt=1500), _leg("DF", "W15"),
              _leg("HF", "W15", turn="L", course_deg=270.0, time_min=1.0), _leg("TF", "W30")],
             runway="RW27"),
        _sid(TDA, "DOVER1", "fly-over fix with an at constraint, then a 45° turn",
             ["DF fly-over→TF", "at"],
             [_ca(), _leg("DF", "E12", desc=FLYOVER, alt_desc=" ", alt1_ft=3000),
              _leg("TF", "E3", alt_desc="+", alt1_ft=5000)]),
        _sid(TDA, "DFLBY1", "the same fix fly-by",
             ["DF fly-by→TF", "at"],
             [_ca(), _leg("DF", "E12", alt_desc=" ", alt1_ft=3000),
              _leg("TF", "E3", alt_desc="+", alt1_ft=5000)]),
        _sid(TDA, "DSPD1", "speed limits at or below and at; a between window",
             ["speed at or below", "speed at", "between"],
             [_ca(), _leg("DF", "E12", alt_desc="+", alt1_ft=3000, speed_kt=210, speed_desc="-"),
              _leg("TF", "E25", alt_desc="B", alt1_ft=8000, alt2_ft=6000, speed_kt=230,
                speed_desc=" ")]),
        _sid(TDA, "DTRN1", "runway transition, common route, en-route transition merged",
             ["runway→common→en-route"],
             [_ca(), _leg("DF", "E12")],
             extra=(Part("2", "", (_leg("TF", "E25", alt_desc="+", alt1_ft=5000),)),
                    Part("3", "NE2", (_leg("TF", "NE2"),)))),
        _sid(TDB, "BMAG1", "XTDB (variation 10° E): magnetic courses turned true",
             ["CA→DF", "DF→CF", "magnetic course"],
             [_ca(), _leg("DF", "BE12"), _leg("CF", "BE24", course_deg=90.0)]),
    ]
    stars = [
        _star("ATF1", "en-route transition then common route of TF legs; descents in windows",
              ["IF→TF", "en-route→common", "at", "at or below", "between", "speed at or below",
               "speed at"],
              [Part("1", "N50", (_leg("IF", "N50", alt_desc=" ", alt1_ft=15000, speed_kt=250,
                                   speed_desc="-"),
                                 _leg("TF", "N30", alt_desc="-", alt1_ft=11000))),
               Part("2", "", (_leg("TF", "NW15", alt_desc="B", alt1_ft=7000, alt2_ft=5000),
                              _leg("TF", "W12", alt_desc=" ", alt1_ft=4000, speed_kt=220,
                                speed_desc=" ")))]),
        _star("ARF1", "TF, constant-radius arc (3 NM, left, 90°), TF",
              ["TF→RF→TF"],
              [Part("2", "", (_leg("IF", "T2A", alt_desc=" ", alt1_ft=9000),
                              _leg("TF", "T2B", alt_desc="-", alt1_ft=8000),
                              _leg("RF", "T2C", turn="L", centre="T2X", arc_radius_nm=3.0),
                              _leg("TF", "T2D", alt_desc=" ", alt1_ft=6000)))]),
        _star("AHM1", "ends in a hold to manual termination (direct entry)",
              ["TF→HM", "HM direct entry"],
              [Part("2", "", (_leg("IF", "NE45", alt_desc=" ", alt1_ft=10000),
                              _leg("TF", "NE20", alt_desc=" ", alt1_ft=6000),
                              _leg("HM", "NE20", turn="R", course_deg=225.0, time_min=1.0)))]),
        _star("AFM1", "ends in a track from a fix to manual termination",
              ["TF→FM"],
              [Part("2", "", (_leg("IF", "W30", alt_desc=" ", alt1_ft=9000),
                              _leg("TF", "W15", alt_desc=" ", alt1_ft=5000),
                              _leg("FM", "W15", course_deg=90.0)))]),
        _star("ADSC1", "descriptors C, Y, X, @ and a speed at or above",
              ["at (@)", "at or above (C)", "at or below (Y)", "at (X)", "speed at or above"],
              [Part("2", "", (_leg("IF", "S40", alt_desc="@", alt1_ft=14000),
                              _leg("TF", "S25", alt_desc="C", alt1_ft=11000, alt2_ft=11000,
                                speed_kt=250, speed_desc="-"),
                              _leg("TF", "SW15", alt_desc="Y", alt1_ft=8000, speed_kt=200,
                                speed_desc="+"),
                              _leg("TF", "W12", alt_desc="X", alt1_ft=5000)))]),
    ]
    apps = [
        _app("R09", "RNAV final, 3.1° to the runway; missed approach CA, DF, HM",
             ["IF→TF", "at or above", "at", "vertical angle", "missed CA→DF→HM"], _final09()),
        _app("R27", "approach transition then the final; missed approach VA, VM",
             ["transition→final", "missed VA→VM"],
             [_leg("IF", "IF27", alt_desc="+", alt1_ft=4000),
              _leg("TF", "FF27", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW27", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1),
              _leg("VA", desc=MISSED, course_deg=270.0, alt_desc="+", alt1_ft=1000),
              _leg("VM", course_deg=270.0)],
             trans=("E25", [_leg("IF", "E25", alt_desc=" ", alt1_ft=6000),
                            _leg("TF", "IF27", alt_desc="+", alt1_ft=4000)])),
        _app("R09Z", "TF, RF (3 NM, left, 90°) onto the final, TF",
             ["TF→RF→TF", "between", "glide-slope at (G)"],
             [_leg("IF", "RFA", alt_desc=" ", alt1_ft=5000),
              _leg("TF", "RFB", alt_desc=" ", alt1_ft=4000),
              _leg("RF", "RFC", turn="L", centre="RFX", arc_radius_nm=3.0, alt_desc="B",
                alt1_ft=4000, alt2_ft=3000),
              _leg("TF", "FF09", desc=FAF, alt_desc="G", alt1_ft=2000, alt2_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)]),
        _app("R09T", "a 1 NM RF: too tight at 210 kt for 25° of bank: the monitor slows "
                     "the aircraft (branch V,γ)", ["TF→RF→TF", "RF V,γ correction"],
             [_leg("IF", "RTA", alt_desc=" ", alt1_ft=4000),
              _leg("TF", "RTB", alt_desc=" ", alt1_ft=3000),
              _leg("RF", "RTC", turn="L", centre="RTX", arc_radius_nm=1.0),
              _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=Expect("fly", monitor=("corrected",), says=r"speed \d+ -> \d+ kt",
                           monitor_should_say="RF radius 1.00 NM: speed reduced so the arc "
                                              "is flown at 25° of bank (branch V,γ)")),
        _app("V09A", "VOR/DME: IF on the 12 NM arc, DME arc to the final course, CF",
             ["IF→AF", "AF→CF", "at or above (J, V)", "glide-slope at (I)"],
             [_leg("IF", "ARW1", alt_desc="J", alt1_ft=4000),
              _leg("AF", "ARW2", turn="L", navaid="TDA", theta_deg=270.0, rho_nm=12.0,
                course_deg=330.0, alt_desc="V", alt1_ft=3000),
              _leg("CF", "FF09", desc=FAF, course_deg=90.0, alt_desc="I", alt1_ft=2000,
                alt2_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1),
              _leg("CA", desc=MISSED, course_deg=90.0, alt_desc="+", alt1_ft=1500),
              _leg("DF", "E12"), _leg("HM", "E12", turn="R", course_deg=270.0, time_min=1.0)],
             route="V"),
        _app("S09P", "procedure turn (PI) at PIF, then the final CF inbound",
             ["TF→PI", "PI→CF", "course reversal"],
             [_leg("IF", "PIE", alt_desc=" ", alt1_ft=3000),
              _leg("TF", "PIF", alt_desc=" ", alt1_ft=3000),
              _leg("PI", "PIF", turn="L", course_deg=315.0, distance_nm=10.0, alt_desc="+",
                alt1_ft=3000),
              _leg("CF", "PIF", desc=FAF, course_deg=90.0, alt_desc=" ", alt1_ft=3000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)], route="S"),
    ]
    for ident, fx, sector, trk in (("H09D", "HDX", "direct", 90), ("H09P", "HPX", "parallel", 300),
                                   ("H09T", "HTX", "teardrop", 240)):
        apps.append(_app(
            ident, f"hold-in-lieu HF at IF09 (right turns, inbound 090) arrived on track "
                   f"{trk:03d}: ICAO {sector} entry sector", [f"TF→HF {sector} entry",
                                                             "HF→final"],
            _final09(missed=False),
            trans=(fx, [_leg("IF", fx, alt_desc=" ", alt1_ft=4000),
                        _leg("TF", "IF09", alt_desc=" ", alt1_ft=4000),
                        _leg("HF", "IF09", turn="R", course_deg=90.0, time_min=1.0,
                          alt_desc=" ", alt1_ft=4000)])))
    apps.append(_app(
        "R27V", "descriptors H, Y, X and @ on a stepdown final",
        ["at or above (H)", "at or below (Y)", "at (X)", "at (@)"],
        [_leg("IF", "IF27", alt_desc="H", alt1_ft=4000),
         _leg("TF", "SD27", alt_desc="Y", alt1_ft=3500),
         _leg("TF", "FF27", desc=FAF, alt_desc="X", alt1_ft=2000),
         _leg("TF", "RW27", desc=MAP, alt_desc="@", alt1_ft=50, vpa_deg=-3.1)]))

    bad = [
        _app("XTFNF", "a TF with no fix", ["TF without fix"],
             [_leg("IF", "IF09", alt_desc=" ", alt1_ft=4000), _leg("TF", alt_desc=" ", alt1_ft=3000),
              _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_refuse(r"TF leg without a fix", "impossible: leg 2 TF without a fix "
                                                      "(column 30)")),
        _app("XRFDR", "the RF of R09Z coded to turn right: against its tangent entry and "
                      "the 90° left arc its fixes give", ["RF inconsistent turn direction"],
             [_leg("IF", "RFA", alt_desc=" ", alt1_ft=5000),
              _leg("TF", "RFB", alt_desc=" ", alt1_ft=4000),
              _leg("RF", "RFC", turn="R", centre="RFX", arc_radius_nm=3.0),
              _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_flag(r"discontinu|track jumps|turn|doubles|loop|impossible",
                          "the coded right turn is flown the long way (270°) and starts "
                          "against the inbound track: a discontinuity (track jump or a turn "
                          "against the coding) must be reported")),
        _app("XRFCT", "the RF of R09Z with its centre 0.6 NM east: the fixes are 3.6 and "
                      "3.06 NM from it, the coded radius 3.0 NM", ["RF wrong centre"],
             [_leg("IF", "RFA", alt_desc=" ", alt1_ft=5000),
              _leg("TF", "RFB", alt_desc=" ", alt1_ft=4000),
              _leg("RF", "RFC", turn="L", centre="RFXE", arc_radius_nm=3.0),
              _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_flag(r"radius coded|arc angle|gap|discontinu|misses|not start",
                          "the RF radius disagrees with its fixes (branch R) and the arc does "
                          "not start at the previous fix (discontinuity)")),
        _sid(TDA, "XCLB1", "15,000 ft at or above 11 NM after take-off: a 22 % climb",
             ["impossible climb gradient"],
             [_ca(alt=800), _leg("DF", "E12", alt_desc="+", alt1_ft=15000)],
             expect=_refuse(r"needs [\d.]+% climb",
                            "impossible: E12 at or above 15000 ft needs ~22 % climb, above "
                            "the aircraft's gradient even at its minimum speed")),
        _star("XLOOP", "the path N30→NW15 coded twice (Danilin Fig. 4: the path drawn twice)",
              ["path flown twice"],
              [Part("2", "", (_leg("IF", "N30", alt_desc=" ", alt1_ft=11000), _leg("TF", "NW15"),
                              _leg("TF", "W12"), _leg("TF", "N30"), _leg("TF", "NW15"),
                              _leg("TF", "W12", alt_desc=" ", alt1_ft=4000)))],
              expect=_flag(r"flown twice|loop", "loop: path N30->NW15 flown twice")),
        _sid(TDA, "XCINI", "a CI parallel to the CF it should intercept (never meets it)",
             ["intercept that never happens"],
             [_ca(), _leg("CI", course_deg=90.0), _leg("CF", "SWI", course_deg=270.0)],
             expect=_flag(r"intercept", "no-intercept: the CI course never meets the CF's "
                                        "course line (bounded search)")),
        _app("XNOFX", "a TF to a fix that has no record", ["fix not in the database"],
             [_leg("IF", "IF09", alt_desc=" ", alt1_ft=4000),
              _leg("TF", "ZZQ01", alt_desc=" ", alt1_ft=3000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_refuse(r"ZZQ01", "refused: ZZQ01 is not in the database",
                            status=("impossible", "degraded"))),
        _sid(TDA, "XBADC", "a course field '9X00' the parser cannot read",
             ["record rejected"],
             [_ca(), _leg("DF", "E12"), _leg("CF", "E3", course_deg=45.0, corrupt=(71, "9X00"))],
             expect=_refuse(r"course", "degraded (rejected): the CF record's course field",
                            status=("degraded",))),
        _app("XDUPS", "sequence number 020 coded twice", ["duplicate sequence number"],
             [_leg("IF", "IF09", alt_desc=" ", alt1_ft=4000),
              _leg("TF", "FF09", seq=20, desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", seq=20, desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_refuse(r"duplicate|sequence", "degraded (duplicate): sequence number 020",
                            status=("degraded",))),
        _app("XRFNC", "an RF with no centre fix", ["RF without centre"],
             [_leg("IF", "RFA", alt_desc=" ", alt1_ft=5000), _leg("TF", "RFB"),
              _leg("RF", "RFC", turn="L", arc_radius_nm=3.0),
              _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_refuse(r"centre|center", "impossible: RF without its centre fix "
                                              "(column 107)")),
        _app("XAFRH", "an AF whose fix is 14 NM from the DME, rho coded 12 NM",
             ["AF fix off its arc"],
             [_leg("IF", "ARW1", alt_desc=" ", alt1_ft=4000),
              _leg("AF", "ARW2X", turn="L", navaid="TDA", theta_deg=270.0, rho_nm=12.0,
                course_deg=330.0),
              _leg("CF", "FF09", desc=FAF, course_deg=90.0, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             route="V",
             expect=_flag(r"radius|arc|rho|gap|discontinu|misses",
                          "the AF's fix is 2 NM off the coded DME arc: a radius correction, "
                          "a gap or a missed fix must be reported")),
        _app("XHFNC", "a hold-in-lieu HF with no inbound course", ["HF without course"],
             _final09(missed=False),
             trans=("HDX", [_leg("IF", "HDX", alt_desc=" ", alt1_ft=4000),
                            _leg("TF", "IF09", alt_desc=" ", alt1_ft=4000),
                            _leg("HF", "IF09", turn="R", time_min=1.0)]),
             expect=_refuse(r"course", "impossible: HF without a course (column 71)")),
        _app("XDSC1", "14,000 ft at IF09, 2,000 ft at FF09 8 NM later: a 25 % descent",
             ["impossible descent"],
             [_leg("IF", "IF09", alt_desc=" ", alt1_ft=14000),
              _leg("TF", "FF09", desc=FAF, alt_desc=" ", alt1_ft=2000),
              _leg("TF", "RW09", desc=MAP, alt_desc=" ", alt1_ft=50, vpa_deg=-3.1)],
             expect=_refuse(r"descent .*needs", "impossible: descent to FF09 needs ~25 %, "
                                                "beyond the descent rate at minimum speed")),
        _sid(TDA, "XCANA", "a CA with no altitude", ["CA without altitude"],
             [_leg("CA", course_deg=90.0), _leg("DF", "E12")],
             expect=_refuse(r"altitude", "impossible: CA without a termination altitude "
                                         "(column 85)")),
        _sid(TDA, "XTURN", "a TF coded to turn right where its track is 45° left of the "
                           "previous one", ["inconsistent turn direction"],
             [_ca(), _leg("DF", "E12"), _leg("TF", "E3", turn="R")],
             expect=_flag(r"turn", "the coded right turn makes a 315° turn for a 45° track "
                                   "change: a turn against the short way by more than 270° "
                                   "must be reported")),
    ]
    return sids + stars + apps + bad


PROCEDURES: tuple[TestProcedure, ...] = tuple(_procedures())
"""The test database's procedures (module docstring)."""


def _fix_records(pts: dict) -> list[str]:
    out = []
    for ident, apt in VORS.items():
        out.append(vor_record(ident, *pts[ident], var_deg=AIRPORTS[apt][2]))
    skip = {"APT_A", "APT_B", "RW09", "RW27", "RWB09"} | set(VORS)
    for name in sorted(pts):
        if name not in skip:
            out.append(waypoint_record(name, *pts[name]))
    return out


def _airport_records(pts: dict) -> list[str]:
    out = []
    for icao, (lat, lon, var) in AIRPORTS.items():
        out.append(airport_record(icao, lat, lon, var_deg=var))
        for (apt, rwy), (pt, brg) in RUNWAYS.items():
            if apt == icao:
                out.append(runway_record(icao, rwy, *pts[pt], brg, length_ft=RUNWAY_LENGTH_FT))
    return out


def procedure_records(proc: TestProcedure) -> list[str]:
    """The leg records of one procedure, in file order (sequence numbers 010, 020, ...).

    Parameters
    ----------
    proc : the procedure
    """
    out = []
    for part in proc.parts:
        for k, lg in enumerate(part.legs):
            rec = leg_record(proc.airport, proc.ident, lg.pt, lg.seq or 10 * (k + 1),
                             proc_type=proc.subsection, transition=part.transition,
                             route_type=part.route_type, **lg.kw)
            if lg.corrupt:
                col, text = lg.corrupt
                rec = rec[:col - 1] + text + rec[col - 1 + len(text):]
            out.append(rec)
    return out


def records() -> list[str]:
    """Every record of the test database: navaids and fixes, airports and runways, then the
    procedures (each transition's records consecutive)."""
    pts = world()
    out = _fix_records(pts) + _airport_records(pts)
    for icao in AIRPORTS:
        for sub in "DEF":
            for p in PROCEDURES:
                if p.airport == icao and p.subsection == sub:
                    out += procedure_records(p)
    return out


def manifest(db_sha256: str) -> dict:
    """The manifest of the test database (design intent; module docstring).

    Parameters
    ----------
    db_sha256 : SHA-256 of the written database file (the check refuses another file)
    """
    entries = []
    for p in PROCEDURES:
        runway, trans = p.case_key()
        e = asdict(p.expect)
        e["status"], e["monitor"] = list(e["status"]), list(e["monitor"])
        entries.append({"airport": p.airport, "type": p.type, "procedure": p.ident,
                        "runway": runway, "transition": trans, "purpose": p.purpose,
                        "combinations": list(p.combos),
                        "coding": "valid" if p.expect.kind == "fly" else "miscoded",
                        "flown_legs": " ".join(p.flown_legs()),
                        "coded_legs": " ".join(p.coded_legs()), "expect": e})
    return {"kind": MANIFEST_KIND, "version": MANIFEST_VERSION, "database_sha256": db_sha256,
            "airports": list(AIRPORTS), "procedures": entries}


def manifest_path(db_path: str | Path) -> Path:
    """Where the manifest of a database file is: beside it, ``FILE.manifest.json``.

    Parameters
    ----------
    db_path : the database file
    """
    db_path = Path(db_path)
    return db_path.with_name(db_path.name + ".manifest.json")


def write_testdb(path: str | Path) -> tuple[Path, Path]:
    """Write the test database (132-column records) and its manifest beside it.

    Parameters
    ----------
    path : the database file to write (its folder must exist)

    Returns
    -------
    (database path, manifest path)
    """
    path = Path(path)
    data = "".join(r + "\n" for r in records()).encode("latin-1")
    path.write_bytes(data)
    mpath = manifest_path(path)
    mpath.write_text(json.dumps(manifest(hashlib.sha256(data).hexdigest()), indent=1,
                                ensure_ascii=False) + "\n", encoding="utf-8")
    return path, mpath


__all__ = ["AIRPORTS", "MANIFEST_KIND", "MANIFEST_VERSION", "PROCEDURES", "Expect", "Leg",
           "Part", "TestProcedure", "manifest", "manifest_path", "procedure_records", "records",
           "world", "write_testdb"]
