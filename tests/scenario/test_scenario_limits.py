"""Limits known before a run is started: every one is refused at load time with an
:class:`InputError` naming the field, the value and what is accepted (issue 9, item 5).

Each scenario is built from a built-in example with one field changed; the reproducer of the
bad-input audit it stands for is named in the test (``/work/shared/repro/fuzz/NNNN-*``).
"""

from __future__ import annotations

import copy
from typing import Any

import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario


def _example(name: str = "calsphere") -> dict[str, Any]:
    return yaml.safe_load(example_text(name))


def _set(d: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    d = copy.deepcopy(d)
    node = d
    keys = path.split(".")
    for key in keys[:-1]:
        node = node[int(key)] if isinstance(node, list) else node.setdefault(key, {})
    if isinstance(node, list):
        node[int(keys[-1])] = value
    else:
        node[keys[-1]] = value
    return d


def _refused(d: dict[str, Any]) -> str:
    with pytest.raises(InputError) as err:
        parse_scenario(yaml.safe_dump(d), source="test.yaml")
    return str(err.value)


# --- non-finite numbers ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("path", "value"),
    [
        ("time.step_s", float("inf")),  # fuzz/0022-step-s-inf
        ("observer.latitude_deg", float("nan")),
        ("observer.altitude_m", float("-inf")),
        ("attitude.quaternion.0", float("inf")),
        ("target.shape.radius_m", float("inf")),
        ("target.materials.body.reflectance", float("nan")),
        ("spectrum.step_nm", float("nan")),
        ("instrument.exposure_s", float("inf")),
        ("instrument.noise.dark_current_e_per_s", float("inf")),
        ("instrument.bands.0.gaussian.center_nm", float("inf")),
    ],
)
def test_non_finite_numbers_are_refused(path: str, value: float) -> None:
    msg = _refused(_set(_example(), path, value))
    assert f"{path} = {value!r}: Input should be a finite number" in msg


def test_non_finite_list_entries_are_refused() -> None:
    d = _set(_example("box-wing"), "target.shape.bus_size_m", [1.0, float("inf"), 1.5])
    assert "target.shape.bus_size_m.1 = inf: Input should be a finite number" in _refused(d)


def test_nan_quaternion_fails_the_unit_norm_check() -> None:
    # issue 9 item 8: abs(nan - 1) > 1e-6 is False, so [nan, 0, 0, 0] passed the check
    from speclight.scenario.sections_geometry import AxesOrientation

    unchecked = AxesOrientation.model_construct(quaternion=[float("nan"), 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"norm nan; it must be 1"):
        unchecked._one_form()  # the norm check on its own, behind the finite-number check
    d = _set(_example(), "attitude", {"model": "fixed", "quaternion": [float("nan"), 0, 0, 0]})
    assert "attitude.quaternion.0 = nan: Input should be a finite number" in _refused(d)


# --- seeds -------------------------------------------------------------------------------


def test_render_seed_above_mitsubas_32_bits_is_refused_at_load() -> None:
    # fuzz/0290-seed-2-64: render.seed 2**64 was accepted and failed only when the NetCDF
    # attribute was written, after the whole run
    for seed in (2**64, 2**32):
        msg = _refused(_set(_example(), "render.seed", seed))
        assert f"render.seed = {seed}: Input should be less than or equal to 4294967295" in msg


def test_noise_seed_above_64_bits_is_refused_at_load() -> None:
    msg = _refused(_set(_example(), "instrument.noise.seed", 2**64))
    assert "instrument.noise.seed = 18446744073709551616: Input should be less than" in msg


def test_largest_seeds_are_written_to_netcdf() -> None:
    # what the limits promise: the largest accepted seeds reach the file (the writer is the
    # one that failed on 2**64) and numpy's generator takes the noise seed
    import numpy as np
    import xarray as xr

    from speclight.io.netcdf import dataset_bytes
    from speclight.scenario.sections_light import MAX_NOISE_SEED, MAX_RENDER_SEED
    from speclight.simulation.dataset import global_attributes

    d = _set(_example(), "render.seed", MAX_RENDER_SEED)
    loaded = parse_scenario(yaml.safe_dump(_set(d, "instrument.noise.seed", MAX_NOISE_SEED)))
    ds = xr.Dataset(attrs=global_attributes(loaded))
    back = xr.open_dataset(bytes(dataset_bytes(ds)), engine="h5netcdf")
    assert int(back.attrs["seed"]) == MAX_RENDER_SEED
    np.random.default_rng(loaded.scenario.instrument.noise.seed)  # type: ignore[union-attr]


# --- time window inside the shipped ephemeris ----------------------------------------------


def test_ephemeris_span_constant_is_the_shipped_de421_file() -> None:
    # reference: the segment table of skyfield-data's de421.bsp (every body, the same span)
    from speclight.orbit.timescale import load_ephemeris
    from speclight.scenario.sections_geometry import EPHEMERIS_SPAN_TDB_JD

    segments = [s.spk_segment for s in load_ephemeris().segments]
    assert min(s.start_jd for s in segments) == EPHEMERIS_SPAN_TDB_JD[0]
    assert max(s.end_jd for s in segments) == EPHEMERIS_SPAN_TDB_JD[1]


@pytest.mark.parametrize(
    ("start", "stop"),
    [
        ("1850-01-01 00:00:00+00:00", "1850-01-01 00:00:09+00:00"),  # fuzz/0029
        ("2060-01-01 00:00:00+00:00", "2060-01-01 00:00:09+00:00"),  # fuzz/0030
        ("9999-12-31 23:59:00+00:00", "9999-12-31 23:59:09+00:00"),  # fuzz/0032
        ("0001-01-01 00:00:00+00:00", "0001-01-01 00:00:09+00:00"),  # fuzz/0033
        ("2053-10-07 00:00:00+00:00", "2053-10-09 00:00:00+00:00"),  # ends past the span
        ("1899-07-29 00:00:00+00:00", "1899-07-29 12:00:00+00:00"),  # starts in the margin
    ],
)
def test_time_window_outside_the_ephemeris_is_refused_at_load(start: str, stop: str) -> None:
    d = _set(_set(_example(), "time.start", start), "time.stop", stop)
    d["time"]["step_s"] = 3600.0
    msg = _refused(d)
    assert "time: " in msg and "DE421" in msg
    assert "1899-07-30" in msg and "2053-10-08" in msg  # the accepted span, named


def test_time_window_at_the_edges_of_the_span_is_accepted() -> None:
    d = _set(_example(), "time.start", "1899-07-30 00:00:00+00:00")
    d = _set(d, "time.stop", "2053-10-08 00:00:00+00:00")
    d["time"]["step_s"] = 86400.0 * 365
    parse_scenario(yaml.safe_dump(d))


# --- built-in shape sizes --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("example", "path", "value", "radius"),
    [
        ("box-wing", "target.shape.wing_gap_m", 1e9, "1e+09"),  # fuzz/0533 (SIGABRT in Dr.Jit)
        ("calsphere", "target.shape.radius_m", 1e7, "1e+07"),  # fuzz/0535
        ("calsphere", "target.shape.radius_m", 1e-4, "0.0001"),
    ],
)
def test_builtin_shape_out_of_scale_is_refused(
    example: str, path: str, value: float, radius: str
) -> None:
    msg = _refused(_set(_example(example), path, value))
    assert f"target.shape: builtin '{_builtin(example)}' has a bounding radius" in msg
    assert f"bounding radius {radius} m" in msg and "accepted: 0.001 to 100000 m" in msg


