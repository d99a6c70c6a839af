"""Strapdown inertial navigation on measured increments: the mechanisation (:mod:`.strapdown`),
the initial alignment (:mod:`.alignment`) and N units behind the INS-bank interface
(:mod:`.bank`, :class:`~fms_testbed.navigation.bank.InsBankLike`).
"""

from pathlib import Path as _Path

import fms_testbed.core.earth as _earth
import fms_testbed.sensors.imu as _imu
from fms_testbed.core._numba_cache import invalidate_if_sources_changed as _invalidate

# before any kernel is loaded from the cache: the kernels here inline the IMU package's and the
# Earth model's
_invalidate(_Path(__file__).parent, also_hash=(_Path(_imu.__file__).parent, _Path(_earth.__file__)))
