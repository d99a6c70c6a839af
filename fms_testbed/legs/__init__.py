"""The ARINC-424 legs: one class per path terminator (:mod:`.types`), the shared leg builder and the
geometric constructions the legs use. A leg turns its record and the flight state into path
segments (:class:`~fms_testbed.core.segments.Line`/:class:`~fms_testbed.core.segments.Arc`)."""
