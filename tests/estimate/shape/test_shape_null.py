"""Null cases: light curves that carry no shape must be reported as such (issue 27)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import trimesh
from synthetic import apparitions, to_body

from conftest import render_mesh
from speclight.estimate.shape import ShapeOptions, run_shape
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.shape_dataset import shape_dataset, verdict
from speclight.estimate.shape.shape_inputs import ShapeInput

OPTIONS = ShapeOptions(6.298, 6.302, law="lambert", pole_step_deg=90.0, n_start_poles=2, nside=2)


def _run(y, t, sun, obs, curve, options=OPTIONS):
    d = build_inversion_data(
        t,
        y,
        0.01 * np.mean(y) * np.ones_like(y),
        sun,
        obs,
        curve,
        np.zeros(curve.max() + 1, bool),
        "null",
    )
    return run_shape(ShapeInput(d, [], None, None, "1", "null"), options)


def test_noise_only_constrains_nothing():
    rng = np.random.default_rng(4)
    t, sun, obs, curve = apparitions(rng, n_apparitions=4, step_h=0.3)
    options = replace(OPTIONS, bootstrap_draws=3)
    run = _run(1.0 + 0.01 * rng.normal(size=t.size), t, sun, obs, curve, options)
    assert not run.shape_constrained and not run.pole_constrained
    assert run.polyhedron is None
    assert "do not constrain" in verdict(run)
    # the bootstrap's draws and their facet areas reach the dataset
    ds = shape_dataset(run)
    assert ds.sample_facet_area.shape == (3, ds.sizes["facet"])
    assert ds.sample_period.shape == (3,) and np.isfinite(ds.attrs["bootstrap_area_std"])


def test_cylinder_spinning_about_its_axis_shows_no_shape():
    """A cylinder turning about its own axis has a flat light curve in every night."""
    rng = np.random.default_rng(5)
    t, sun, obs, curve = apparitions(rng, n_apparitions=4, step_h=0.3)
    m = trimesh.creation.cylinder(radius=0.8, height=2.6, sections=48)  # axis along z
    sb, ob = (to_body(v, 40.0, 35.0, 6.3, t, np.floor(t[0])) for v in (sun, obs))
    y = render_mesh(np.asarray(m.vertices), np.asarray(m.faces), sb, ob)
    run = _run(y * (1 + 0.01 * rng.normal(size=t.size)), t, sun, obs, curve)
    assert not run.shape_constrained
