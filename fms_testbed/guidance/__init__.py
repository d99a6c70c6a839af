"""Guidance: the procedure guidance (:mod:`.fms`) flying a built procedure on the navigation
solution and the air data — never the true state — split by concern: locating the aircraft on
the path (:mod:`.locate`, :mod:`.geometry`), sequencing the legs (:mod:`.sequencing`), replanning
(:mod:`.replan`, :mod:`.conditions`), the lateral law (:mod:`.lateral`, :mod:`.steering`), the
vertical step (:mod:`.vnav`, :mod:`.vertical`, :mod:`.speed_plan`, :mod:`.profile_kernel`) and
the log (:mod:`.step_log`). Its interface is :class:`~fms_testbed.core.contracts.Guidance`."""
