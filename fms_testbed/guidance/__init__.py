"""Procedure guidance (issue 6): lateral path following, leg sequencing, conditional-leg
termination in flight and vertical targets, behind the runner's ``Guidance`` hook.

Modules: :mod:`.geometry` (local-plane pieces of Line/Arc segments), :mod:`.lateral` (the bank
law), :mod:`.vertical` (altitude/speed targets), :mod:`.procedure` (the scenario's
``procedure:`` block, sequence selection and (re)building), :mod:`.fms` (``ProcedureGuidance``).
"""

from .lateral import LateralGains, bank_command_rad, feedforward_bank_rad
from .procedure import FlyablePath, ProcedureSpec, build_procedure, parse_procedure

__all__ = ["FlyablePath", "LateralGains", "ProcedureSpec", "bank_command_rad",
           "build_procedure", "feedforward_bank_rad", "parse_procedure"]
