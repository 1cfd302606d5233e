"""Synthetic observing geometries and true bodies for the shape-inversion tests.

The geometries are asteroid-like apparitions: the observer's direction from the target at
several ecliptic longitudes (and latitudes up to 20 deg), the Sun's direction a phase
angle away, a night of points every ``step_h`` per apparition; the body turns about its
pole with the sidereal period of DAMIT's convention (written here from the definition, not
imported from the code under test).
"""

from __future__ import annotations

import numpy as np


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def radec(lon_deg, lat_deg):
    lo, la = np.deg2rad(lon_deg), np.deg2rad(lat_deg)
    return np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1)


def apparitions(
    rng,
    n_apparitions=6,
    nights=2,
    hours=6.0,
    step_h=0.2,
    years=4.0,
    max_phase_deg=25.0,
    max_lat_deg=20.0,
):
    """Epochs [JD], target->Sun and target->observer unit vectors (ecliptic), curve index."""
    t, s, o, c = [], [], [], []
    k = 0
    t_app = 2455000.5 + np.sort(rng.uniform(0, 365.25 * years, n_apparitions))
    lons = rng.uniform(0, 360, n_apparitions)
    for t0, lon in zip(t_app, lons, strict=True):
        lat = rng.uniform(-max_lat_deg, max_lat_deg)
        for night in range(nights):
            tt = t0 + 3.0 * night + np.arange(0, hours, step_h) / 24.0
            obs = radec(lon + 0.3 * night, lat)
            phase = np.deg2rad(rng.uniform(3.0, max_phase_deg))
            axis = unit(np.cross(obs, rng.normal(size=3)))
            sun = obs * np.cos(phase) + np.cross(axis, obs) * np.sin(phase)
            t.append(tt)
            s.append(np.tile(sun, (tt.size, 1)))
            o.append(np.tile(obs, (tt.size, 1)))
            c.append(np.full(tt.size, k))
            k += 1
    return np.concatenate(t), np.concatenate(s), np.concatenate(o), np.concatenate(c)


def to_body(v, lambda_deg, beta_deg, period_h, t_jd, t0_jd):
    """Ecliptic vectors into the body frame: R_z(-phi) R_y(-(90 - beta)) R_z(-lambda) v."""
    lam, bet = np.deg2rad(lambda_deg), np.deg2rad(beta_deg)
    phi = 2 * np.pi * (t_jd - t0_jd) * 24.0 / period_h

    def rz(a):
        c, s = np.cos(a), np.sin(a)
        z, o = np.zeros_like(c), np.ones_like(c)
        return np.moveaxis(np.array([[c, -s, z], [s, c, z], [z, z, o]]), (0, 1), (-2, -1))

    th = -(np.pi / 2 - bet)
    ry = np.array([[np.cos(th), 0, np.sin(th)], [0, 1, 0], [-np.sin(th), 0, np.cos(th)]])
    w = v @ rz(np.array(-lam)).T @ ry.T
    return np.einsum("nij,nj->ni", rz(-phi), w)


def lambert_mesh_brightness(vertices, faces, sun_b, obs_b):
    """Sum over faces of area mu0 mu / pi (a convex Lambertian mesh, albedo 1) [m2 sr-1]."""
    tri = vertices[faces]
    cr = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(cr, axis=1)
    n = cr / (2 * area[:, None])
    mu0 = np.clip(sun_b @ n.T, 0, None)
    mu = np.clip(obs_b @ n.T, 0, None)
    return (mu0 * mu) @ area / np.pi