def _builtin(example: str) -> str:
    return str(_example(example)["target"]["shape"]["builtin"])


def test_tiny_cube_is_refused() -> None:
    # fuzz/0536-cube-edge-1e-12 (SIGABRT in Dr.Jit): bounding radius edge * sqrt(3) / 2
    d = _set(_example(), "target.shape", {"builtin": "cube", "edge_m": 1e-12})
    d["target"]["materials"] = {"*": {"bsdf": "lambertian", "reflectance": 0.5}}
    assert "builtin 'cube' has a bounding radius 8.66e-13 m" in _refused(d)


def test_shape_scale_limits_are_the_mesh_readers() -> None:
    from speclight.target.mesh_io import MAX_BOUNDING_RADIUS_M, MIN_BOUNDING_RADIUS_M

    ok_small = _set(_example(), "target.shape.radius_m", MIN_BOUNDING_RADIUS_M)
    ok_large = _set(_example(), "target.shape.radius_m", MAX_BOUNDING_RADIUS_M)
    for d in (ok_small, ok_large):
        parse_scenario(yaml.safe_dump(d))
    _refused(_set(_example(), "target.shape.radius_m", MAX_BOUNDING_RADIUS_M * 1.01))


# --- noise parameters --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("path", "value", "bound"),
    [
        ("instrument.noise.dark_current_e_per_s", 1e300, "6241509074460.763"),  # fuzz/0246
        ("instrument.noise.read_noise_e", 1e7, "1000000"),
        ("instrument.noise.aperture_radius_arcsec", 1e6, "648000"),
        ("instrument.exposure_s", 1e5, "86400"),
    ],
)
def test_noise_parameters_above_their_physical_ceiling_are_refused(
    path: str, value: float, bound: str
) -> None:
    msg = _refused(_set(_example(), path, value))
    assert f"{path} = {value!r}: Input should be less than or equal to {bound}" in msg


@pytest.mark.parametrize("key", ["sigma_nm", "center_nm"])
def test_a_gaussian_band_wider_than_any_grid_is_refused(key):
    # repro fuzz/0395, 0474: sigma_nm 1e308 overflowed to NaN count rates with exit 0
    d = yaml.safe_load(example_text("calsphere"))
    d["instrument"]["bands"][0]["gaussian"][key] = 1.0e308
    with pytest.raises(InputError, match=key):
        parse_scenario(yaml.safe_dump(d), source="test")
