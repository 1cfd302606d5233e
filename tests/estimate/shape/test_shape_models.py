"""The forward pieces of shape inversion against references they did not produce."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from conftest import ellipsoid_mesh, render_mesh
from speclight.estimate.shape.convex_model import ConvexModel, facet_brightness
from speclight.estimate.shape.ecliptic import ecliptic_to_gcrs, gcrs_to_ecliptic
from speclight.estimate.shape.egi import close_egi, closure_vector, facet_normals, mesh_facets
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.minkowski import format_obj, minkowski_polyhedron, polyhedron
from speclight.estimate.shape.scattering import scattering_law
from speclight.target.materials import Material
from speclight.target.reflectance import Reflectance


def _unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_convex_model_matches_speclight_render():
    """A convex Lambertian mesh: the sum over its faces (the convex model on the mesh's own
    EGI) against speclight's ray-cast render, which knows nothing of EGIs. The render's
    error is its pixelisation: about (pixel / silhouette)^1 ~ 1 % at 128 px; 2 % allowed."""
    vertices, faces = ellipsoid_mesh()
    normals, areas = mesh_facets([(vertices, faces)])
    rng = np.random.default_rng(0)
    sun = _unit(rng.normal(size=(40, 3)))
    obs = _unit(sun + rng.normal(size=(40, 3)))
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    model = facet_brightness(sun, obs, normals, areas, scattering_law("lambert"), chp)
    rendered = render_mesh(vertices, faces, sun, obs)
    lit = rendered > 0.05 * rendered.max()
    assert np.max(np.abs(model[lit] / rendered[lit] - 1)) < 0.02


@pytest.mark.parametrize("law", ["lambert", "ls-lambert", "lommel-seeliger"])
def test_jacobian_against_central_differences(law):
    """The analytic Jacobian against central differences (step 1e-6: truncation ~1e-12,
    round-off ~1e-10 relative); facets crossing the terminator within a step make kinks,
    so the comparison is on the largest entries, to 1e-4."""
    rng = np.random.default_rng(1)
    n = 60
    t = 2450000 + np.sort(rng.uniform(0, 30, n))
    s, o = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    d = build_inversion_data(
        t,
        rng.uniform(1, 2, n),
        None,
        s,
        s + 0.4 * o,
        np.repeat([0, 1, 2], 20),
        np.array([False, True, False]),
        "x",
    )
    m = ConvexModel(d, facet_normals(2), scattering_law(law), t[0])
    theta = np.concatenate([[0.7, 0.3, 7.3], 0.3 * rng.normal(size=48)])
    _, jac = m.residuals(theta)
    num = np.empty_like(jac)
    for i in range(theta.size):
        e = np.zeros_like(theta)
        e[i] = 1e-6 * max(1.0, abs(theta[i]))
        num[:, i] = (m.residuals(theta + e)[0] - m.residuals(theta - e)[0]) / (2 * e[i])
    assert np.max(np.abs(jac - num)) < 1e-4 * np.max(np.abs(jac))


def test_material_law_is_the_render_models():
    """speclight's lambertian material of albedo 0.3 through the render's material
    evaluation is 0.3 times the Lambert law (f = rho / pi)."""
    mat = Material(name="w", bsdf="lambertian", reflectance=Reflectance.constant(0.3, field="r"))
    law = scattering_law("material", material=mat)
    mu0, mu = np.array([[0.2, 0.7, 0.0]]), np.array([[0.5, 0.9, 0.4]])
    s, d0, d1 = law(mu0, mu, np.array([[0.9]]))
    assert np.allclose(d1[:, :2], 0.3 * mu0[:, :2] / np.pi, rtol=1e-6)
    assert np.allclose(s, 0.3 * mu0 * mu / np.pi, rtol=1e-12)
    assert np.allclose(d0[:, :2], 0.3 * mu[:, :2] / np.pi, rtol=1e-6)


def test_ecliptic_rotation_against_skyfield():
    """GCRS to ecliptic J2000 against skyfield's ecliptic_J2000_frame (IAU 2006 obliquity
    there too; agreement to round-off)."""
    from skyfield.api import load
    from skyfield.framelib import ecliptic_J2000_frame

    ts = load.timescale(builtin=True)
    rot = ecliptic_J2000_frame.rotation_at(ts.tt_jd(2451545.0))
    v = np.random.default_rng(2).normal(size=(5, 3))
    assert np.allclose(gcrs_to_ecliptic(v), v @ rot.T, atol=1e-12)
    assert np.allclose(ecliptic_to_gcrs(gcrs_to_ecliptic(v)), v, atol=1e-14)


def test_minkowski_rebuilds_a_known_polyhedron():
    """A box's support function h(n) = sum |n_i| a_i gives a polyhedron; its facet areas fed
    to the Minkowski solver give it back (unique up to translation, Minkowski 1897): the
    same facet areas and volume (solver tolerance ~1e-5 relative)."""
    normals = facet_normals(4)
    truth = polyhedron(normals, np.abs(normals) @ np.array([2.0, 1.2, 0.7]))
    rebuilt = minkowski_polyhedron(normals, truth.facet_area)
    scale = np.max(truth.facet_area)
    assert np.max(np.abs(rebuilt.facet_area - truth.facet_area)) < 1e-4 * scale
    mesh = trimesh.Trimesh(rebuilt.vertices, rebuilt.faces)
    assert mesh.is_watertight and mesh.is_winding_consistent
    true_volume = trimesh.Trimesh(truth.vertices, truth.faces).volume
    assert mesh.volume == pytest.approx(true_volume, rel=1e-4)
    obj = trimesh.load(trimesh.util.wrap_as_stream(format_obj(rebuilt)), file_type="obj")
    assert obj.volume == pytest.approx(true_volume, rel=1e-4)


def test_closing_an_egi():
    a = np.exp(np.random.default_rng(3).normal(size=48))
    n = facet_normals(2)
    assert np.linalg.norm(closure_vector(a, n)) > 1e-2
    assert np.linalg.norm(closure_vector(close_egi(a, n), n)) < 1e-10
