"""Unmixing the cube-materials examples against their per-material ground truth.

The model. Every material of the cube has a BRDF equal to its tabulated reflectance times a
geometric factor (Lambertian; Beckmann with the reflectance as numbers, no Fresnel from n,k
and no plastic coat, whose coat does not scale with a reflectance), and a single-mode render
has no interreflections, so each material's share of the band reflectance factor is exactly
``F_k(t, j) = g_k(t) s_kj(t)``, with the band signature ``s_kj(t)`` the band average of its
reflectance weighted by the detected photons of the source at epoch t (the Sun or the laser
lines, times the atmosphere; :mod:`speclight.estimate.spectra.ground_truth`). Hence:

1. the shares are the per-epoch signatures times one number each, to rounding;
2. unmixing each epoch with its own signatures recovers the true fractions to rounding
   (``nnls-norm``; ``fcls`` once the data are divided by the true total contribution: FCLS
   forces the contributions to sum to one, but here they sum to an area factor in m2 sr-1,
   which is why the paper, and this project, normalise NNLS instead);
3. with one signature matrix for the whole pass (the mean source spectrum), the data are
   ``x = S g + e`` with ``e = (S(t) - S) g``. The NNLS solution fits at least as well as the
   feasible ``g``, so ``|S (g_hat - g)| <= 2 |e|`` and ``|g_hat - g|_2 <= 2 |e| / sigma_min(S)``;
   for the normalised fractions ``|f_hat - f|_1 <= 2 |g_hat - g|_1 / sum(g)``
   ``<= 4 sqrt(K) |e| / (sigma_min(S) sum(g))``. The test asserts this bound per epoch, and
   that the dominant material is found wherever the truth's lead exceeds it.
"""

import numpy as np
import pytest
import yaml

from speclight.estimate import confusion_matrix, unmix
from speclight.estimate.inputs.source_spectrum import mean_source_W_m2_nm
from speclight.estimate.spectra.ground_truth import (
    fractions,
    material_signatures,
    true_contributions,
)
from speclight.illumination.laser import gaussian_line_per_nm
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.simulation.ranging_stage import SUPPORT_THRESHOLD
from speclight.target import Reflectance
from speclight.target.material_tables import MATERIAL_TABLES, material_table_path

NAMES = list(MATERIAL_TABLES)
#: Float64 rounding through the render, the band sums and the small least-squares systems
#: (condition number of the signature matrix ~120).
EXACT = 1e-9


def _run(name: str):
    d = yaml.safe_load(example_text(name))
    d["time"] = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:25:00Z", "step_s": 5.0}
    d["render"]["resolution_px"] = 32
    d["instrument"].pop("noise", None)
    loaded = parse_scenario(yaml.safe_dump(d), source=name)
    return loaded, simulate(loaded).dataset


def _case(name: str):
    loaded, ds = _run(name)
    wl = ds["wavelength"].values
    response = (
        ds["band_response"].values * ds["detector_qe"].values * ds["optics_transmission"].values
    )
    tables = np.stack([Reflectance.table_file(material_table_path(n)).evaluate(wl) for n in NAMES])
    if name.endswith("laser"):
        lines = np.stack(
            [
                gaussian_line_per_nm(wl, la.wavelength_nm, la.linewidth_nm)
                for la in loaded.scenario.illumination.lasers
            ]
        )
        # the pipeline keeps each line on its support (simulation/ranging_stage.py)
        lines = np.where(lines > SUPPORT_THRESHOLD * lines.max(axis=1, keepdims=True), lines, 0)
        # lasers at the observer's site: the uplink has the downlink's transmission T, so
        # each line at the target is beam x shape x T with laser_irradiance its sum over
        # the (uniform, 5 nm) bins; at the aperture, times T again
        t_down = ds["transmission"].values
        at_target = np.zeros_like(t_down)
        for k in range(len(lines)):
            shaped = lines[k] * t_down
            beam = ds["laser_irradiance"].values[:, k] / shaped.sum(axis=1)
            at_target += beam[:, None] * shaped
        source = at_target * t_down
        x = ds["laser_reflectance_factor"].values
        shares = ds["laser_reflectance_factor_material"].values
    else:
        source = ds["solar_irradiance"].values * ds["transmission"].values
        x = ds["reflectance_factor"].values
        shares = ds["reflectance_factor_material"].values
    ok = np.all(np.isfinite(x), axis=1)
    assert ok.sum() >= 40
    per_epoch = np.stack(
        [material_signatures(tables, response, wl, source[t]) for t in range(len(x)) if ok[t]]
    )
    labels = [str(v) for v in ds["material_reflectance"].values]
    mean = material_signatures(tables, response, wl, mean_source_W_m2_nm(source[ok], 1.0))
    return x[ok], shares[ok], labels, per_epoch, mean


@pytest.fixture(scope="module", params=["cube-materials", "cube-materials-laser"])
def case(request):
    return _case(request.param)


def test_material_shares_are_signature_times_contribution(case):
    x, shares, labels, per_epoch, _ = case
    for t in range(len(shares)):
        g = true_contributions(shares[t : t + 1], labels, NAMES, per_epoch[t])[0]
        model = np.zeros_like(shares[t, 0])
        for k, name in enumerate(NAMES):
            share = shares[t, [lab == name for lab in labels]].sum(axis=0)
            np.testing.assert_allclose(g[k] * per_epoch[t, k], share, atol=EXACT * x[t].max())
            model += g[k] * per_epoch[t, k]
    assert np.all(np.isfinite(model))


def test_unmixing_with_each_epochs_signatures_is_exact(case):
    x, shares, labels, per_epoch, _ = case
    for t in range(len(x)):
        g = true_contributions(shares[t : t + 1], labels, NAMES, per_epoch[t])
        truth = fractions(g)
        est = unmix(x[t : t + 1], per_epoch[t], method="nnls-norm").abundance
        np.testing.assert_allclose(est, truth, atol=EXACT)
        est = unmix(x[t : t + 1] / g.sum(), per_epoch[t], method="fcls").abundance
        np.testing.assert_allclose(est, truth, atol=EXACT)


def test_unmixing_with_one_signature_matrix_stays_within_the_derived_bound(case):
    x, shares, labels, per_epoch, mean = case
    sigma_min = np.linalg.svd(mean, compute_uv=False).min()
    k = len(NAMES)
    est = unmix(x, mean, method="nnls-norm").abundance
    truth = np.empty_like(est)
    bound = np.empty(len(x))
    for t in range(len(x)):
        g = true_contributions(shares[t : t + 1], labels, NAMES, per_epoch[t])[0]
        truth[t] = g / g.sum()
        e = np.linalg.norm((per_epoch[t] - mean).T @ g)
        bound[t] = 4.0 * np.sqrt(k) * e / (sigma_min * g.sum())
    error = np.abs(est - truth).sum(axis=1)
    assert np.all(error <= bound + EXACT)
    top2 = np.sort(truth, axis=1)[:, -2:]
    clear = (top2[:, 1] - top2[:, 0]) > bound
    conf = confusion_matrix(truth[clear], est[clear], normalise=False)
    assert conf.sum() == clear.sum() and np.trace(conf) == conf.sum()
    assert clear.sum() >= len(x) // 2  # the bound is informative for most epochs
