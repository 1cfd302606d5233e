"""Multi-bounce laser returns (path mode) against Mitsuba's path tracer and geometry.

Reference: Mitsuba 3's ``path`` integrator (Jakob et al. 2022, https://mitsuba-renderer.org),
an independent renderer, gives the radiant intensity of the target lit by the laser with and
without interreflections; the range-resolved tracer of ``speclight.render.laser_multibounce`` must
give the same multi-bounce intensity (the sum of its histogram) within the Monte Carlo errors.
A convex body has no interreflection: there the multi-bounce result equals the exact
single-scattering one.
"""

import numpy as np
import pytest

from speclight.render import available_variants, render_intensity
from speclight.render.laser_returns import LaserLight, render_laser_returns
from speclight.target import Material, Part, Reflectance, Target, sphere

WL = np.array([530.0, 531.0, 532.0])
LAMBERT = Material("paint", "lambertian", Reflectance.constant(0.8))


def _dihedral() -> Target:
    """Two 1 m square Lambertian plates meeting at 90 deg along the z axis (a concave edge)."""
    a = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1.0]])
    b = np.array([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    return Target((Part("a", a, f, LAMBERT), Part("b", b, f, LAMBERT)))


def _view() -> np.ndarray:
    o = np.array([[1.0, 1.0, 0.6]])
    return o / np.linalg.norm(o)


def _ranging(target, depth, spp, seed, variant="numpy", res=48):
    obs = _view()
    light = LaserLight(obs, np.array([1]), np.ones((1, 1)))
    return render_laser_returns(
        target,
        obs,
        [light],
        WL,
        resolution_px=res,
        variant=variant,
        max_depth=depth,
        samples_per_pixel=spp,
        seed=seed,
    )


def test_convex_sphere_has_no_interreflection():
    target = sphere(0.7, {"body": LAMBERT})
    single = _ranging(target, 2, 1, 0)
    multi = _ranging(target, 8, 2, 0)
    np.testing.assert_allclose(multi.histogram[0], single.histogram[0], rtol=1e-12, atol=0)


def _spectral_variant() -> str | None:
    avail = available_variants()
    for v in ("llvm_ad_spectral", "cuda_ad_spectral", "scalar_spectral"):
        if v in avail:
            return v
    return None


@pytest.mark.skipif(_spectral_variant() is None, reason="no Mitsuba spectral variant")
def test_dihedral_interreflection_matches_mitsuba_path_tracer(monkeypatch):
    import speclight.render.path_scene as path_mode

    target, obs, res = _dihedral(), _view(), 48
    mitsuba = {}
    for depth in (2, 16):
        monkeypatch.setattr(path_mode, "MAX_DEPTH", depth)
        r = render_intensity(
            target,
            obs,
            obs,
            np.ones((1, 3)),
            WL,
            mode="path",
            resolution_px=res,
            samples_per_pixel=256,
            seed=5,
            variant=_spectral_variant(),
        )
        # the three 1 nm bins are independent estimates of the same grey quantity
        mitsuba[depth] = (r.intensity_W_sr_nm[0].mean(), r.intensity_std_W_sr_nm[0].mean() / 3**0.5)
    ref = mitsuba[16][0] - mitsuba[2][0]
    ref_se = np.hypot(mitsuba[16][1], mitsuba[2][1])
    single = _ranging(target, 2, 1, 0, res=res).intensity_W_sr_nm(0)[0, 0]
    runs = [_ranging(target, 16, 8, seed, res=res) for seed in range(4)]
    multi = np.array([r.intensity_W_sr_nm(0)[0, 0] - single for r in runs])
    se = multi.std(ddof=1) / np.sqrt(len(multi))
    assert ref > 0.1 * single  # interreflection matters here (about 20 %)
    # agreement within 4 combined standard errors (fixed seeds)
    assert abs(multi.mean() - ref) < 4 * np.hypot(se, ref_se), (multi.mean(), ref, se, ref_se)
    # interreflected light arrives later: the multi-bounce part's mean offset is larger than
    # the single-bounce one (triangle inequality: each extra leg adds path)
    r0 = _ranging(target, 2, 1, 0, res=res)
    mean_single = r0.moment_m[0][0, 0] / r0.intensity_W_sr_nm(0)[0, 0]
    extra_moment = np.mean([r.moment_m[0][0, 0] for r in runs]) - r0.moment_m[0][0, 0]
    assert extra_moment / multi.mean() > mean_single
