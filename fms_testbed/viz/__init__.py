"""Plots and map exports. No backend is set at import; plot functions take data and return
matplotlib Figures, and saving is the caller's (:func:`fms_testbed.viz.figure.save`).

Units: plots of a flight (ground tracks, profiles, time histories: :mod:`.run`,
:mod:`.procedure`, :mod:`.path`) use the aviation edge — NM, ft, kt, ft/min, path errors in m;
engineering plots of one subsystem stay SI as their sources draw them (:mod:`.control`: the
coupled law in m and km/h like the paper; :mod:`.sins`: m, mrad; :mod:`.inner`: deg, g, s).
Tracks for Google Earth/QGIS: :mod:`.geojson`, :mod:`.kml` (altitudes m above mean sea level).
"""
