"""The closed loop: one flight as one loop of named steps (read → check → wind → navigate → air
data → events → guide → phase change → command → log → advance) over its phases (takeoff,
airborne), :class:`~fms_testbed.loop.flight.Flight` for stepping it, :class:`~.log.FlightLog`
for what it logs and :class:`~.record.FlightRecord` for what it reports."""
