"""The closed loop: one flight as named steps (read → navigate → guide → law → command → log),
:class:`~fms_testbed.loop.flight.Flight` for stepping it."""
