"""Guidance: lateral path following (:mod:`.lateral`, :mod:`.geometry`), vertical targets
(:mod:`.vertical`) and the procedure guidance that sequences the legs (:mod:`.fms`). Guidance flies on
the navigation solution and returns :class:`~fms_testbed.core.contracts.GuidanceOutput`."""
