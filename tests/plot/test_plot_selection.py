"""The epoch followed through the chain and the band images, checked against the data."""

from __future__ import annotations

import numpy as np
import pytest
from plot_datasets import (
    PEAK_OBSERVABLE,
    PEAK_UNOBSERVABLE,
    WAVELENGTH_NM,
    full_dataset,
    geometry_dataset,
    image_dataset,
)

from speclight.errors import InputError
from speclight.plot.selection import (
    band_radiance,
    brightest_observable_epoch,
    resolve_band,
    resolve_epoch,
)


def test_default_epoch_is_the_brightest_observable_one():
    ds = full_dataset()
    # the brightest epoch overall is flagged below the minimum elevation (bit 2): the figure
    # must not follow it. Reference: the observable epochs' aperture power, integrated here
    # with numpy's trapezoid rule (the code uses a bin sum).
    power = np.trapezoid(ds["spectral_flux"].values, WAVELENGTH_NM, axis=1)
    ok = (ds["flags"].values & (1 | 2 | 4 | 16)) == 0
    expected = int(np.flatnonzero(ok)[np.argmax(power[ok])])
    assert expected == PEAK_OBSERVABLE  # the construction of the synthetic pass
    assert ds["flags"].values[PEAK_UNOBSERVABLE] & 2
    assert brightest_observable_epoch(ds) == expected
    assert resolve_epoch(ds, None) == expected


def test_brightest_epoch_without_spectral_flux_uses_intensity_over_range_squared():
    ds = full_dataset().drop_vars("spectral_flux")
    irradiance = np.trapezoid(ds["intensity"].values, WAVELENGTH_NM, axis=1) / (
        ds["range"].values ** 2
    )
    ok = (ds["flags"].values & (1 | 2 | 4 | 16)) == 0
    assert brightest_observable_epoch(ds) == int(np.flatnonzero(ok)[np.argmax(irradiance[ok])])


def test_no_epoch_when_nothing_is_observable_or_no_spectra():
    ds = full_dataset()
    ds["flags"] = ds["flags"] | 4
    assert brightest_observable_epoch(ds) is None
    assert brightest_observable_epoch(geometry_dataset()) is None


def test_epoch_by_index_or_time():
    ds = full_dataset()
    assert resolve_epoch(ds, 12) == 12
    assert resolve_epoch(ds, "12") == 12
    assert resolve_epoch(ds, -1) == ds.sizes["time"] - 1
    # nearest epoch to a time between two epochs (1 s grid starting 05:06:00)
    assert resolve_epoch(ds, "2021-03-04T05:06:20.4Z") == 20
    with pytest.raises(InputError, match="neither an index nor a UTC time"):
        resolve_epoch(ds, "noon")


def test_band_image_is_the_response_weighted_integral():
    ds = image_dataset(size_px=10)
    radiance = ds["image_radiance"].values[1].astype(float)  # (y, x, wavelength)
    response = ds["band_response"].sel(band="G-450/30").values
    # trapezoid rule on the uniform 10 nm grid: differs from the bin sum only by half the
    # end bins, where the 450 nm band's response is exp(-0.5 * (50/30)^2) = 0.25 at 400 nm
    reference = np.trapezoid(radiance * response, WAVELENGTH_NM, axis=-1)
    end_bins = 0.5 * 10.0 * (radiance[..., 0] * response[0] + radiance[..., -1] * response[-1])
    got = band_radiance(ds, 1, "G-450/30")
    np.testing.assert_allclose(got, reference + end_bins, rtol=1e-6, atol=1e-12)
    whole = band_radiance(ds, 1, None)
    np.testing.assert_allclose(whole, radiance.sum(axis=-1) * 10.0, rtol=1e-6)


def test_default_band_is_the_first():
    ds = image_dataset(size_px=4)
    assert resolve_band(ds, None) == "G-450/30"
    assert resolve_band(ds.drop_vars("band_response"), None) is None
