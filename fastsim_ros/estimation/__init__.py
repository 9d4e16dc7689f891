"""Friction estimation: the friction coefficient from measured creep forces.

Pure (numpy and :mod:`fastsim_ros.contact`; SciPy only in the batch fit),
no ROS.  Two estimators share one measurement model, the package's own
solver (default ``mae_calibrated``) under the configured friction law:

- :class:`~fastsim_ros.estimation.ekf.FrictionEkf`: recursive, per rig cycle
  (the node and the replay): an extended Kalman filter on the static
  coefficient ``mu_s`` (a random walk of rate ``q``), the measurement model's
  slope ``dF/dmu_s`` the march's own derivative (the MAE solvers; the
  node's is computed in the march of the forces it publishes), else a
  forward difference (one extra solve per contact).
  Where the force does not depend on ``mu_s`` (the linear range: small
  creepage) the update is skipped: the estimate holds, its variance grows.
  The model's own error against the rail (largest at the knee of the creep
  curve, nil in full slip) is carried as a bound, not as noise: samples the
  model gets wrong weigh little, and sigma covers it.
- :func:`~fastsim_ros.estimation.fit.fit_friction`: batch, over a measured
  creep curve (``fastsim_contact estimate``): Gauss-Newton (SciPy's
  trust-region least squares) over ``mu_s`` and, for the exponential law,
  its limit ratio ``A`` and decay ``B``.

:mod:`~fastsim_ros.estimation.model`: the measurement model (contacts,
creepages, a law's shape) as a function of the law's parameters.
"""

from __future__ import annotations

from fastsim_ros.estimation.ekf import EkfStep, FrictionEkf
from fastsim_ros.estimation.model import ContactSample, CreepModel, model_error, solver_for

__all__ = ["ContactSample", "CreepModel", "EkfStep", "FrictionEkf", "model_error",
           "solver_for"]
