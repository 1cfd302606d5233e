"""speclight light curves in: the scenario's geometry in ecliptic J2000, light-time
corrected epochs and band reflectance factors (shape_inputs)."""

from __future__ import annotations

import numpy as np
import xarray as xr
import yaml
from astropy import units as u
from astropy.coordinates import BarycentricMeanEcliptic, SkyCoord

from speclight.estimate.shape import read_shape_input
from speclight.estimate.shape.ecliptic import julian_date, pole_vector
from speclight.io.netcdf import write_dataset
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate


def test_speclight_input_geometry(tmp_path):
    data = yaml.safe_load(example_text("box-wing"))
    data["time"] = {"start": "2019-08-30T02:24:00Z", "stop": "2019-08-30T02:25:00Z", "step_s": 5.0}
    data["render"]["resolution_px"] = 32
    data["instrument"]["noise"] = None
    loaded = parse_scenario(yaml.safe_dump(data), source="box-wing-short")
    path = tmp_path / "pass.nc"
    write_dataset(simulate(loaded).dataset, path)
    got = read_shape_input(path, "speclight")
    d = got.data
    with xr.open_dataset(path) as ds:
        ok = np.isfinite(ds["reflectance_factor"].values).all(axis=1)
        assert d.n_points == ok.sum() and d.n_curves == 1
        # the phase angle of the ecliptic vectors is the pipeline's (a rotation keeps angles)
        assert np.allclose(d.phase_angle_deg, ds["phase_angle"].values[ok], atol=1e-6)
        # epochs moved back by the light time range / c
        jd = julian_date(ds["time"].values[ok])
        lt_d = ds["range"].values[ok] / 299_792_458.0 / 86400.0
        assert np.allclose(d.time_jd, jd - lt_d, rtol=0, atol=1e-9)
        # the brightness is the mean band factor
        assert np.allclose(d.brightness, ds["reflectance_factor"].values[ok].mean(axis=1))
        # the spin axis (RA, Dec in GCRS) in ecliptic J2000 by astropy: the Sun's component
        # along it is the body z component of the Sun's direction (spin about body z)
        axis = SkyCoord(ra=30.0 * u.deg, dec=45.0 * u.deg, frame="icrs").transform_to(
            BarycentricMeanEcliptic(equinox="J2000")
        )
        pole = pole_vector(axis.lon.deg, axis.lat.deg)
        body_z = ds["sun_direction_body"].values[ok][:, 2]
        assert np.allclose(d.sun_ecliptic @ pole, body_z, atol=1e-6)
    assert got.band_factor is not None and got.band_factor.shape == (d.n_points, 10)


def test_csv_and_netcdf_give_the_same_points(tmp_path):
    """A CSV of the dataset's count rates with its scenario (the factors then come from a
    simulation at the CSV's epochs) gives the NetCDF's points."""
    data = yaml.safe_load(example_text("box-wing"))
    data["time"] = {"start": "2019-08-30T02:24:00Z", "stop": "2019-08-30T02:25:00Z", "step_s": 5.0}
    data["render"]["resolution_px"] = 32
    data["instrument"]["noise"] = None
    loaded = parse_scenario(yaml.safe_dump(data), source="box-wing-short")
    ds = simulate(loaded).dataset
    write_dataset(ds, tmp_path / "pass.nc")
    bands = [str(b) for b in ds["band"].values]
    rows = ["time," + ",".join(bands)]
    for i in range(ds.sizes["time"]):
        rate = ds["count_rate"].values[i]
        rows.append(f"{str(ds['time'].values[i])[:19]}Z," + ",".join(repr(float(r)) for r in rate))
    (tmp_path / "pass.csv").write_text("\n".join(rows) + "\n")
    a = read_shape_input(tmp_path / "pass.nc", "speclight").data
    b = read_shape_input(tmp_path / "pass.csv", "speclight", loaded=loaded).data
    assert np.array_equal(a.time_jd, b.time_jd)
    # the same simulation twice: equal to the render's float32 rounding
    assert np.allclose(a.brightness, b.brightness, rtol=1e-6)
    assert np.allclose(a.sun_ecliptic, b.sun_ecliptic, atol=1e-12)
