"""Material contribution maps of the cube-materials-laser example against its ground truth.

Each material's share of the laser reflectance factor is ``F_k(t) = g_k(t) s_k(t)`` exactly
(tests/estimate/test_estimate_cube_materials.py: BRDFs linear in the tabulated reflectance,
single scattering), with ``s_k(t)`` the band signature weighted by epoch t's source. A
pixel's mean factor is ``x = sum_k mean_t F_k`` and the map unmixes it with the pixel's mean
signatures ``S`` (rows ``s_k``). With the true contributions ``g_k = mean_t F_k . s_k /
|s_k|^2`` (the projection, as ``unmix`` compares with the truth) the pixel's data are
``x = S^T g + e``, ``e`` the part of the pixel-mean shares off their mean signatures (the
covariance of g and s within the pixel). The argument of the cube test then bounds the
normalised fractions of NNLS: ``|f_hat - f|_1 <= 4 sqrt(K) |e| / (sigma_min(S) sum(g))``
(NNLS fits at least as well as the feasible g, so ``|S^T (g_hat - g)| <= 2 |e|``). The test
asserts that bound for every mapped pixel, and the dominant material wherever the truth's
lead exceeds it. Pixels are assigned here with astropy-healpix directly.
"""

import numpy as np
import yaml
from astropy_healpix import xyz_to_healpix

from speclight.estimate.inputs.reflectance_factors import read_reflectance_factors
from speclight.estimate.reflection_maps.reflection_map_run import reflection_map_measured
from speclight.estimate.spectra.endmember_spectra import endmembers_from_scenario
from speclight.estimate.spectra.ground_truth import fractions
from speclight.io.netcdf import dataset_bytes
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

NSIDE = 2  # 48 pixels: several epochs in most, so that the covariance term is not zero
#: Float64 rounding through the render, band sums and small least-squares systems.
ROUNDING = 1e-9


def test_contribution_maps_recover_the_true_fractions_within_the_bound(tmp_path):
    d = yaml.safe_load(example_text("cube-materials-laser"))
    d["time"] = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:25:00Z", "step_s": 5.0}
    d["render"]["resolution_px"] = 32
    d["instrument"].pop("noise", None)
    loaded = parse_scenario(yaml.safe_dump(d), source="cube-materials-laser")
    ds = simulate(loaded).dataset
    path = tmp_path / "cube.nc"
    path.write_bytes(dataset_bytes(ds))
    m = reflection_map_measured(path, nside=NSIDE, loaded=loaded, endmembers=["scenario"])
    assert m.attrs["light"] == "laser" and m.attrs["method"] == "nnls-norm"
    names = [str(e) for e in m["endmember"].values]
    assert names == ["+x,-x", "+y,-y", "+z", "-z"]

    # the truth, pixel by pixel, assigned with astropy-healpix
    v = ds["observer_direction_body"].values
    share = ds["laser_reflectance_factor_material"].transpose("time", "material", "band").values
    materials = [str(x) for x in ds["material"].values]
    seen = np.isfinite(ds["laser_reflectance_factor"].values).all(axis=1)
    pix = np.full(v.shape[0], -1)
    pix[seen] = xyz_to_healpix(v[seen, 0], v[seen, 1], v[seen, 2], NSIDE, order="ring")
    data = read_reflectance_factors(path, loaded, light="laser")
    sig_t = endmembers_from_scenario(loaded, data.bands, data.source_W_m2_nm).signatures_epoch
    assert sig_t is not None
    est = m["abundance"].transpose("pixel", "endmember").values
    checked = 0
    for p in np.unique(pix[pix >= 0]):
        here = pix == p
        s = sig_t[here].mean(axis=0)  # (K, B)
        f_k = np.stack(
            [share[here][:, [materials.index(n) for n in e.split(",")]].sum(1) for e in names]
        ).mean(axis=1)  # (K, B): pixel mean of each endmember's shares
        g = np.einsum("kb,kb->k", f_k, s) / np.einsum("kb,kb->k", s, s)
        x = f_k.sum(axis=0)
        np.testing.assert_allclose(x, m["reflectance_factor"].values[:, p], rtol=ROUNDING)
        e = np.linalg.norm(x - g @ s)
        sigma_min = np.linalg.svd(s, compute_uv=False).min()
        bound = 4 * np.sqrt(len(names)) * e / (sigma_min * g.sum()) + ROUNDING
        truth = fractions(g[None])[0]
        assert np.abs(est[p] - truth).sum() <= bound, (p, est[p], truth, bound)
        lead = np.sort(truth)[-1] - np.sort(truth)[-2]
        if lead > bound:
            assert np.argmax(est[p]) == np.argmax(truth)
        checked += 1
    assert checked >= 20
    assert np.all(np.isnan(est[m["n_samples"].values == 0]))
