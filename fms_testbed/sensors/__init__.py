"""Sensors, the truth side: error realisations of the inertial sensors (the 33-state SINS error
model, :mod:`.sins`) and, later, GNSS and baro. The navigation layer turns them into solutions."""
