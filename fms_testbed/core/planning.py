"""Planning constants shared by the leg builder, the path, guidance and the flight loop: one place
for the numbers a procedure is planned with (SI; the aviation value in each docstring)."""

from __future__ import annotations

from fms_testbed.core.units import FT_M, KT_MPS

PLANNED_BANK_DEG = 20.0
"""Bank angle turns are planned with, deg (fly-by and fly-over turns, DF turns, arcs' ground
speed limit; the ARINC 424 / PANS-OPS planning bank for the terminal area is 15-25°)."""

SCREEN_HEIGHT_M = 35.0 * FT_M
"""Height above the runway at which a departure starts and the approach threshold is crossed in
the planning (35 ft: the take-off screen height, the reference of a SID's climb), m."""

PROC_TYPE_NAMES: dict[str, str] = {"D": "SID", "E": "STAR", "F": "APPROACH"}
"""ARINC 424 procedure-type letter (section P subsection D/E/F) → its name."""

DECEL_MPS2 = 0.3
"""Deceleration (TAS along the path) a plan may count on to slow down — for a turn, an arc or a
speed limit ahead — and guidance slows at, m/s² (about 0.6 kt/s: idle thrust in a level or
shallow path, no speed brakes)."""

ACCEL_HEIGHT_M = 1000 * FT_M
"""Height above the runway where a departure accelerates from its climb-out speed, when the
aircraft file gives none (1,000 ft: the lowest of the usual 1,000-3,000 ft), m."""

DEPARTURE_ACCEL_MPS2 = 0.5
"""Acceleration (CAS along the path) a departure is planned to make good from the acceleration
height, when the aircraft file gives none, m/s² (about 1 kt/s)."""

SPEED_LIMIT_10000FT_CAS_MPS = 250 * KT_MPS
"""The speed limit below 10,000 ft (ICAO Annex 11 airspace classes C-G, FAA 14 CFR 91.117):
250 kt IAS, m/s (a CAS)."""

SPEED_LIMIT_ALT_M = 10000 * FT_M
"""The altitude below which :data:`SPEED_LIMIT_10000FT_CAS_MPS` applies, m."""

MIN_CLEAN_CAS_FACTOR = 1.15
"""The lowest CAS guidance flies clean is this multiple of the aircraft's minimum clean CAS
(``guidance.vertical`` floors its TAS target with it): a departure's climb-out speed is
planned no lower, so a SID started airborne (clean) flies the turn radii it was planned for."""

ARC_BANK_MARGIN_DEG = 3.0
"""Guidance flies arcs at a speed that needs at most the bank limit less this, deg; a turn a
departure must fly at the climb-out speed (no slower CAS is flown clean) is planned with this
margin below the bank limit too: its TAS grows as it climbs through the turn."""
