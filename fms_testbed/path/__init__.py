"""Path-segment data shared by the procedure builder, the monitor, guidance, GeoJSON and plots.

``Line`` and ``Arc`` are frozen dataclasses on WGS-84 (geodesics via geographiclib);
:func:`project` gives along-track, cross-track (right positive), desired track and curvature.
"""

from .geodesy import LocalFrame, direct, gravity_mps2, inverse, wrap180, wrap360
from .segments import Arc, Line, Segment, project, turn_angle_deg

__all__ = ["Arc", "Line", "LocalFrame", "Segment", "direct", "gravity_mps2", "inverse",
           "project", "turn_angle_deg", "wrap180", "wrap360"]
