"""The sign (and size) of path mode's Stokes V against an independent electromagnetic model.

Sunlight is unpolarised and one reflection gives V = 0; two reflections off a metal whose
planes of incidence are turned against each other give V != 0: the first partially
polarises the light at 45 deg to the second's plane of incidence, whose s/p phase
difference turns that linear part elliptical. The reference here does not use Fresnel
coefficients at all (whose r_p sign differs between Born & Wolf and Hecht): each reflection
solves Maxwell's boundary conditions (tangential E and H continuous) for the complex field
vectors in 3-D, with fields ``Re(E exp(i (k.r - w t)))`` and the absorbing index
``n + i k`` (k > 0: the wave decays in the metal with this time factor). Unpolarised
sunlight is the mean over two orthogonal incident fields.

The handedness is read off the reflected field itself. ``E(t) = Re(E) cos(wt) + Im(E) sin(wt)``
turns from ``Re(E)`` toward ``Im(E)``: counter-clockwise for an observer who looks back
along the propagation direction ``o`` (toward the source) when ``(Re E x Im E) . o > 0``,
and ``V = 2 (Re E x Im E) . o`` (|V| = I for circular light). That is V > 0 for the IAU's
right-handed sense (IAU 1974, Transactions of the IAU XVB, 166; Hamaker & Bregman 1996,
A&AS 117, 161: the IEEE sense, IEEE Std 149-1979 sec. 11.1, clockwise for an observer
looking along the propagation, i.e. counter-clockwise seen facing the source; on the sky,
north (Q > 0) turning toward east).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.render import available_variants, render_intensity
from speclight.render.polarization import fresnel_sp
from speclight.render.shading import sun_disk_sin2
from speclight.target import Material, Part, Reflectance, Target, refractive_index
from speclight.wavelength_grid import grid_bin_bounds_nm

C128 = np.complex128


def _unit(v: np.ndarray) -> np.ndarray:
    return np.asarray(v / np.linalg.norm(v))


def reflect(field: np.ndarray, k: np.ndarray, normal: np.ndarray, eta: complex) -> np.ndarray:
    """Complex field (3,) reflected from vacuum off the half-space of index ``eta``.

    ``k``: unit propagation direction of the incident wave, ``normal``: the surface normal on
    the incident side. Local axes: z the normal, x along the tangential part of k. The
    reflected field ``r1 y + r2 (kr x y)`` and the transmitted ``t1 y + t2 (kt x y)`` (both
    transverse, ``kt`` complex with ``kt . kt = eta^2``) are solved from the continuity of
    the tangential E and H (``H ~ k x E``, non-magnetic media).
    """
    ez = _unit(normal)
    ex = _unit(k - (k @ ez) * ez)
    rot = np.stack([ex, np.cross(ez, ex), ez])  # world -> local
    e_in = rot @ field
    a, g = k @ ex, -(k @ ez)
    gt = np.sqrt(C128(eta * eta - a * a))
    gt = gt if gt.imag >= 0 else -gt  # decaying into the metal (z < 0)
    ki, kr, kt = np.array([a, 0, -g], C128), np.array([a, 0, g], C128), np.array([a, 0, -gt])
    y = np.array([0, 1, 0], C128)
    basis = [(kr, y), (kr, np.cross(kr, y)), (kt, -y), (kt, -np.cross(kt, y))]
    rows = [np.concatenate([e[:2], np.cross(kv, e)[:2]]) for kv, e in basis]
    rhs = -np.concatenate([e_in[:2], np.cross(ki, e_in)[:2]])
    r1, r2, _, _ = np.linalg.solve(np.array(rows).T, rhs)
    return np.asarray(rot.T @ (r1 * basis[0][1] + r2 * basis[1][1]))


def stokes(field: np.ndarray, o: np.ndarray, north: np.ndarray, east: np.ndarray) -> np.ndarray:
    """I, Q, U, V of a fully polarised field travelling along ``o`` in the north-east frame."""
    jn, je = field @ north, field @ east
    v = 2.0 * np.cross(field.real, field.imag) @ o  # handedness seen facing the source
    return np.array([abs(jn) ** 2 + abs(je) ** 2, abs(jn) ** 2 - abs(je) ** 2,
                     2.0 * (np.conj(jn) * je).real, v])  # fmt: skip


def _rotate(axis: np.ndarray, angle: float, v: np.ndarray) -> np.ndarray:
    axis = _unit(axis)
    return np.asarray(
        v * np.cos(angle)
        + np.cross(axis, v) * np.sin(angle)
        + axis * (axis @ v) * (1 - np.cos(angle))
    )


# The dihedral: sunlight reflects off plate A toward +x, then off plate B toward the
# observer; 70 deg incidence on both, B's plane of incidence turned by 45 deg about x.
THETA, PHI = np.radians(70.0), np.radians(45.0)
K1 = np.array([1.0, 0.0, 0.0])  # A -> B
SUN = _rotate(np.array([0.0, 1.0, 0.0]), -(np.pi - 2 * THETA), -K1)
N_A = _unit(SUN + K1)
W_B = _rotate(K1, PHI, np.array([0.0, 0.0, 1.0]))  # B's plane of incidence holds K1 and W_B
OBS = np.cos(np.pi - 2 * THETA) * K1 + np.sin(np.pi - 2 * THETA) * W_B
N_B = _unit(OBS - K1)
POLE = np.array([0.0, 0.0, 1.0])
B_CENTRE, B_HALF = np.array([2.5, 0.0, 0.0]), 0.5


def reference_stokes(wavelength_nm: float) -> np.ndarray:
    """I, Q, U, V toward the observer per unit solar irradiance on plate A's beam."""
    eta = complex(refractive_index("Au", np.array([wavelength_nm]))[0])
    # the IAU frame: north = the pole projected on the sky, east = pole x line of sight
    east = _unit(np.cross(POLE, -OBS))
    north = np.cross(-OBS, east)
    k0 = -SUN
    e1 = _unit(np.cross(k0, [0.3, 1.0, 0.1]))
    total = np.zeros(4)
    for e in (e1, np.cross(k0, e1)):  # unpolarised: mean over two orthogonal fields
        e_b = reflect(e.astype(C128), k0, N_A, eta)
        total += stokes(reflect(e_b, K1, N_B, eta), OBS, north, east) / 2
    return total


