"""Convex inversion of bodies of known shape, pole and period rendered by speclight.

The light curves come from another route than the model under test: speclight's ray-cast
render of a white Lambertian mesh (conftest.render_mesh) at asteroid-like apparitions
(synthetic.apparitions), written as a DAMIT .lc file by the writer below (built from the
format description: Durech et al. 2010, A&A 513, A46), read back by the
reader under test. Checks (issue 27): the period to its resolution, the pole within 5 deg (or
the mirror, flagged), the EGI within 10 % of the true body's.
"""

from __future__ import annotations

import numpy as np
import pytest
from synthetic import apparitions, to_body

from conftest import render_mesh
from speclight.estimate.shape import ShapeOptions, read_shape_input, run_shape
from speclight.estimate.shape.ecliptic import angular_distance_deg, pole_vector
from speclight.estimate.shape.egi import egi_difference, mesh_egi
from speclight.estimate.shape.shape_dataset import verdict

TRUE_LAMBDA, TRUE_BETA, TRUE_PERIOD_H = 40.0, 35.0, 6.3
NOISE = 0.01  # relative photometric noise (0.01 mag)
MAX_PHASE_DEG = 60.0  # phase angles up to 60 deg, as a satellite shows them
POLE_TOLERANCE_DEG = 5.0
#: The EGI is compared after smoothing both by a 60 deg FWHM Gaussian: light curves see
#: the facets through the Lambert kernel mu0 mu, max(0, cos)^2 at small phase angles, whose
#: FWHM is 90 deg, so the data determine the EGI only at that resolution (Kaasalainen,
#: Lamberg & Lumme 1992, A&A 259, 318: only its low-degree part is well determined); 60 deg
#: compares finer than that.
EGI_FWHM_DEG = 60.0
EGI_TOLERANCE = 0.10


def write_lc(path, t, y, sun, obs, curve):
    """DAMIT .lc text from the format description: the number of curves, then per curve
    'N 0' and N lines 'JD I sx sy sz ex ey ez' (vectors from the target, AU)."""
    lines = [str(curve.max() + 1)]
    for k in range(curve.max() + 1):
        m = curve == k
        lines.append(f"{m.sum()} 0")
        for row in zip(t[m], y[m], *(1.3 * sun[m]).T, *(0.4 * obs[m]).T, strict=True):
            lines.append(" ".join(repr(float(x)) for x in row))
    path.write_text("\n".join(lines) + "\n")


def rendered_lc(tmp_path, vertices, faces, seed):
    rng = np.random.default_rng(seed)
    t, sun, obs, curve = apparitions(rng, n_apparitions=10, step_h=0.3, max_phase_deg=MAX_PHASE_DEG)
    t0 = np.floor(t[0])
    sb = to_body(sun, TRUE_LAMBDA, TRUE_BETA, TRUE_PERIOD_H, t, t0)
    ob = to_body(obs, TRUE_LAMBDA, TRUE_BETA, TRUE_PERIOD_H, t, t0)
    y = render_mesh(vertices, faces, sb, ob) * (1.0 + NOISE * rng.normal(size=t.size))
    path = tmp_path / "body.lc"
    write_lc(path, t, y, sun, obs, curve)
    return path


@pytest.mark.parametrize("body", ["ellipsoid", "cylinder", "box_wing_hull"])
def test_convex_body_recovered(tmp_path, bodies, body):
    vertices, faces = bodies[body]
    inputs = read_shape_input(rendered_lc(tmp_path, vertices, faces, seed=3), "damit")
    run = run_shape(
        inputs,
        ShapeOptions(
            TRUE_PERIOD_H - 0.002,
            TRUE_PERIOD_H + 0.002,
            law="lambert",
            pole_step_deg=60.0,
            n_start_poles=2,
        ),
    )
    baseline_h = inputs.data.baseline_d * 24.0
    resolution_h = TRUE_PERIOD_H**2 / baseline_h  # one turn of phase drift over the baseline
    assert abs(run.best.period_h - TRUE_PERIOD_H) < 0.1 * resolution_h
    truth = pole_vector(TRUE_LAMBDA, TRUE_BETA)
    found = pole_vector(run.best.lambda_deg, run.best.beta_deg)
    mirror = pole_vector(TRUE_LAMBDA + 180.0, TRUE_BETA)
    near_truth = angular_distance_deg(found, truth) < POLE_TOLERANCE_DEG
    assert near_truth or (
        angular_distance_deg(found, mirror) < POLE_TOLERANCE_DEG and run.mirror_reported
    )
    assert run.shape_constrained and run.pole_constrained
    _check_solutions(run)
    if near_truth:  # the mirror solution's shape is the mirror image
        normals = run.model.normals
        true_egi = mesh_egi(vertices, faces, normals)
        assert egi_difference(run.best.areas, true_egi, normals, EGI_FWHM_DEG) < EGI_TOLERANCE


def _check_solutions(run):
    """What the run reports is consistent: the best has the lowest chi-square of all its
    solutions, no two solutions share a minimum (30 deg), and the mirror solution is at
    the best's mirror pole when it is a minimum (the mirror start could before end back in
    the best's own minimum and be reported as its mirror)."""
    sols = [run.best, run.mirror, *run.others]
    assert all(run.best.chi2 <= s.chi2 for s in sols)
    distinct = [run.best, *([run.mirror] if run.mirror_is_minimum else []), *run.others]
    poles = [pole_vector(s.lambda_deg, s.beta_deg) for s in distinct]
    for i in range(len(poles)):
        for j in range(i):
            assert angular_distance_deg(poles[i], poles[j]) >= 30.0
    if run.mirror_reported:  # the verdict names the mirror pole
        m = run.mirror
        assert f"the mirror pole ({m.lambda_deg:.0f}, {m.beta_deg:.0f}) fits" in verdict(run)
    target = pole_vector(run.best.lambda_deg + 180.0, run.best.beta_deg)
    assert (
        angular_distance_deg(pole_vector(run.mirror.lambda_deg, run.mirror.beta_deg), target) < 30.0
    )
