"""A spinning cube of three materials simulated by speclight (orbit, attitude, render,
atmosphere, instrument) over seven passes: the period, the pole and each face's material
recovered by ``speclight shape``'s run from the NetCDF and its scenario."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from astropy import units as u
from astropy.coordinates import BarycentricMeanEcliptic, SkyCoord

from speclight.attitude.quaternion import quat_rotate
from speclight.estimate.shape import ShapeOptions, read_shape_input, run_shape
from speclight.estimate.shape.convex_model import ecliptic_to_body
from speclight.estimate.shape.ecliptic import (
    angular_distance_deg,
    gcrs_to_ecliptic,
    julian_date,
    pole_vector,
)
from speclight.io.netcdf import write_dataset
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.simulation.geometry_stage import attitude_quaternions

PERIOD_S = 40.0
MATERIALS = {"+x": "white_paint", "-x": "white_paint", "+y": "kapton_mli",
             "-y": "kapton_mli", "+z": "solar_cell", "-z": "solar_cell"}  # fmt: skip
#: A cube's six flat faces on 192 fixed facet normals (15 deg apart) leave a model error of
#: a few percent (a face between normals is spread over them), so the pole is asked within
#: 10 deg here, not the 5 deg of the smooth bodies of test_shape_convex.py.
POLE_TOLERANCE_DEG = 10.0


def test_spinning_cube_from_a_speclight_dataset(tmp_path):
    d = yaml.safe_load(example_text("cube-materials"))
    d["time"] = {"start": "2019-08-30T00:00:00Z", "stop": "2019-08-31T12:00:00Z", "step_s": 10.0}
    d["attitude"] = {"model": "spin", "spin_axis_ra_deg": 30.0, "spin_axis_dec_deg": 45.0,
                     "period_s": PERIOD_S, "spin_body_axis": [0.3, 0.2, 1.0]}  # fmt: skip
    d["target"]["materials"] = {
        k: {"bsdf": "lambertian", "reflectance": {"table": v}} for k, v in MATERIALS.items()
    }
    d["render"] = {"mode": "single", "resolution_px": 96}
    d["observer"]["max_sun_elevation_deg"] = 90.0  # the passes in daylight too (seven in all)
    d["instrument"]["noise"] = None
    loaded = parse_scenario(yaml.safe_dump(d), source="spinning-cube")
    path = tmp_path / "cube.nc"
    write_dataset(simulate(loaded).dataset, path)
    inputs = read_shape_input(path, "speclight")
    assert inputs.data.n_curves >= 5  # passes split at the gaps
    p_h = PERIOD_S / 3600.0
    run = run_shape(inputs, ShapeOptions(p_h * (1 - 3e-4), p_h * (1 + 3e-4), law="lambert",
                                         pole_step_deg=45.0, n_start_poles=4))  # fmt: skip
    # the period within a tenth of its resolution P^2 / T
    resolution_s = PERIOD_S**2 / (inputs.data.baseline_d * 86400.0)
    assert abs(run.best.period_h * 3600.0 - PERIOD_S) < 0.1 * resolution_s
    # the pole: the scenario's spin axis (GCRS RA, Dec) in ecliptic J2000 by astropy
    axis = SkyCoord(ra=30.0 * u.deg, dec=45.0 * u.deg, frame="icrs").transform_to(
        BarycentricMeanEcliptic(equinox="J2000"))  # fmt: skip
    truth = pole_vector(axis.lon.deg, axis.lat.deg)
    found = pole_vector(run.best.lambda_deg, run.best.beta_deg)
    assert angular_distance_deg(found, truth) < POLE_TOLERANCE_DEG
    # every face's material (per-facet unmixing): the face normal carried into the fit's
    # body frame at t0; the facets within 30 deg of it (the EGI spreads a flat face over
    # the nearest normals, and the +z face, near the spin axis, is seen only obliquely)
    assert run.materials is not None
    names, area = run.materials
    start = np.datetime64("2019-08-30T00:00:00", "ns")
    t0_s = (run.model.t0_jd - julian_date(np.array([start]))[0]) * 86400.0
    q0 = attitude_quaternions(loaded.scenario.attitude, np.array([t0_s]))[0]
    to_fit = ecliptic_to_body(np.deg2rad(run.best.lambda_deg), np.deg2rad(run.best.beta_deg),
                              run.best.period_h, np.array([0.0]))[0]  # fmt: skip
    for face, material in MATERIALS.items():
        n_body = np.zeros(3)
        n_body["xyz".index(face[1])] = 1.0 if face[0] == "+" else -1.0
        n_fit = to_fit @ gcrs_to_ecliptic(quat_rotate(q0, n_body))
        near = run.model.normals @ n_fit > np.cos(np.deg2rad(30.0))
        share = area[near].sum(axis=0) / area[near].sum()
        column = next(i for i, n in enumerate(names) if face in n.split(","))
        # the face's own material holds the majority of the facets around its normal
        assert share[column] > 0.5, (face, material, dict(zip(names, share, strict=True)))


def test_materials_with_proportional_signatures_are_not_unmixed():
    # Two grey Lambertian materials (albedo 0.2 and 0.6): their band signatures are
    # proportional in any bands (rank 1), so per-facet shares are undetermined: the shape run
    # keeps its facet spectra and says why instead of failing at the end (exit 2).
    from speclight.estimate.inputs.band_responses import scenario_band_responses
    from speclight.estimate.shape.facet_spectra import facet_materials

    d = yaml.safe_load(example_text("cube-materials"))
    d["target"]["materials"] = {
        k: {"bsdf": "lambertian", "reflectance": 0.2 if j % 2 else 0.6}
        for j, k in enumerate(d["target"]["materials"])
    }
    loaded = parse_scenario(yaml.safe_dump(d), source="grey-cube")
    bands = scenario_band_responses(loaded)
    facet_band_area = np.full((12, len(bands.band_names)), 0.5)
    with pytest.warns(UserWarning, match="linearly dependent"):
        assert facet_materials(facet_band_area, loaded, bands) is None
