"""The mirror ambiguity of torque-free states: a motion and its mirror image through the
plane that holds the Sun's and the observer's directions give the same light curve.

Reflect a rotation ``R(t)`` (body to ecliptic) through a plane of unit normal ``n``
(``M = 1 - 2 n n^T``) and invert the body: ``R'(t) = -M R(t)`` is again a rotation
(``det(-M) = +1``) with the same body rates (``R'^T dR'/dt = R^T dR/dt``), so it is the
torque-free motion of the same body with the same moments, started from ``R'(0)``; its
angular momentum is ``-M H``. In the body frame it sees a direction ``v`` as
``-R^T M v``, which is ``-R^T v`` for ``v`` in the plane: the Sun and the observer
antipodal. A body whose EGI is centrally symmetric (a box-wing, an ellipsoid: every facet
with an equal one opposite) reflects the same light under the Lambert and Lommel-Seeliger
laws from antipodal directions, so when every Sun and observer direction lies near one
plane, the state and its mirror fit alike: the light curves cannot tell them apart. This is
the tumbling counterpart of the mirror pole ``lambda + 180 deg`` of a principal-axis
rotator seen near the ecliptic (Kaasalainen & Lamberg 2006, Inverse Problems 22, 749).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from speclight.estimate.shape.tumbling_state import TumblingState

F64 = NDArray[np.float64]


def mirror_plane(sun: F64, observer: F64) -> tuple[F64, float]:
    """The plane nearest to every Sun and observer direction (module doc).

    Parameters
    ----------
    sun, observer
        (N, 3) unit vectors from the target [1].

    Returns
    -------
    normal
        (3,) unit normal of the plane [1].
    rms_sine
        The root mean square of the directions' components along ``normal`` [1]: 0 when
        all lie in the plane (the mirror state then fits exactly as well).
    """
    v = np.vstack([sun, observer])
    _, singular, vt = np.linalg.svd(v, full_matrices=False)
    return np.asarray(vt[2]), float(singular[2] / np.sqrt(v.shape[0]))


def mirror_state(state: TumblingState, normal: F64) -> TumblingState:
    """The mirror image of ``state`` through the plane of unit ``normal`` (module doc):
    attitude ``-M R(q0)``, the same body rates and moments (chi-square not evaluated:
    NaN)."""
    reflect = np.eye(3) - 2.0 * np.outer(normal, normal)
    r_body = Rotation.from_quat(state.q0, scalar_first=True).as_matrix()
    q = Rotation.from_matrix(-reflect @ r_body).as_quat(scalar_first=True)
    return TumblingState(
        np.asarray(q), state.omega0_body_rad_s, state.moments, float("nan"), state.scale
    )
