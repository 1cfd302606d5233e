"""Figures stay readable (issue 14 item 8): many bands, noisy measurements, lasers, compass."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import xarray as xr
from plot_datasets import N_TIME, WAVELENGTH_NM, full_dataset, image_dataset

from speclight.plot.compass import image_plane_directions
from speclight.plot.images import images_figure
from speclight.plot.lightcurve import MAX_LEGEND_BANDS
from speclight.plot.overview import overview_figure

pytest.importorskip("matplotlib")

TEN_BANDS_NM = np.linspace(420.0, 960.0, 10)


def _with_bands(ds: xr.Dataset, centres_nm: np.ndarray) -> xr.Dataset:
    """``ds`` with its band variables replaced by Gaussian bands at ``centres_nm``."""
    ds = ds.drop_vars([v for v in ds.data_vars if "band" in ds[v].dims]).drop_vars("band")
    response = np.exp(-0.5 * ((WAVELENGTH_NM[None, :] - centres_nm[:, None]) / 20.0) ** 2)
    rate = np.nan_to_num(ds["spectral_flux"].values) @ response.T * 1e20 + 1.0
    rng = np.random.default_rng(1)
    ds = ds.assign_coords(band=[f"G-{c:.0f}" for c in centres_nm])
    tb = ("time", "band")
    ds["band_response"] = (("band", "wavelength"), response, {"units": "1"})
    ds["count_rate"] = (tb, rate, {"units": "s-1"})
    ds["count_rate_measured"] = (tb, rng.poisson(rate).astype(float), {"units": "s-1"})
    ds["ab_magnitude"] = (tb, -2.5 * np.log10(rate / 1e10), {"units": "mag"})
    return ds


def _with_lasers(ds: xr.Dataset) -> xr.Dataset:
    n = ds.sizes["band"]
    k = np.arange(N_TIME)[:, None]
    ds["return_rate"] = (("time", "band"), 5.0 + k + np.arange(n), {"units": "s-1"})
    ds["range_offset"] = (("time", "band"), -0.3 + 0.001 * k * np.ones(n), {"units": "m"})
    return ds


def _panel(fig, title: str):  # type: ignore[no-untyped-def]
    found = [ax for ax in fig.axes if ax.get_title(loc="left").startswith(title)]
    assert len(found) == 1, [ax.get_title(loc="left") for ax in fig.axes]
    return found[0]


def _legend_bands(ax, bands: list[str]) -> list[str]:  # type: ignore[no-untyped-def]
    legend = ax.get_legend()
    texts = [t.get_text() for t in legend.get_texts()] if legend is not None else []
    return [t for t in texts if t in bands]


def test_three_bands_are_named_in_the_legend() -> None:
    ds = full_dataset()
    fig = overview_figure(ds)
    ax = _panel(fig, "light curve per band")
    assert _legend_bands(ax, [str(b) for b in ds["band"].values]) == list(ds["band"].values)
    assert not [a for a in ax.child_axes]  # no band colour bar


def test_ten_bands_get_a_wavelength_colour_bar_not_a_legend() -> None:
    ds = _with_bands(full_dataset(), TEN_BANDS_NM)
    fig = overview_figure(ds)
    ax = _panel(fig, "light curve per band")
    bands = [str(b) for b in ds["band"].values]
    assert len(_legend_bands(ax, bands)) <= MAX_LEGEND_BANDS
    bars = [a for a in ax.child_axes if "wavelength" in a.get_ylabel()]
    assert len(bars) == 1
    # every band's line drawn, and the legend still explains measured vs model
    assert len([ln for ln in ax.get_lines() if ln.get_label() in bands]) == 10
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "measured (with noise)" in texts and "model (noiseless)" in texts


def test_measurements_are_drawn_above_the_model_lines() -> None:
    ax = _panel(overview_figure(full_dataset()), "light curve per band")
    points = [ln for ln in ax.get_lines() if ln.get_marker() == "."]
    markers = [ln for ln in points if ln.get_linestyle() == "None"]
    lines = [ln for ln in ax.get_lines() if ln.get_linestyle() != "None"]
    assert markers and lines
    assert min(m.get_zorder() for m in markers) > max(ln.get_zorder() for ln in lines)
    assert all(m.get_alpha() is not None and m.get_alpha() < 1 for m in markers)


def test_overview_has_laser_panels_only_with_lasers() -> None:
    ds = full_dataset()
    without = overview_figure(ds)
    with_lasers = overview_figure(_with_lasers(ds.copy()))
    titles = [ax.get_title(loc="left") for ax in with_lasers.axes]
    assert any(t.startswith("laser return rate") for t in titles)
    assert any(t.startswith("laser range offset") for t in titles)
    assert not any("laser" in ax.get_title(loc="left") for ax in without.axes)
    assert len(with_lasers.axes) == len(without.axes) + 2
    offset = _panel(with_lasers, "laser range offset")
    assert offset.get_ylabel() == "range offset [mm]"
    y = offset.get_lines()[0].get_ydata()
    assert y[0] == pytest.approx(-300.0)  # metres in the file, millimetres on the axis


def _compass_dataset(q_wxyz: tuple[float, float, float, float]) -> xr.Dataset:
    """Hand-worked geometry, written in GCRS and turned into the body frame by ``q``.

    Observer on the equator at GCRS (6.4e6, 0, 0) m; the line of sight from it to the
    target u = (1, 0, 1)/sqrt(2) (45 deg elevation, due north), range 1000 km. Image axes
    (seen from the observer): right (0, 1, 0), up = (-u) x right = (1, 0, -1)/sqrt(2).
    Sun direction (0, 0.6, 0.8). By hand, (right, up) components:
    north (0, 0, 1) -> (0, -1/sqrt(2)); zenith (1, 0, 0) -> (0, 1/sqrt(2));
    Sun -> (0.6, -0.8/sqrt(2)).
    """
    from speclight.attitude.quaternion import quat_to_matrix

    ds = image_dataset()
    a = 1.0 / np.sqrt(2.0)
    u = np.array([a, 0.0, a])
    site = np.array([6.4e6, 0.0, 0.0])
    body_to_gcrs = quat_to_matrix(np.array(q_wxyz))
    to_body = body_to_gcrs.T
    n = ds.sizes["time"]
    ds["attitude_quaternion"] = (("time", "wxyz"), np.tile(q_wxyz, (n, 1)))
    ds["target_position_gcrs"] = (("time", "xyz"), np.tile(site + 1e6 * u, (n, 1)))
    ds["range"] = ("time", np.full(n, 1e6), {"units": "m"})
    ds["observer_direction_body"] = (("time", "xyz"), np.tile(to_body @ -u, (n, 1)))
    ds["sun_direction_body"] = (("time", "xyz"), np.tile(to_body @ [0.0, 0.6, 0.8], (n, 1)))
    m = ds.sizes["image_time"]
    ds["image_right_body"] = (("image_time", "xyz"), np.tile(to_body @ [0.0, 1.0, 0.0], (m, 1)))
    ds["image_up_body"] = (("image_time", "xyz"), np.tile(to_body @ [a, 0.0, -a], (m, 1)))
    return ds


@pytest.mark.parametrize(
    "q_wxyz",
    # body = GCRS; and a body turned 90 deg about z, then tilted (the answer must not change)
    [(1.0, 0.0, 0.0, 0.0), (np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)), (0.5, 0.5, -0.5, 0.5)],
)
def test_compass_arrows_match_the_hand_worked_case(q_wxyz) -> None:
    a = 1.0 / np.sqrt(2.0)
    dirs = image_plane_directions(_compass_dataset(q_wxyz), 0)
    assert set(dirs) == {"N", "Z", "☉"}
    assert np.allclose(dirs["N"], (0.0, -a), atol=1e-12)
    assert np.allclose(dirs["Z"], (0.0, a), atol=1e-12)
    assert np.allclose(dirs["☉"], (0.6, -0.8 * a), atol=1e-12)


def test_images_figure_draws_the_compass() -> None:
    fig = images_figure(_compass_dataset((1.0, 0.0, 0.0, 0.0)), None)
    first = fig.axes[0]
    assert {t.get_text() for t in first.texts} - {""} == {"N", "Z", "☉"}  # "": the arrows
    assert "celestial north" in first.get_xlabel()
    # without attitude or image axes: no compass, the figure still draws
    plain = images_figure(image_dataset(), None)
    assert not [t for t in plain.axes[0].texts if t.get_text()]


def _overlapping_tick_labels(fig, ax) -> list[tuple[str, str]]:  # type: ignore[no-untyped-def]
    """Pairs of neighbouring x tick labels of ``ax`` whose drawn boxes intersect."""
    fig.canvas.draw()  # layout and ticks as they are saved
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.get_xticklabels() if t.get_visible() and t.get_text()]
    boxes = sorted(((t.get_window_extent(renderer), t.get_text()) for t in labels),
                   key=lambda box: box[0].x0)  # fmt: skip
    return [(a, b) for (p, a), (q, b) in itertools.pairwise(boxes) if p.x1 > q.x0]


@pytest.mark.parametrize("span_s", [20.0, 600.0, 6 * 3600.0])
def test_time_tick_labels_do_not_run_together(span_s: float) -> None:
    # issue 22 item 9: the box-wing pass (600 s) read "02:20:0002:21:00..."
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    ds = _with_bands(full_dataset(), TEN_BANDS_NM)  # ten bands: a colour bar, narrow axes
    step = np.timedelta64(int(span_s / (N_TIME - 1) * 1e9), "ns")
    ds = ds.assign_coords(time=ds["time"].values[0] + np.arange(N_TIME) * step)
    fig = overview_figure(ds)
    FigureCanvasAgg(fig)
    bottom = next(ax for ax in fig.axes if ax.get_xlabel().startswith("time [UTC]"))
    assert _overlapping_tick_labels(fig, bottom) == []
    assert len([t for t in bottom.get_xticklabels() if t.get_text()]) >= 3


def _polarised(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with Stokes Q, U images (a quarter and a tenth of the radiance)."""
    ds["image_radiance_q"] = ds["image_radiance"] * 0.25
    ds["image_radiance_u"] = ds["image_radiance"] * 0.1
    return ds


