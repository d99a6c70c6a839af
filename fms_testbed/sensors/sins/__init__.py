"""SINS stochastic error model (33 states) and its discretisation (Babich 2017).

Modules: :mod:`.model` (F, G, Q from the true state), :mod:`.discretize` (Picard / Van Loan /
trapezoid), :mod:`.simulate` (x_k = Φ x + B u + S N with a semidefinite factor), :mod:`.euler`
(eq. 6.10), :mod:`.presets` (IMU files in ``imu/``), :mod:`.trajectory`, :mod:`.analysis`
(covariance / Monte-Carlo), :mod:`.navigation` (``SinsNavigation`` source), :mod:`.cli` (``ins``).

``fms_testbed.sensors.sins.discretize(F, Q, dt, method="picard", order=None, tol=1e-12)`` is the function
(the module of the same name stays importable as ``fms_testbed.sensors.sins.discretize`` in ``from``
imports).
"""

from pathlib import Path as _Path

import fms_testbed.core.earth as _earth
from fms_testbed.core._numba_cache import invalidate_if_sources_changed as _invalidate

# before any kernel is loaded from the cache; model.build_F inlines core/earth.py's kernels
_invalidate(_Path(__file__).parent, also_hash=(_Path(_earth.__file__),))

from fms_testbed.sensors.sins.discretize import DiscretisationError, discretize, discretize_sins  # noqa: E402
from fms_testbed.sensors.sins.euler import eps_to_euler_errors, euler_errors_to_eps  # noqa: E402
from fms_testbed.sensors.sins.model import N_STATES, STATE_NAMES, build_F  # noqa: E402
from fms_testbed.sensors.sins.presets import load_imu  # noqa: E402
from fms_testbed.sensors.sins.simulate import IndefiniteCovarianceError, factor_psd, simulate_lti  # noqa: E402

__all__ = ["discretize", "discretize_sins", "DiscretisationError", "factor_psd",
           "simulate_lti", "IndefiniteCovarianceError", "eps_to_euler_errors",
           "euler_errors_to_eps", "build_F", "N_STATES", "STATE_NAMES", "load_imu"]
