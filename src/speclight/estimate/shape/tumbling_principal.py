"""Is the rotation tumbling at all? The best torque-free state against a principal-axis
rotation, by a nested-model F-test.

A rotation about one principal axis is a torque-free state too (the rates stay on the
axis whatever the moments), so the torque-free fit of a body that is not tumbling ends at
a state as good as that rotation, with moments and a nutation the data do not fix. The
state counts as tumbling only when it fits significantly better than the best uniform
rotation about a principal axis (4 parameters: attitude at ``t0`` and the rate; 5 with a
calibrated scale): :func:`speclight.estimate.period.period_decision.nested_f_test`, with
the residuals' lag-1 correlation (model error) counted as fewer independent points, at
:data:`ALPHA`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from speclight.estimate.period.period_decision import nested_f_test

F64 = NDArray[np.float64]
#: p-value below which the state is reported as tumbling.
ALPHA = 1e-3


def lag1_correlation(r: F64) -> float:
    """Lag-1 correlation of residuals ``r`` (0 when all vanish; at most 0.99)."""
    den = float(np.sum(r**2))
    return min(float(np.sum(r[1:] * r[:-1])) / den, 0.99) if den > 0 else 0.0


def principal_axis_test(
    residuals: Callable[[F64], F64], x_best: F64, n_par: int
) -> tuple[float, float]:
    """Chi-square of the best principal-axis rotation and the F-test's p-value (module
    doc).

    Parameters
    ----------
    residuals
        The torque-free fit's residuals of a state vector (rotation vector, body rates
        [rad/s], second-moment parameters ``u``, log scale).
    x_best
        The best torque-free state's vector.
    n_par
        Its parameters (8, or 9 with a calibrated scale).
    """
    r_best = residuals(x_best)
    chi_best = float(np.sum(r_best**2))
    att = Rotation.from_rotvec(x_best[:3])
    w = x_best[3:6]
    rate = float(np.linalg.norm(w))
    chi_pa = np.inf
    for k in range(3):
        axis = np.eye(3)[k] * np.sign(w[k] or 1.0)
        # the body axis k turned onto the inertial direction of the rates
        align, _ = Rotation.align_vectors([w / rate], [axis])
        x0 = np.concatenate([(att * align).as_rotvec(), [rate], x_best[8:n_par]])

        def pa(y: F64, axis: F64 = axis) -> F64:
            return residuals(np.concatenate([y[:3], y[3] * axis, x_best[6:8], y[4:]]))

        fit = least_squares(pa, x0, method="trf", x_scale="jac", max_nfev=200)
        chi_pa = min(chi_pa, float(2.0 * fit.cost))
    p_pa = 4 + n_par - 8
    _, p = nested_f_test(chi_pa, p_pa, chi_best, n_par, r_best.size, lag1_correlation(r_best))
    return chi_pa, 1.0 if np.isnan(p) else p
