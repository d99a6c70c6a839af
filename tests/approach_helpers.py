"""A synthetic RNAV approach written as ARINC-424 records (procedures/synth.py): runway 09 of
KSYN at 1,000 ft with a 50 ft TCH, IAF 20 NM and IF 10 NM west (200 kt 'at or below' at the IF),
FAF 5 NM west (at or above 2,600 ft), MAP at the threshold on a 3.00° VPA (1,050 ft), and a
missed approach CA (runway heading to 1,500 ft) → DF HOLDX (10 NM east, 3,000 ft) → HM."""

from __future__ import annotations

from fms_testbed.procedures import synth

THR = (40.0, -100.0)
ELEV_FT = 1000
TCH_FT = 50
VPA_DEG = 3.0


def write_synthetic_approach(path) -> str:
    """Write the database file; return its path as text."""
    wp = {"IAFXX": synth.offset(*THR, 270.0, 20.0), "IFXXX": synth.offset(*THR, 270.0, 10.0),
          "FAFXX": synth.offset(*THR, 270.0, 5.0), "HOLDX": synth.offset(*THR, 90.0, 10.0)}
    recs = [synth.airport_record("KSYN", THR[0], THR[1] - 0.01, elev_ft=ELEV_FT + 20),
            synth.runway_record("KSYN", "RW09", THR[0], THR[1], 90.0, elev_ft=ELEV_FT,
                                tch_ft=TCH_FT)]
    recs += [synth.waypoint_record(k, la, lo, airport="KSYN") for k, (la, lo) in wp.items()]
    leg = dict(airport="KSYN", proc="R09", fix_section="PC")
    recs += [
        synth.leg_record(pt="IF", seq=10, fix="IAFXX", desc="E  A", alt_desc="+", alt1_ft=5000,
                         **leg),
        synth.leg_record(pt="TF", seq=20, fix="IFXXX", desc="E  I", alt_desc="+", alt1_ft=3000,
                         speed_kt=200, speed_desc="-", **leg),
        synth.leg_record(pt="TF", seq=30, fix="FAFXX", desc="E  F", alt_desc="+", alt1_ft=2600,
                         **leg),
        synth.leg_record(airport="KSYN", proc="R09", pt="TF", seq=40, fix="RW09",
                         fix_section="PG", desc="GY M", alt1_ft=ELEV_FT + TCH_FT,
                         vpa_deg=-VPA_DEG),
        synth.leg_record(airport="KSYN", proc="R09", pt="CA", seq=50, desc="  M ",
                         course_deg=90.0, alt_desc="+", alt1_ft=1500),
        synth.leg_record(pt="DF", seq=60, fix="HOLDX", desc="EY  ", alt_desc="+",
                         alt1_ft=3000, **leg),
        synth.leg_record(pt="HM", seq=70, fix="HOLDX", desc="EE  ", turn="R", course_deg=270.0,
                         time_min=1.0, alt_desc="+", alt1_ft=3000, **leg),
    ]
    return str(synth.write_file(path, recs))
