"""Gain schedule of the coupled law in dynamic pressure and mass (the table itself is
:mod:`fms_testbed.guidance.vertical_schedule`: VNAV's read-ahead follows it too, and guidance
is below the control layer)."""

from fms_testbed.guidance.vertical_schedule import (MASS_LEVEL_REL, REFRESH_REL, SCHEDULED,
                                                    GainSchedule, MassLevel, qbar_from_state,
                                                    schedule_from_config, schedule_from_points)

__all__ = ["MASS_LEVEL_REL", "REFRESH_REL", "SCHEDULED", "GainSchedule", "MassLevel",
           "qbar_from_state", "schedule_from_config", "schedule_from_points"]
