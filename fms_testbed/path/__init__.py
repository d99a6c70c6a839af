"""The path: legs assembled into segments (:mod:`.segmentation`), the planned vertical profile
(:mod:`.profile`), the built-in parameter monitor (:mod:`.monitor`, Danilin) and the flight plan
built from a scenario's ``procedure:`` block (:mod:`.plan`)."""
