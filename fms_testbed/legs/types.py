"""The 23 ARINC-424 path terminators: one small class each, one table code -> class.

Every class turns the current leg (``b.leg``, a :class:`~.builder.ResolvedLeg`) and the planned
aircraft state into segments via the :class:`~.builder.LegBuilder` moves, and returns the end
state and the leg's :class:`~.model.Termination` (kept as data for guidance). Its class
attributes (:class:`~.base.Leg`) are what the builder, the monitor, guidance and the flight
errors ask about a leg type; its :meth:`~.base.Leg.coded_path` is the path the record defines,
for the path definition error.

The classes live by family — :mod:`.fix_legs` (IF TF CF DF RF AF), :mod:`.course_legs`
(CA CD CR CI VA VD VR VI VM, FA FC FD FM), :mod:`.holds` (HA HF HM PI) — and register
themselves in :data:`LEG_TYPES` when defined; importing this module loads every family.
"""

from __future__ import annotations

from fms_testbed.legs import course_legs, fix_legs, holds
from fms_testbed.legs.base import LEG_TYPES, Leg, LegError

_FAMILIES = (fix_legs, course_legs, holds)   # imported for their classes' registration

__all__ = ["LEG_TYPES", "Leg", "LegError"]