def _inside(box, outer) -> bool:  # type: ignore[no-untyped-def]
    return box.x0 >= outer.x0 and box.x1 <= outer.x1 and box.y0 >= outer.y0 and box.y1 <= outer.y1


def test_images_figure_titles_stay_inside_the_figure_and_apart() -> None:
    # issue 22 item 9: four panels a row (polarised) clipped their titles at the edges
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    ds = _polarised(_compass_dataset((1.0, 0.0, 0.0, 0.0)))
    fig = images_figure(ds, None)
    FigureCanvasAgg(fig).draw()
    renderer = fig.canvas.get_renderer()
    assert len(fig.axes) >= 4 * ds.sizes["image_time"]  # radiance, DoLP, depth, parts
    texts = [ax.title for ax in fig.axes] + [ax.xaxis.label for ax in fig.axes]
    texts += [sub._suptitle for sub in fig.subfigs]
    texts = [t for t in texts if t is not None and t.get_text()]
    outside = [t.get_text() for t in texts if not _inside(t.get_window_extent(renderer), fig.bbox)]
    assert outside == []
    titles = [ax.title.get_window_extent(renderer) for ax in fig.axes if ax.get_title()]
    pairs = [(a, b) for i, a in enumerate(titles) for b in titles[i + 1 :]]
    assert not [p for p in pairs if p[0].overlaps(p[1])]
    # each row names its epoch once
    assert [sub._suptitle.get_text()[:30] for sub in fig.subfigs] == [
        "synthetic-pass: saved image 1 ",
        "synthetic-pass: saved image 2 ",
    ]


