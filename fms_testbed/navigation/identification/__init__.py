"""Seed 001's fault identification over arrays (realisations × units × channels): the rules
(:mod:`.rules`: table 1, pair tests, the estimate, the three-way stage-2 table, voting), the
sensor-level pair test (:mod:`.sensor`), the two-stage state machine (:mod:`.two_stage`) and its
tuning (:mod:`.tuning`). The per-flight source (through :mod:`fms_testbed.navigation.fdi`) and
the Monte-Carlo engine (:mod:`fms_testbed.navigation.montecarlo`) both run these.
"""

from fms_testbed.navigation.identification.rules import MAJORITY, PAIRS
from fms_testbed.navigation.identification.sensor import SensorPairTest
from fms_testbed.navigation.identification.tuning import FdiTuning
from fms_testbed.navigation.identification.two_stage import TwoStage

__all__ = ["FdiTuning", "MAJORITY", "PAIRS", "SensorPairTest", "TwoStage"]
