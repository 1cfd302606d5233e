"""The `speclight compare` figure shows the observations' sigmas and tells the sites apart
(issue 22 item 9: cmp.png had no error bars and one marker for every site)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from speclight.plot.compare_figure import SITE_MARKERS, compare_figure

pytest.importorskip("matplotlib")

# docs/compare.md's worked example: Stuttgart and Zimmerwald, bands V and sdss2010-r
STUTTGART, ZIMMERWALD = (48.7822, 9.1967, 355.0), (46.8772, 7.4652, 951.0)


def _compare_dataset() -> xr.Dataset:
    sites = [STUTTGART, STUTTGART, STUTTGART, STUTTGART, ZIMMERWALD, ZIMMERWALD]
    n = len(sites)
    t0 = np.datetime64("2020-02-29T21:14:00", "ns")
    time = t0 + np.array([0, 120, 150, 180, 120, 180]) * np.timedelta64(1, "s")
    residual = np.array([np.nan, -0.2, 0.1, 0.3, -0.1, 0.05])  # the first: in the shadow
    sigma = np.array([0.05, 0.05, 0.1, np.nan, 0.05, 0.08])  # row 4 gave no sigma
    lat, lon, alt = (np.array(c) for c in zip(*sites, strict=True))
    unit = np.tile([0.0, 0.6, 0.8], (n, 1))
    ds = xr.Dataset(
        {
            "time": ("obs", time),
            "residual": ("obs", residual),
            "magnitude_sigma": ("obs", sigma),
            "band": ("obs", np.array(["V", "V", "sdss2010-r", "V", "V", "V"], dtype=object)),
            "phase_angle": ("obs", np.linspace(100.0, 108.0, n)),
            "site_latitude": ("obs", lat),
            "site_longitude": ("obs", lon),
            "site_altitude": ("obs", alt),
            "sun_direction_body": (("obs", "xyz"), unit),
            "observer_direction_body": (("obs", "xyz"), unit[:, ::-1]),
        },
        attrs={"residual_n": 5, "residual_mean_mag": 0.03, "residual_rms_mag": 0.17},
    )
    return ds


def test_residuals_have_error_bars_of_the_observed_sigma() -> None:
    from matplotlib.container import ErrorbarContainer

    ds = _compare_dataset()
    fig = compare_figure(ds)
    ax_t, ax_p = fig.axes[0], fig.axes[1]
    finite = np.isfinite(ds["residual"].values)
    for ax in (ax_t, ax_p):
        bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
        assert sum(len(c.lines[0].get_xdata()) for c in bars) == finite.sum()
        # the bars' half lengths, in observation order of the drawn points, are the sigmas
        halves = []
        for c in bars:
            (segments,) = c.lines[2]
            halves += [abs(seg[1][1] - seg[0][1]) / 2 for seg in segments.get_segments()]
        sigma = ds["magnitude_sigma"].values[finite]
        expected = np.sort(np.where(np.isfinite(sigma), sigma, 0.0))
        np.testing.assert_allclose(np.sort(halves), expected, rtol=1e-12)


def test_each_site_has_its_marker_and_a_legend_entry() -> None:
    fig = compare_figure(_compare_dataset())
    (legend,) = fig.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert texts[:2] == ["V", "sdss2010-r"]
    assert texts[2:] == [
        "site 1: 48.7822° N, 9.1967° E, 355 m",
        "site 2: 46.8772° N, 7.4652° E, 951 m",
    ]
    markers = {c.lines[0].get_marker() for c in fig.axes[0].containers}
    assert markers == {SITE_MARKERS[0], SITE_MARKERS[1]}
    assert "from 2 sites" in fig._suptitle.get_text()


def test_one_site_needs_no_site_legend() -> None:
    ds = _compare_dataset()
    for name, value in zip(("site_latitude", "site_longitude", "site_altitude"), STUTTGART,
                           strict=True):  # fmt: skip
        ds[name] = ("obs", np.full(ds.sizes["obs"], value))
    fig = compare_figure(ds)
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert texts == ["V", "sdss2010-r"]
    assert "from 1 site:" in fig._suptitle.get_text()