def _compass_over_target(fig, ax, ds: xr.Dataset, k: int) -> int:  # type: ignore[no-untyped-def]
    """On-target pixel centres under the compass disc of image ``k``, in display space."""
    from matplotlib.patches import Circle

    fig.canvas.draw()
    (disc,) = [p for p in ax.patches if isinstance(p, Circle)]
    outline = disc.get_transform().transform_path(disc.get_path())
    ny, nx = ds.sizes["y"], ds.sizes["x"]
    x0, x1, y0, y1 = ax.get_images()[0].get_extent()  # metres at the target, row 0 on top
    xs = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
    ys = y1 - (np.arange(ny) + 0.5) * (y1 - y0) / ny
    gx, gy = np.meshgrid(xs, ys)
    on = np.isfinite(ds["image_depth"].isel(image_time=k).values)
    centres = ax.transData.transform(np.column_stack([gx[on], gy[on]]))
    return int(outline.contains_points(centres).sum())


def test_the_compass_is_drawn_off_the_target() -> None:
    # issue 22 item 9: the compass (upper left) covered a wing reaching into that corner
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    ds = _compass_dataset((1.0, 0.0, 0.0, 0.0))
    ny, nx = ds.sizes["y"], ds.sizes["x"]
    row, col = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    # a wing from the upper-left corner to the lower-right one, and a body in the middle
    wing = np.abs(row - col) <= 2
    body = (row - ny / 2) ** 2 + (col - nx / 2) ** 2 < (ny / 5) ** 2
    for corner in ("upper left", "upper right"):
        mask = wing | body if corner == "upper left" else wing[:, ::-1] | body
        depth = np.where(mask, 0.0, np.nan)
        ds["image_depth"] = (("image_time", "y", "x"), np.stack([depth, depth]))
        fig = images_figure(ds, None)
        FigureCanvasAgg(fig)
        ax = fig.axes[0]
        assert _compass_over_target(fig, ax, ds, 0) == 0, corner
        assert {t.get_text() for t in ax.texts} - {""} == {"N", "Z", "☉"}
