"""The test database's world and vocabulary (:mod:`.testdb`): the synthetic airports, their
runways, VOR/DMEs and fixes (:func:`world`), and the types a test procedure is stated in
(:class:`Leg`, :class:`Part`, :class:`Expect`, :class:`TestProcedure`)."""

from __future__ import annotations

from dataclasses import dataclass, field

from fms_testbed.procedures.synth import offset

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