def _plate(
    name: str, centre: np.ndarray, u: np.ndarray, v: np.ndarray, hu: float, hv: float, m: Material
) -> Part:
    """Rectangle centred on ``centre``, half sizes ``hu``, ``hv`` along ``u``, ``v``."""
    signs = ((-1, -1), (1, -1), (1, 1), (-1, 1))
    corners = [centre + su * hu * u + sv * hv * v for su, sv in signs]
    return Part(name, np.array(corners), np.array([[0, 1, 2], [0, 2, 3]]), m)


def dihedral() -> Target:
    gold = Material("gold", "specular", Reflectance.conductor("Au"))
    vb = _unit(np.cross(N_B, [0.0, 0.0, 1.0]))
    b = _plate("b", B_CENTRE, vb, np.cross(N_B, vb), B_HALF, B_HALF, gold)
    # plate A: B's shadow along -x on A's plane (every ray B sends back lands on A), + 20 %
    ua, va = _unit(np.cross([0.0, 1.0, 0.0], N_A)), np.array([0.0, 1.0, 0.0])
    foot = np.array([p - (p @ N_A) / (K1 @ N_A) * K1 for p in b.vertices_m])
    cu, cv = foot @ ua, foot @ va
    centre = (cu.max() + cu.min()) / 2 * ua + (cv.max() + cv.min()) / 2 * va
    hu, hv = 0.6 * np.ptp(cu), 0.6 * np.ptp(cv)
    return Target((_plate("a", centre, ua, va, hu, hv, gold), b))


def test_reflection_solver_gives_the_fresnel_reflectances() -> None:
    # the boundary-value solution against Born & Wolf's |r_s|^2, |r_p|^2 (fresnel_sp)
    k = np.array([np.sin(1.2), 0.0, -np.cos(1.2)])
    for eta in (complex(refractive_index("Au", np.array([600.0]))[0]), 1.5 + 0j):
        rs, rp = fresnel_sp(np.cos(1.2), eta)
        s_out = reflect(np.array([0, 1, 0], C128), k, np.array([0, 0, 1.0]), eta)
        p_out = reflect(np.cross([0.0, 1.0, 0.0], k).astype(C128), k, np.array([0, 0, 1.0]), eta)
        np.testing.assert_allclose([np.vdot(s_out, s_out).real, np.vdot(p_out, p_out).real],
                                   [rs, rp], rtol=1e-12)  # fmt: skip
    # the geometry: reversing the order of the plates does not reach the Sun
    k_rev = -OBS - 2 * (-OBS @ N_A) * N_A
    assert (k_rev - 2 * (k_rev @ N_B) * N_B) @ SUN < np.cos(np.radians(5.0))


@pytest.mark.skipif(
    "llvm_ad_spectral_polarized" not in available_variants(),
    reason="polarised path mode needs Mitsuba's llvm_ad_spectral_polarized variant",
)
def test_path_mode_stokes_v_has_the_iau_sign() -> None:
    wl = np.array([599.0, 600.0, 601.0])
    r = render_intensity(
        dihedral(), SUN[None], OBS[None], np.ones((1, 3)), wl, mode="path", resolution_px=32,
        samples_per_pixel=64, seed=5, solar_disk=True, polarization=True, pole_body=POLE[None],
        variant="llvm_ad_spectral_polarized",
    )  # fmt: skip
    lo, hi = grid_bin_bounds_nm(wl)
    # the path mode's bins average over wavelength: so does the reference (21 points per bin)
    ref = np.array([np.mean([reference_stokes(w) for w in np.linspace(a, b, 21)], 0)
                    for a, b in zip(lo, hi, strict=True)])  # fmt: skip
    assert np.all(ref[:, 3] / ref[:, 0] > 0.05)  # a clear V (7 % of I)
    path = np.concatenate([r.intensity_W_sr_nm[0][:, None], r.stokes_W_sr_nm[0]], axis=1)
    std = np.concatenate([r.intensity_std_W_sr_nm[0][:, None], r.stokes_std_W_sr_nm[0]], axis=1)
    # every sample that reaches the Sun does so through both plates with the same Stokes
    # vector: the fractions agree beyond the noise (n, k interpolated differently: 2-5e-6
    # over seeds 1-6), and the sign of V with them
    np.testing.assert_allclose(path[:, 1:] / path[:, :1], ref[:, 1:] / ref[:, :1], atol=2e-5)
    # absolute: the Sun's radiance (unit irradiance over its disk) times B's projected area
    radiance = 1.0 / (np.pi * sun_disk_sin2())
    expect = radiance * (2 * B_HALF) ** 2 * (N_B @ OBS) * ref
    z = (path - expect) / np.hypot(std, 1e-3 * np.abs(expect))
    assert np.all(np.abs(z) < 4.0), z
    assert np.all(path[:, 3] > 10 * std[:, 3])  # the sign is far outside the noise
