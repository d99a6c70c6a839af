"""The compiled altitude command (guidance/profile_kernel) gives the Python reference's numbers
(guidance/vertical.altitude_command_m) to the last bit: random descending and climbing profiles
with 'at', 'at or above', 'at or below' windows, coded vertical angles, climb targets, positions
before, on and past every node, with and without the approach's extension."""

from __future__ import annotations

import random

import pytest

from fms_testbed.guidance.profile_kernel import ProfileNodes, altitude_command_fast_m
from fms_testbed.guidance.vertical import altitude_command_m


def _profile(rng: random.Random, n: int):
    s, h = [0.0], [rng.uniform(500.0, 5000.0)]
    for _ in range(n - 1):
        s.append(s[-1] + rng.choice([rng.uniform(500.0, 20000.0), 1e-7]))   # a 0-length piece too
        h.append(max(0.0, h[-1] + rng.choice([-1, 1, 0]) * rng.uniform(0.0, 900.0)))
    climb = [rng.choice([None, None, None, h[k] + rng.uniform(0.0, 500.0)]) for k in range(n)]
    wins = []
    for k in range(n):
        kind = rng.choice(["none", "at", "above", "below"])
        wins.append({"none": (None, None), "at": (h[k], h[k]), "above": (h[k], None),
                     "below": (None, h[k])}[kind])
    coded = [False] + [rng.random() < 0.2 for _ in range(n)]
    return s, h, climb, wins, coded


@pytest.mark.parametrize("seed", range(40))
def test_the_compiled_command_is_the_reference_to_the_last_bit(seed):
    rng = random.Random(seed)
    n = rng.randint(1, 12)
    s, h, climb, wins, coded = _profile(rng, n)
    use_windows = rng.random() < 0.8
    nodes = ProfileNodes.of(s, h, climb, wins if use_windows else [], coded)
    approach = rng.random() < 0.5
    for x in [-500.0, 0.0, *s, s[-1] + 3000.0] + [rng.uniform(-100.0, s[-1] + 500.0)
                                                  for _ in range(60)]:
        gs, lead, t2, top = (rng.uniform(40.0, 260.0), rng.uniform(0.0, 20.0),
                             rng.uniform(0.0, 60.0), rng.uniform(1000.0, 9000.0))
        tas = rng.choice([None, rng.uniform(40.0, 260.0)])
        ref = altitude_command_m(s, h, climb, x, gs, lead, t2, top, approach,
                                 wins if use_windows else [], coded, tas)
        got = altitude_command_fast_m(nodes, x, gs, lead, t2, top, approach, tas)
        assert got == ref or (got != got and ref != ref), (seed, x, got, ref)
