"""Shared fixtures of the shape-inversion tests: bodies rendered by speclight."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from speclight.render import render_intensity
from speclight.target import shapes
from speclight.target.materials import Material
from speclight.target.parts import Part, Target
from speclight.target.reflectance import Reflectance

WHITE = Material(name="body", bsdf="lambertian", reflectance=Reflectance.constant(1.0, field="r"))


def render_mesh(vertices, faces, sun_body, obs_body, resolution_px=128):
    """speclight's single-scattering render of a white Lambertian mesh, per unit solar
    irradiance: the intensity [W sr-1 nm-1] per [W m-2 nm-1] is the reflectance factor
    [m2 sr-1] (a ray-cast image, independent of the convex model under test)."""
    target = Target(parts=(Part("body", np.asarray(vertices, float), np.asarray(faces), WHITE),))
    n = len(sun_body)
    res = render_intensity(
        target, sun_body, obs_body, np.ones((n, 1)), np.array([550.0]), resolution_px=resolution_px
    )
    return res.intensity_W_sr_nm[:, 0]


def ellipsoid_mesh():
    m = trimesh.creation.icosphere(subdivisions=3)
    m.vertices *= [2.0, 1.3, 1.0]
    return np.asarray(m.vertices), np.asarray(m.faces)


def cylinder_mesh():
    # its axis across the spin axis (a cylinder spinning about its own axis shows no light
    # curve: tests/estimate/shape/test_shape_null.py)
    m = trimesh.creation.cylinder(radius=0.8, height=2.6, sections=48)
    m.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    return np.asarray(m.vertices), np.asarray(m.faces)


def box_wing_hull_mesh():
    tgt = shapes.box_wing(WHITE, dish=False)
    hull = trimesh.Trimesh(np.vstack([p.vertices_m for p in tgt.parts])).convex_hull
    return np.asarray(hull.vertices), np.asarray(hull.faces)


BODIES = {
    "ellipsoid": ellipsoid_mesh,
    "cylinder": cylinder_mesh,
    "box_wing_hull": box_wing_hull_mesh,
}


@pytest.fixture(scope="session")
def bodies():
    return {k: f() for k, f in BODIES.items()}
