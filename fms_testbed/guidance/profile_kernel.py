"""The altitude command compiled: :func:`.vertical.altitude_command_m` (the blended profile with
its corners moved clear of the windows, :func:`.vertical.knees_clear_of_windows` and
:func:`.vertical.blended_profile`, the lead and curvature terms, the climb targets) as one numba
kernel over the profile's node arrays, the same operations in the same order — the same numbers
to the last bit (``tests/guidance/test_profile_kernel.py`` holds it to the Python functions).

:class:`ProfileNodes` packs a profile's nodes once per active path (None becomes NaN);
:func:`altitude_command_fast_m` is what guidance calls every outer step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from fms_testbed.core._numba_cache import invalidate_if_sources_changed
from fms_testbed.guidance.vertical import BLEND_S

invalidate_if_sources_changed(Path(__file__).parent)


@dataclass(frozen=True)
class ProfileNodes:
    """A vertical profile's nodes as one array (NaN for None), rows: distances (m, on the active
    path), altitudes (m), climb target per node (m), coded window per node (lo, hi; m), 1 where
    the piece ending at the node is on a coded vertical angle, 1 where the piece after it is;
    ``windows``: the nodes carry windows (else the plain blend is flown)."""

    rows: np.ndarray
    windows: bool

    @classmethod
    def of(cls, prof_s, prof_h, climb_tgt, windows, coded_angle) -> "ProfileNodes":
        """Pack the lists guidance keeps (:class:`~.active_path.ActivePath`)."""
        nan = math.nan
        n = len(prof_s)
        win = list(windows) if windows else [(None, None)] * n
        coded = list(coded_angle) if coded_angle is not None else [False] * n
        coded += [False] * (n + 1 - len(coded))
        return cls(np.array([list(prof_s), list(prof_h),
                             [nan if c is None else c for c in climb_tgt],
                             [nan if w[0] is None else w[0] for w in win],
                             [nan if w[1] is None else w[1] for w in win],
                             [1.0 if c else 0.0 for c in coded[:n]],
                             [1.0 if c else 0.0 for c in coded[1:n + 1]]], dtype=float),
                   bool(windows))


@njit(cache=True)
def _bisect_right(a, x):
    lo, hi = 0, a.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if x < a[mid]:
            hi = mid
        else:
            lo = mid + 1
    return lo


@njit(cache=True)
def _slope(ps, ph, k, extend):
    n = ps.shape[0]
    if k <= 0:
        return 0.0
    if k >= n:
        if not extend:
            return 0.0
        k = n - 1
        if k <= 0:
            return 0.0
    d = ps[k] - ps[k - 1]
    return (ph[k] - ph[k - 1]) / d if d > 1e-6 else 0.0


@njit(cache=True)
def _knees(ps, ph, climb, lo_m, hi_m, coded, coded_next, w_m):
    n = ps.shape[0]
    out_s, out_h = ps.copy(), ph.copy()
    for j in range(1, n - 1):
        if j >= lo_m.shape[0] or not math.isnan(climb[j]):
            continue
        lo, top = lo_m[j], hi_m[j]
        d_in, d_out = ps[j] - ps[j - 1], ps[j + 1] - ps[j]
        if d_in <= 1e-6 or d_out <= 1e-6:
            continue
        g_in = (ph[j] - ph[j - 1]) / d_in
        g_out = (ph[j + 1] - ph[j]) / d_out
        if not (g_in < -1e-4 or g_out < -1e-4):
            continue
        if g_out > g_in + 1e-4 and not math.isnan(top) and ph[j] >= top - 1.0 \
                and coded[j] == 0.0:
            d = min(w_m, 0.5 * (out_s[j] - out_s[j - 1]))
            out_s[j], out_h[j] = ps[j] - d, ph[j] - g_out * d
        elif g_out < g_in - 1e-4 and not math.isnan(lo) and ph[j] <= lo + 1.0 \
                and coded_next[j] == 0.0:
            d = min(w_m, 0.5 * d_out)
            out_s[j], out_h[j] = ps[j] + d, ph[j] + g_in * d
    return out_s, out_h


@njit(cache=True)
def _blend(ps, ph, s_m, w_m, extend):
    n = ps.shape[0]
    if n == 1:
        return ph[0], 0.0, 0.0
    j = _bisect_right(ps, s_m)
    m = _slope(ps, ph, j, extend)
    if j <= 0:
        h = ph[0]
    elif j >= n:
        h = ph[n - 1] + m * (s_m - ps[n - 1])
    else:
        h = ph[j - 1] + m * (s_m - ps[j - 1])
    dh, ddh = m, 0.0
    if w_m <= 0:
        return h, dh, ddh
    for k in range(max(j - 2, 0), min(j + 2, n)):
        sk = ps[k]
        if abs(s_m - sk) >= w_m:
            continue
        delta = _slope(ps, ph, k + 1, extend) - _slope(ps, ph, k, extend)
        if delta == 0.0:
            continue
        u = s_m - sk + w_m
        after = 1.0 if s_m > sk else 0.0
        h += delta * u * u / (4.0 * w_m) - delta * (s_m - sk) * after
        dh += delta * u / (2.0 * w_m) - delta * after
        ddh += delta / (2.0 * w_m)
    return h, dh, ddh


@njit(cache=True)
def _command(rows, windows, s_path_m, gs_mps, lead_s, t2_s2, top_m, approach, v_lead):
    ps, ph, climb, lo_m, hi_m = rows[0], rows[1], rows[2], rows[3], rows[4]
    w_m = gs_mps * BLEND_S
    if windows:
        bs, bh = _knees(ps, ph, climb, lo_m, hi_m, rows[5], rows[6], w_m)
    else:
        bs, bh = ps, ph
    h, dh, ddh = _blend(bs, bh, s_path_m, w_m, approach)
    jn = _bisect_right(ps, s_path_m)
    if windows and 0 < jn < lo_m.shape[0] and math.isnan(climb[jn]):
        lo = lo_m[jn]
        if not math.isnan(lo) and h < lo:
            h, dh, ddh = lo, 0.0, 0.0
    alt_cmd = h + lead_s * v_lead * dh + t2_s2 * gs_mps * gs_mps * ddh
    if 0 < jn < ps.shape[0] and not math.isnan(climb[jn]):
        alt_cmd = min(climb[jn], top_m)
    return alt_cmd


def altitude_command_fast_m(p: ProfileNodes, s_path_m: float, gs_mps: float, lead_s: float,
                            t2_s2: float, top_m: float, approach: bool,
                            lead_speed_mps: float | None = None) -> float:
    """:func:`.vertical.altitude_command_m` on the packed nodes ``p``, m.

    Parameters
    ----------
    s_path_m : distance along the active path, m; gs_mps : ground speed, m/s
    lead_s : read-ahead time 2 ξ_H T_H, s; t2_s2 : T_H², s²; top_m : the climb top, m
    approach : the last slope continues to the runway
    lead_speed_mps : the speed of the lead term, m/s (None: ``gs_mps``)
    """
    v_lead = gs_mps if lead_speed_mps is None else lead_speed_mps
    return _command(p.rows, p.windows, s_path_m, gs_mps, lead_s, t2_s2, top_m, approach,
                    v_lead)


__all__ = ["ProfileNodes", "altitude_command_fast_m"]
