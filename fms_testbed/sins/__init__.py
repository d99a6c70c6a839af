"""SINS stochastic error model (33 states) and its discretisation (Babich 2017).

Modules: :mod:`.model` (F, G, Q from the true state), :mod:`.discretize` (Picard / Van Loan /
trapezoid), :mod:`.simulate` (x_k = Φ x + B u + S N with a semidefinite factor), :mod:`.euler`
(eq. 6.10), :mod:`.presets` (IMU files in ``imu/``), :mod:`.trajectory`, :mod:`.analysis`
(covariance / Monte-Carlo), :mod:`.navigation` (``SinsNavigation`` source), :mod:`.cli` (``ins``).

``fms_testbed.sins.discretize(F, Q, dt, method="picard", order=None, tol=1e-12)`` is the function
(the module of the same name stays importable as ``fms_testbed.sins.discretize`` in ``from``
imports).
"""

from .discretize import DiscretisationError, discretize, discretize_sins
from .euler import eps_to_euler_errors, euler_errors_to_eps
from .model import N_STATES, STATE_NAMES, build_F
from .presets import load_imu
from .simulate import IndefiniteCovarianceError, factor_psd, simulate_lti

__all__ = ["discretize", "discretize_sins", "DiscretisationError", "factor_psd",
           "simulate_lti", "IndefiniteCovarianceError", "eps_to_euler_errors",
           "euler_errors_to_eps", "build_F", "N_STATES", "STATE_NAMES", "load_imu"]
