"""The scenario's ``navigation:`` block: which navigation source guidance flies on, with that
source's own keys — a discriminated union on ``source``, so a key another source would take is
an error, not silently ignored.

A new source adds its block here (a model with ``source: Literal["name"]``, added to
:data:`NavigationBlock`) and its class in :mod:`fms_testbed.navigation` (the registry).

Seed precedence: ``navigation.seed``, when given, seeds the navigation errors; otherwise the run's
seed (``--seed``) does. The summary reports both (``seed``, ``navigation_seed``).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field

_FINITE = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)


class TruthBlock(BaseModel):
    """``navigation: {source: truth}`` — the solution is the true state."""

    model_config = _FINITE
    source: Literal["truth"] = "truth"


class SinsBlock(BaseModel):
    """``navigation: {source: sins, imu: PRESET, ...}`` — truth ⊕ the 33-state SINS error model
    (free inertial, baro-damped vertical channel by default)."""

    model_config = _FINITE
    source: Literal["sins"]
    imu: str | dict[str, Any] = Field(
        description="IMU preset name (fms_testbed/data/imu/), a .yaml path, or an inline mapping")
    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="seed of the error realisation (default: the run's seed)")
    method: Literal["picard", "vanloan", "trapezoid"] = Field(
        "picard", description="discretisation of the error model (Babich: Picard series)")
    dt_s: Annotated[float, Field(gt=0, le=10)] = Field(
        0.1, description="nominal navigation step, s")
    vertical: Literal["baro", "free"] = Field(
        "baro", description="vertical channel: baro-damped, or free (unstable)")
    baro_tau_s: Annotated[float, Field(gt=0, le=3600)] = Field(
        60.0, description="baro loop time constant, s")
    tol: Annotated[float, Field(gt=0, lt=1e-3)] = Field(
        1e-12, description="adaptive Picard tolerance (relative)")
    alignment: Literal["stationary", "none"] = Field(
        "stationary", description="initial attitude errors from a stationary self-alignment, "
                                  "or independent")
    matrices_dt_s: Annotated[float, Field(ge=0, le=60)] = Field(
        0.0, description="reuse Φ_k, S_k this long before rebuilding F, s (0: every step)")


NavigationBlock = Annotated[Union[TruthBlock, SinsBlock], Field(discriminator="source")]
"""The navigation block of a scenario, discriminated by ``source``."""


def with_default_source(raw: Any) -> Any:
    """A navigation mapping without ``source`` means truth."""
    if isinstance(raw, dict) and "source" not in raw:
        return {"source": "truth", **raw}
    return raw


__all__ = ["NavigationBlock", "SinsBlock", "TruthBlock", "with_default_source"]
