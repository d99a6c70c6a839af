"""Planning constants shared by the leg builder, the path, guidance and the flight loop: one place
for the numbers a procedure is planned with (SI; the aviation value in each docstring)."""

from __future__ import annotations

from fms_testbed.core.units import FT_M

PLANNED_BANK_DEG = 20.0
"""Bank angle turns are planned with, deg (fly-by and fly-over turns, DF turns, arcs' ground
speed limit; the ARINC 424 / PANS-OPS planning bank for the terminal area is 15-25°)."""

SCREEN_HEIGHT_M = 35.0 * FT_M
"""Height above the runway at which a departure starts and the approach threshold is crossed in
the planning (35 ft: the take-off screen height, the reference of a SID's climb), m."""

PROC_TYPE_NAMES: dict[str, str] = {"D": "SID", "E": "STAR", "F": "APPROACH"}
"""ARINC 424 procedure-type letter (section P subsection D/E/F) → its name."""
