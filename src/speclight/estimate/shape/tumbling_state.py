"""One torque-free state of the tumbling fit (:mod:`.tumbling`), in a module of its own so
that :mod:`.tumbling_mirror` builds states without importing the fit."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from speclight.attitude.quaternion import quat_rotate

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class TumblingState:
    """One fitted torque-free state (module doc).

    Attributes
    ----------
    q0
        (4,) body-to-ecliptic quaternion at ``t0`` (scalar first).
    omega0_body_rad_s
        (3,) body rates at ``t0`` [rad/s].
    moments
        (3,) principal moments along the body axes, the largest 1 [1].
    chi2
        Sum of squared residuals.
    scale
        Factor on the brightness (calibrated data; 1 for relative).
    std
        (5,) standard deviations of the rate [rad/s], of the two moment ratios [1] and
        of the momentum direction along the local east and north [rad]
        (:mod:`.tumbling_uncertainty`); NaN where not fitted.
    """

    q0: F64
    omega0_body_rad_s: F64
    moments: F64
    chi2: float
    scale: float = 1.0
    std: F64 = field(default_factory=lambda: np.full(5, np.nan))

    @property
    def momentum_direction(self) -> F64:
        """Unit angular momentum in ecliptic J2000."""
        h = quat_rotate(self.q0, self.moments * self.omega0_body_rad_s)
        return np.asarray(h / np.linalg.norm(h))

    @property
    def rate_rad_s(self) -> float:
        """``|H| / I_max`` [rad/s]."""
        return float(np.linalg.norm(self.moments * self.omega0_body_rad_s) / np.max(self.moments))

    @property
    def moment_ratios(self) -> F64:
        """(2,) the smaller moments over the largest, sorted."""
        m = np.sort(self.moments)
        return np.asarray(m[:2] / m[2])
