"""Wind as a profile over altitude: layers (altitude, direction it blows from, speed), the wind
vector interpolated linearly in altitude between them and held constant beyond the ends.

The north and east components are interpolated (not speed and direction apart): a layer of
270°/20 kt over one of 090°/20 kt gives calm air half-way, the shear the two layers describe.
A steady wind is the one-layer profile (:meth:`WindProfile.constant`).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class WindProfile:
    """Wind layers, SI: ``alt_m`` strictly increasing (m above MSL), ``north_mps`` /
    ``east_mps`` the velocity of the air (where it blows *to*) at each altitude, m/s."""

    alt_m: tuple[float, ...]
    north_mps: tuple[float, ...]
    east_mps: tuple[float, ...]

    def __post_init__(self):
        n = len(self.alt_m)
        if n == 0 or len(self.north_mps) != n or len(self.east_mps) != n:
            raise ValueError("a wind profile needs one or more layers, each with north and east")
        if any(b <= a for a, b in zip(self.alt_m, self.alt_m[1:])):
            raise ValueError("wind layer altitudes must increase strictly")

    @classmethod
    def from_layers(cls, layers) -> "WindProfile":
        """From ``(alt_m, from_deg, speed_mps)`` triples (altitude m, direction the wind blows
        from deg true, speed m/s), in increasing altitude."""
        alt, north, east = [], [], []
        for a, frm, spd in layers:
            to = math.radians(frm + 180.0)
            alt.append(float(a))
            north.append(spd * math.cos(to))
            east.append(spd * math.sin(to))
        return cls(tuple(alt), tuple(north), tuple(east))

    @classmethod
    def constant(cls, speed_mps: float, from_deg: float) -> "WindProfile":
        """A steady wind: speed (m/s) from ``from_deg`` (deg true) at every altitude."""
        return cls.from_layers([(0.0, from_deg, speed_mps)])

    @property
    def layered(self) -> bool:
        """True when the wind changes with altitude (more than one layer)."""
        return len(self.alt_m) > 1

    @property
    def max_speed_mps(self) -> float:
        """The largest wind speed of any layer, m/s (the interpolation never exceeds it)."""
        return max(math.hypot(n, e) for n, e in zip(self.north_mps, self.east_mps))

    def ned_at(self, alt_m: float) -> tuple[float, float]:
        """(north, east) velocity of the air at ``alt_m`` (m), m/s: linear in altitude between
        layers, the end layer's beyond the ends."""
        a = self.alt_m
        if len(a) == 1 or alt_m <= a[0]:
            return self.north_mps[0], self.east_mps[0]
        if alt_m >= a[-1]:
            return self.north_mps[-1], self.east_mps[-1]
        k = bisect.bisect_right(a, alt_m)
        f = (alt_m - a[k - 1]) / (a[k] - a[k - 1])
        n, e = self.north_mps, self.east_mps
        return n[k - 1] + f * (n[k] - n[k - 1]), e[k - 1] + f * (e[k] - e[k - 1])

    def at(self, alt_m: float) -> tuple[float, float]:
        """(speed m/s, direction it blows from deg true) at ``alt_m`` (m)."""
        n, e = self.ned_at(alt_m)
        spd = math.hypot(n, e)
        return spd, (math.degrees(math.atan2(-e, -n)) % 360.0 if spd > 0.0 else 0.0)

    def strongest_between(self, lo_m: float, hi_m: float) -> tuple[float, float]:
        """(speed m/s, from deg true) of the strongest wind between altitudes ``lo_m`` and
        ``hi_m`` (m): the wind speed is convex between layers (the components are linear), so
        it is the strongest at the band's ends or at a layer inside it."""
        lo, hi = min(lo_m, hi_m), max(lo_m, hi_m)
        alts = [lo, hi] + [a for a in self.alt_m if lo < a < hi]
        return max((self.at(a) for a in alts), key=lambda w: w[0])

