"""Seed 001's fault identification over arrays (realisations × units × channels): the rules
(:mod:`.rules`: table 1, pair tests, the estimate, the three-way stage-2 table, voting), the
sensor-level pair test (:mod:`.sensor`), the two-stage state machine (:mod:`.two_stage`) and its
tuning (:mod:`.tuning`). The per-flight source (through :mod:`fms_testbed.navigation.fdi`) and
the Monte-Carlo engine (:mod:`fms_testbed.navigation.montecarlo`) both run these.
"""

from pathlib import Path as _Path

from fms_testbed.core._numba_cache import invalidate_if_sources_changed as _invalidate

# before any kernel is loaded from the cache: the two-stage step inlines the rules' kernels
_invalidate(_Path(__file__).parent)

from fms_testbed.navigation.identification.rules import MAJORITY, PAIRS  # noqa: E402
from fms_testbed.navigation.identification.sensor import SensorPairTest  # noqa: E402
from fms_testbed.navigation.identification.tuning import FdiTuning  # noqa: E402
from fms_testbed.navigation.identification.two_stage import TwoStage  # noqa: E402

__all__ = ["FdiTuning", "MAJORITY", "PAIRS", "SensorPairTest", "TwoStage"]
