"""Sensors, the truth side: error realisations of the inertial sensors (the 33-state SINS error
model, :mod:`.sins`), the GNSS receiver (:mod:`.gnss`), the baro altimeter (:mod:`.baro`), and
synthetic manoeuvre profiles to run them along (:mod:`.profiles`). The navigation layer turns
them into solutions."""
