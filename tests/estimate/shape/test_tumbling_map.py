"""The tumbling fit's light model chosen and its reflectivity map built from the scenario
(tumbling_run.py :func:`tumbling_light`, maps/writer/cached_map.py): built when absent, found in the
cache on a rerun, equal to a map made by ``speclight reflectivity-map`` with the same
settings (an independent route: the command line on a scenario file), refused for DAMIT
light curves. Maps at the smallest resolution (12 directions, 4 rolls, 8 px) to stay fast."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.estimate.inputs.band_responses import scenario_band_responses
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.shape_inputs import ShapeInput
from speclight.estimate.shape.tumbling_light import ConvexLight, band_map_light
from speclight.estimate.shape.tumbling_run import tumbling_light
from speclight.maps.map_geometry import sun_observer
from speclight.maps.writer.cached_map import MapResolution, map_phase_angles_deg

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/estimate: map_scenarios
F32_EPS = float(np.finfo(np.float32).eps)
TINY = MapResolution(1, 4, 80.0, 8)  # 12 directions, 4 rolls, phase angles every 80 deg, 8 px
LAW = scattering_law("lambert")


def _inputs(loaded, phase_deg=(40.0, 55.0, 70.0)):
    """Light curves of the scenario's bands at the phase angles ``phase_deg`` (the light
    model does not read the brightness)."""
    a = np.deg2rad(np.asarray(phase_deg))
    n = a.size
    sun = np.tile([1.0, 0.0, 0.0], (n, 1))
    obs = np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
    data = build_inversion_data(
        np.arange(float(n)), np.ones(n), np.ones(n), sun, obs, np.zeros(n, int),
        np.array([False]), "x",
    )  # fmt: skip
    bands = scenario_band_responses(loaded)
    return ShapeInput(data, bands.band_names, None, None, "m2 sr-1", "x", loaded, bands)


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    """The box-wing example at 8 px (the tiny map's renders) and 100 nm bins, as a file."""
    from map_scenarios import write_scenario

    folder = tmp_path_factory.mktemp("tumbling_map")
    return write_scenario(folder, "box-wing.yaml", resolution_px=8, step_nm=100)


@pytest.fixture(scope="module")
def built(scenario, tmp_path_factory):
    """The map built in an empty cache folder, then asked for again: both lights, their
    messages and the store's modification time after each."""
    _, loaded = scenario
    cache = tmp_path_factory.mktemp("cache")
    said: list[str] = []
    first = tumbling_light(
        _inputs(loaded), LAW, map_resolution=TINY, cache_dir=cache, say=said.append
    )
    assert first.map_path is not None
    stamp = (first.map_path / "zarr.json").stat().st_mtime_ns
    again_said: list[str] = []
    again = tumbling_light(
        _inputs(loaded), LAW, map_resolution=TINY, cache_dir=cache, say=again_said.append
    )
    return first, said, again, again_said, stamp, cache


def test_map_built_when_absent(built):
    first, said, *_, cache = built
    assert first.kind == "reflectivity map"
    assert "built from the scenario in this run" in first.note
    assert first.map_path is not None and first.map_path.parent == cache / "tumbling-maps"
    assert any("building the reflectivity map" in line for line in said)
    attrs = first.attrs()
    assert attrs["tumbling_light_model"] == "reflectivity map"
    assert attrs["tumbling_map"] == str(first.map_path)
    assert (attrs["tumbling_map_nside"], attrs["tumbling_map_rolls"]) == (1, 4)
    assert attrs["tumbling_map_resolution_px"] == 8
    # the data's 40-70 deg between multiples of the 80 deg step
    assert list(attrs["tumbling_map_phase_angle_deg"]) == [0.0, 80.0]


def test_map_reused_when_cached(built):
    first, _, again, again_said, stamp, _ = built
    assert again.map_path == first.map_path
    assert "from the cache" in again.note
    assert not any("building" in line for line in again_said)
    assert (again.map_path / "zarr.json").stat().st_mtime_ns == stamp  # not written again


def test_built_map_equals_the_reflectivity_map_command(built, scenario, tmp_path):
    """The light model of the built map equals that of a map made by ``speclight
    reflectivity-map`` on the scenario file (8 px there too) with the same directions,
    phase angles and rolls, at geometries between the nodes: the same renders (float32
    storage, a weighted sum of 16 values)."""
    first, *_ = built
    path, loaded = scenario
    store = tmp_path / "cli.zarr"
    result = CliRunner().invoke(
        app,
        ["reflectivity-map", str(path), "-o", str(store), "--directions", "12",
         "--phase-angles-deg", "0,80", "--rolls", "4"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    bands = scenario_band_responses(loaded)
    cli = band_map_light(store, bands.band_names, bands.response, bands.wavelength_nm)
    rng = np.random.default_rng(4)
    p = rng.normal(size=(50, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    sun, obs = sun_observer(p, np.deg2rad(rng.uniform(40, 70, 50)), rng.uniform(0, 6.28, 50))
    want = cli(sun, obs, np.zeros(50))
    got = first.model(sun, obs, np.zeros(50))
    assert np.all(want > 0)
    assert np.allclose(got, want, rtol=16 * F32_EPS, atol=0.0)


def test_damit_light_curves_get_the_convex_model_and_refuse_a_map(scenario):
    """DAMIT light curves have no band rates: the convex model of the scenario's mesh, said
    in the note; a map asked for is refused, naming the parameter; without a scenario the
    tumbling fit has no target at all."""
    _, loaded = scenario
    damit = replace(_inputs(loaded), bands=None, band_names=[])
    light = tumbling_light(damit, LAW)
    assert light.kind == "convex model" and "DAMIT" in light.note
    assert isinstance(light.model, ConvexLight) and light.map_path is None
    assert light.attrs() == {
        "tumbling_light_model": "convex model",
        "tumbling_light_note": light.note,
    }
    with pytest.raises(InputError, match="DAMIT") as err:
        tumbling_light(damit, LAW, map_resolution=TINY)
    assert err.value.field == "map_resolution"
    with pytest.raises(InputError) as err:
        tumbling_light(replace(damit, loaded=None), LAW)
    assert err.value.field == "n_starts"


def test_no_map_and_contradictions(scenario, tmp_path):
    _, loaded = scenario
    inputs = _inputs(loaded)
    light = tumbling_light(inputs, LAW, no_map=True)
    assert light.kind == "convex model" and light.map_path is None
    for kwargs, field in (
        ({"map_path": tmp_path, "no_map": True}, "map_path"),
        ({"map_path": tmp_path, "map_resolution": TINY}, "map_path"),
        ({"no_map": True, "map_resolution": TINY}, "map_resolution"),
    ):
        with pytest.raises(InputError) as err:
            tumbling_light(inputs, LAW, **kwargs)
        assert err.value.field == field
    with pytest.raises(InputError, match="1, 2, 4, 8, 16") as err:
        MapResolution.of_nside(3)
    assert err.value.field == "nside"
    assert MapResolution.of_nside() == MapResolution(16, 32, 10.0, 64)  # docs/shape.md
    for args, field in (((3, 4, 10.0, 8), "nside"), ((2, 4, 0.0, 8), "phase_step_deg")):
        with pytest.raises(InputError) as err:
            MapResolution(*args)
        assert err.value.field == field


def test_map_phase_angles_cover_the_data():
    assert map_phase_angles_deg(np.array([31.0, 106.0]), 10.0) == [30.0 + 10 * k for k in range(9)]
    assert map_phase_angles_deg(np.array([40.0, 70.0]), 80.0) == [0.0, 80.0]
    assert map_phase_angles_deg(np.array([150.0, 175.0]), 20.0) == [140.0, 160.0, 179.0]


def test_scenario_rendering_from_its_map_uses_that_map(built, scenario):
    """A scenario with ``render.mode: map`` has its map: that one is the light model (no
    build), and a resolution for a map to build is refused."""
    from speclight.scenario.overrides import with_overrides

    first, *_ = built
    _, loaded = scenario
    mapped = with_overrides(loaded, {"render.mode": "map", "render.map_file": str(first.map_path)})
    light = tumbling_light(_inputs(mapped), LAW, cache_dir=Path("/nonexistent"))
    assert light.map_path == first.map_path and "render.map_file" in light.note
    with pytest.raises(InputError) as err:
        tumbling_light(_inputs(mapped), LAW, map_resolution=TINY)
    assert err.value.field == "map_resolution"
