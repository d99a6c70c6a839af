"""Slope changes of the planned profile at constrained fixes: the blended profile passes each
fix at its planned altitude (guidance/vertical.knees_clear_of_windows), where the plain blend
is |Δγ| w / 4 off it — high at a descent that flattens at an 'at' / 'at or below' fix, low
at one that steepens at an 'at' / 'at or above' fix (60-100 ft misses at STAR fixes)."""

import pytest

from fms_testbed.core.units import FT_M as FT
from fms_testbed.guidance.vertical import (BLEND_S, altitude_command_m, blended_profile,
                                           knees_clear_of_windows)

W_M = 130.0 * BLEND_S          # blend half-width at 130 m/s ground speed
S = [0.0, 20000.0, 40000.0]


@pytest.mark.parametrize("h_end_ft, win, off_sign", [
    (11000, (11000 * FT, 11000 * FT), +1),   # descent that levels at an 'at' fix
    (11000, (None, 11000 * FT), +1),         # ... at an 'at or below' fix planned at its top
    (10000, (11000 * FT, 11000 * FT), +1),   # descent that flattens at an 'at' fix
    (8000, (11000 * FT, 11000 * FT), -1),    # descent that steepens at an 'at' fix
    (4000, (11000 * FT, None), -1),          # descent that steepens at an 'at or above' fix
])
def test_the_blended_profile_passes_a_constrained_fix_at_its_planned_altitude(h_end_ft, win,
                                                                              off_sign):
    h_in = 13000 * FT if h_end_ft >= 10000 else 12000 * FT
    H = [h_in, 11000 * FT, h_end_ft * FT]
    ct = [None, None, None]
    wins = [(None, None), win, (None, None)]
    plain = blended_profile(S, H, S[1], W_M, False)[0]
    dg = (H[2] - H[1]) / 20000.0 - (H[1] - H[0]) / 20000.0
    assert plain - H[1] == pytest.approx(dg * W_M / 4.0, rel=1e-9)     # the plain blend is off
    assert off_sign * (plain - H[1]) > 5 * FT
    bs, bh = knees_clear_of_windows(S, H, ct, wins, W_M)
    assert blended_profile(bs, bh, S[1], W_M, False)[0] == pytest.approx(H[1], abs=1e-6)
    # the corner moved by w along one of its pieces, the other nodes stay
    assert abs(bs[1] - S[1]) == pytest.approx(W_M) and (bs[0], bs[2]) == (S[0], S[2])


def test_a_corner_the_window_allows_is_left_where_it_is():
    H = [13000 * FT, 11000 * FT, 11000 * FT]
    ct = [None, None, None]
    # an 'at or above' fix where the descent levels: the blend lies above it, inside the window
    bs, bh = knees_clear_of_windows(S, H, ct, [(None, None), (11000 * FT, None), (None, None)],
                                    W_M)
    assert bs == S and bh == H
    # climbs are flown to their targets, not along the blend
    bs, bh = knees_clear_of_windows(S, [3000.0, 4000.0, 4000.0], [None, 4000.0, 4000.0],
                                    [(None, None), (None, 4000.0), (None, None)], W_M)
    assert bs == S


def test_altitude_command_reaches_the_at_fix_altitude_at_the_fix():
    H = [13000 * FT, 11000 * FT, 11000 * FT]
    ct = [None, None, None]
    wins = [(None, None), (11000 * FT, 11000 * FT), (None, None)]
    gs = 130.0
    cmd = altitude_command_m(S, H, ct, S[1] - 1e-3, gs, 0.0, 0.0, 20000.0, False, wins)
    assert cmd == pytest.approx(11000 * FT, abs=0.5)
    cmd_plain = altitude_command_m(S, H, ct, S[1] - 1e-3, gs, 0.0, 0.0, 20000.0, False, None)
    assert cmd_plain > 11000 * FT + 10 * FT

