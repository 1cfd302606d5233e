"""Laser returns from the Sun render's shared primary rays and from the lasers' own rays
agree (the pipeline shares them only on the numpy caster, where casting costs most)."""

import numpy as np
import pytest
import yaml

import speclight.simulation.pipeline as pipeline
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate


def _run(share: bool, monkeypatch: pytest.MonkeyPatch):
    d = yaml.safe_load(example_text("box-wing-laser"))
    d["time"]["stop"] = "2019-08-30T02:20:19Z"
    d["render"]["resolution_px"] = 48
    monkeypatch.setattr(pipeline, "_share_rays", lambda session: share)
    return simulate(parse_scenario(yaml.safe_dump(d), source="test")).dataset


def test_shared_and_own_rays_give_the_same_returns(monkeypatch: pytest.MonkeyPatch) -> None:
    shared, own = _run(True, monkeypatch), _run(False, monkeypatch)
    laser = [v for v in shared.data_vars if str(v).startswith(("laser", "range"))]
    assert laser, list(shared.data_vars)
    for name in laser:
        a, b = shared[name].values, own[name].values
        if a.dtype.kind not in "fc":
            assert np.array_equal(a, b), name
            continue
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
        # the same rays and hits; the Sun render sums them in another order (Dr.Jit or
        # numpy): float64 rounding of sums of ~48^2 terms, far below float32's 6e-8
        scale = np.nanmax(np.abs(a)) if np.isfinite(a).any() else 0.0
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-10 * scale, err_msg=name)
