"""The fit's standard deviations are the marginal ones (issue 25, the cube with a material per
face): correlated with the other roughness values and the band scale, not conditional on them.

Reference: the Frisch-Waugh-Lovell theorem (Frisch & Waugh 1933, Econometrica 1, 387;
Lovell 1963, JASA 58, 993): in weighted linear least squares the marginal variance of one
coefficient is ``1 / sum w r^2``, with ``r`` the residual of its column after a weighted
least-squares regression on all the other columns; the conditional variance (the others
known) is ``1 / sum w x^2``. Computed here with ``numpy.linalg.lstsq``, not by inverting the
information matrix as the code does.
"""

from __future__ import annotations

import numpy as np

from speclight.estimate.fitting.fit import joint_std
from speclight.estimate.fitting.noise_model import Likelihood


def _case() -> tuple[np.ndarray, list[np.ndarray], Likelihood]:
    """A one-band model c [s-1] over 200 epochs, the derivatives of two glinting faces that
    overlap in time and with the brightness, and Gaussian sigmas; measured = model (chi2 0,
    so the max(1, chi2/dof) factor is 1)."""
    t = np.linspace(0.0, 60.0, 200)
    glint = np.exp(-0.5 * ((t - 30.0) / 4.0) ** 2)
    c = (1000.0 + 5000.0 * glint)[:, None]
    u = (t - 30.0) / 4.0
    d1 = (3000.0 * glint * (u**2 - 1.0) + 6000.0 * glint * u)[:, None]
    d2 = (2000.0 * glint * u + 1500.0 * glint)[:, None]
    sigma = np.sqrt(c)
    return c, [d1, d2], Likelihood(c, sigma)


def _fwl_std(columns: list[np.ndarray], k: int, w: np.ndarray) -> float:
    """Marginal std of coefficient k by the Frisch-Waugh-Lovell theorem (module doc)."""
    sw = np.sqrt(w)
    x = columns[k] * sw
    others = np.stack([col * sw for i, col in enumerate(columns) if i != k], axis=1)
    coef, *_ = np.linalg.lstsq(others, x, rcond=None)
    r = x - others @ coef
    return float(1.0 / np.sqrt(r @ r))


def test_joint_std_is_marginal_over_the_other_faces_and_the_scale() -> None:
    c, cols, likelihood = _case()
    w = 1.0 / c.ravel()  # Gaussian sigma^2 = c
    columns = [c.ravel(), cols[0].ravel(), cols[1].ravel()]  # scale, face 1, face 2
    std, std_scale = joint_std(cols, c, likelihood, np.ones(1), True)
    for k, got in ((1, std[0]), (2, std[1]), (0, std_scale[0])):
        expected = _fwl_std(columns, k, w)
        conditional = 1.0 / np.sqrt(np.sum(w * columns[k] ** 2))
        assert conditional < 0.9 * expected  # the correlations matter in this case
        np.testing.assert_allclose(got, expected, rtol=1e-9)


def test_an_unseen_face_gets_inf_and_leaves_the_others_sigma() -> None:
    """The +z and -z faces of the spinning cube never glint: a zero column. Their std is inf
    and the others' is what it is without them (BENCHMARKS.md, "per-face cube")."""
    c, cols, likelihood = _case()
    w = 1.0 / c.ravel()
    columns = [c.ravel(), cols[0].ravel(), cols[1].ravel()]
    std, std_scale = joint_std([*cols, np.zeros_like(c)], c, likelihood, np.ones(1), True)
    assert np.isinf(std[2])
    for k, got in ((1, std[0]), (2, std[1]), (0, std_scale[0])):
        np.testing.assert_allclose(got, _fwl_std(columns, k, w), rtol=1e-9)
