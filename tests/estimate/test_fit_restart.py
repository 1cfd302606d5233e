"""A roughness fit of two materials that misfits starts again from the scan's common line.

A coordinate scan moves one roughness at a time; a basin that only a joint move leaves keeps
it (the box-wing example's `plastic` wings from 10x off: 0.54 and 0.99 for 0.05 and 0.08,
chi2 per dof 42; tests/estimate/test_fit_box_wing_plastic.py, long). The plain-array model
here has that landscape by construction: in log roughness, chi2 above the noise is the
squared distance to the truth (0.05, 0.08), or to a trap at (0.5, 0.9) plus 1, whichever is
smaller. From the trap, a move of either roughness alone stays farther from the truth than
the trap's excess (a distance of at least ln(0.9 / 0.08)^2 = 5.9 or ln(0.5 / 0.05)^2 = 5.3
against 1), while the common line passes within ln(0.08 / 0.046)^2 + ln(0.05 / 0.046)^2 =
0.30 of the truth. The reference is that construction (the truth, and its Fisher sigma in
closed form), not the fit's output.
"""

from __future__ import annotations

import numpy as np

from speclight.estimate import fit_roughness
from speclight.estimate.fitting.roughness_problem import RoughnessProblem
from speclight.estimate.fitting.roughness_scan import coordinate_scan

TRUTH = np.array([0.05, 0.08])
TRAP = np.array([0.5, 0.9])
N = 200
GAIN = 10.0  # residual per unit of log roughness, in noise sigmas per entry
t = np.arange(N)
BASE = np.full(N, 1000.0)  # orthogonal to the three patterns below (zero means)
PATTERNS = [np.cos(2 * np.pi * k * t / N) for k in (5, 7, 11)]  # orthogonal, each |p|^2 = N/2


def _model(alpha: np.ndarray) -> np.ndarray:
    x = np.log(alpha)
    d_truth, d_trap = x - np.log(TRUTH), x - np.log(TRAP)
    if np.sum(d_truth**2) <= np.sum(d_trap**2) + 1.0:
        u, v, w = d_truth[0], d_truth[1], 0.0
    else:
        u, v, w = d_trap[0], d_trap[1], 1.0
    bumps = u * PATTERNS[0] + v * PATTERNS[1] + w * PATTERNS[2]
    return (BASE + GAIN * bumps)[:, None]


def test_a_fit_that_misfits_starts_again_from_the_common_line():
    rng = np.random.default_rng(0)
    measured = _model(TRUTH) + rng.normal(0.0, 1.0, (N, 1))
    sigma = np.ones((N, 1))
    start = np.array([0.5, 0.8])  # 10x off, in the trap's basin
    # the trap is real: the coordinate scan from the start stays in it
    problem = RoughnessProblem(_model, measured, sigma, (0.01, 1.0))
    assert np.all(np.abs(np.log(coordinate_scan(problem, start).best / TRAP)) < 0.8)
    fit = fit_roughness(_model, measured, sigma, start, (0.01, 1.0))
    # Fisher sigma of ln(alpha_k) in closed form: 1 / (GAIN |pattern|) = 1 / (GAIN sqrt(N / 2))
    sigma_log = 1.0 / (GAIN * np.sqrt(N / 2))
    np.testing.assert_allclose(fit.roughness_std / fit.roughness, sigma_log, rtol=0.05)
    assert np.all(np.abs(fit.roughness - TRUTH) < 3 * fit.roughness_std), fit.roughness
    # chi2 about the number of data at the truth's basin (the trap's is N + 100 N / 2 more)
    assert problem.chi2(fit.roughness) < N + 5 * np.sqrt(2 * N)
