"""The test database's procedures (:mod:`.testdb`): SIDs, STARs and approaches that fly every
path terminator and the leg combinations that matter, and the deliberately miscoded ones, each
with the outcome it is designed to have."""

from __future__ import annotations

from fms_testbed.procedures.testdb_world import (TDA, TDB, Expect, Part, TestProcedure, _leg)

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
PROCEDURES: tuple[TestProcedure, ...] = tuple(sids + stars + apps + bad)
"""The test database's procedures (:mod:`.testdb`)."""
