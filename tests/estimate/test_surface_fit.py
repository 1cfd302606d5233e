"""``speclight fit --free brdf`` (estimate.surface_fit) against the full pipeline.

The observations are ``simulate``'s magnitudes of the ``starlink-v1.5`` example with Phong
surfaces of known coefficients (tests/estimate/surface_fit_data.py): the pipeline renders
them through its channels and radiometry at the truth, a path the fit's model (records
rendered once at a far start, BRDFs evaluated in numpy) does not take.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from surface_fit_data import FAR_START, TRUTH, write_observations, write_scenario

from speclight.errors import InputError
from speclight.estimate.inputs.observations import read_observations
from speclight.estimate.surface_fit import fit_surfaces
from speclight.estimate.surface_fit import surface_fit_run as run
from speclight.estimate.surface_fit.robust_fit import night_halves
from speclight.scenario import load_scenario

#: Agreement of the records' model with the pipeline at the same coefficients [mag]: the
#: records hold the render's own cosines (merged where they agree to 1e-7) and areas; the
#: rest is float64 rounding of sums over some 100 records (1e-13 relative).
MODEL_TOL_MAG = 1e-6
#: A coefficient is recovered when it lies within this many of its reported std of the
#: truth (3 std: a 0.3 % chance per coefficient for a Gaussian estimate).
N_STD = 3.0


@pytest.fixture(scope="module")
def data(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("surface_fit")
    obs_path = tmp / "obs.csv"
    clean = write_observations(obs_path)
    return {
        "obs": read_observations(obs_path),
        "clean": clean,
        "start": load_scenario(write_scenario(tmp / "start.yaml", FAR_START)),
        "tmp": tmp,
    }


def test_model_matches_the_pipeline_at_other_coefficients(data: dict) -> None:
    """Records rendered at the far start, evaluated at the truth, give the pipeline's
    magnitudes at the truth (the design matrix is the render's, not an approximation)."""
    loaded, obs = data["start"], data["obs"]
    surfaces = run.free_surfaces(loaded.scenario.target.materials, None)
    d = run._design(loaded, obs, surfaces, None, False)
    u = np.concatenate([[np.log10(TRUTH[s.name][c.name]) for c in s.free] for s in surfaces])
    assert d.used.all()
    np.testing.assert_allclose(d.model.magnitude(u), data["clean"], atol=MODEL_TOL_MAG, rtol=0)


def test_recovers_the_truth_from_a_far_start(data: dict) -> None:
    result = fit_surfaces(data["start"], data["obs"], n_bootstrap=20)
    s = result.summary
    for name, coeff in (("bus_nadir", "kd"), ("bus_nadir", "ks"), ("bus_nadir", "n"),
                        ("array", "kd")):  # fmt: skip
        p = s["surfaces"][name]["parameters"][coeff]
        assert p["constrained"], (name, coeff, p)
        assert abs(p["value"] - TRUTH[name][coeff]) < N_STD * p["std"], (name, coeff, p)
    # the fitted scatter is the noise: RMS of N(0, 0.05) over ~100 rows, within 3 of its
    # standard error 0.05 / sqrt(2 N)
    n = s["n_used"]
    assert abs(s["fit"]["rms_mag"] - 0.05) < 3 * 0.05 / np.sqrt(2 * n)
    assert s["start"]["rms_mag"] > 1.0  # the start was far
    assert s["cross_validation"]["split"] == "time"  # one night
    assert len(s["cross_validation"]["halves"]) == 2


def test_a_lobe_never_seen_is_reported_not_constrained(data: dict) -> None:
    """The array faces the Sun's azimuth; no observer of these passes sees its mirror
    direction, so its specular lobe (ks, n) changes no magnitude: not constrained, and the
    fit says so instead of quoting a std."""
    s = fit_surfaces(data["start"], data["obs"], n_bootstrap=0).summary
    for coeff in ("ks", "n"):
        p = s["surfaces"]["array"]["parameters"][coeff]
        assert not p["constrained"]
        assert p["std"] is None
        assert f"array.{coeff} not constrained" in s["message"]
    assert not s["converged"]


def test_refuses_a_target_without_analytic_surfaces(data: dict, tmp_path: Path) -> None:
    import yaml

    from speclight.scenario import example_text

    path = tmp_path / "tables.yaml"
    path.write_text(example_text("starlink-v1.5"))
    with pytest.raises(InputError, match="no material of the target has an analytic BRDF"):
        fit_surfaces(load_scenario(path), data["obs"])
    with pytest.raises(InputError, match="brdf or brdf,attitude"):
        fit_surfaces(data["start"], data["obs"], free=("albedo",))
    assert yaml  # imported for the scenario helpers


def test_night_halves_split_by_local_night() -> None:
    """Two nights in Chile (UTC-4.7 h mean solar time): rows before and after local
    midnight of one night stay together."""
    t = np.array(
        ["2024-03-20T23:50", "2024-03-21T00:10", "2024-03-21T23:50", "2024-03-22T00:10"],
        dtype="datetime64[ns]",
    )
    first, second, how = night_halves(t, np.full(4, -70.7))
    assert how == "night"
    assert first.tolist() == [0, 1] and second.tolist() == [2, 3]
