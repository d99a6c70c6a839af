"""Truth-side IMU: increments from the flown trajectory, and the sensors' errors.

Modules: :mod:`.kinematics` (the discrete strapdown step that defines an increment, and its exact
inverse), :mod:`.synthesis` (error-free increments at the IMU position from JSBSim's per-frame
samples), :mod:`.errors` (each unit's sensor errors: turn-on bias, bias instability, bias random
walk, scale factor, misalignment, ARW/VRW, quantisation).
"""

from pathlib import Path as _Path

import fms_testbed.core.earth as _earth
from fms_testbed.core._numba_cache import invalidate_if_sources_changed as _invalidate

# before any kernel is loaded from the cache: the kernels here inline core/earth.py's
_invalidate(_Path(__file__).parent, also_hash=(_Path(_earth.__file__),))
