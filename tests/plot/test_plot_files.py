"""`speclight plot` files: which figures are written, that they are real images, overwrite rules."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from plot_datasets import IMAGE_EPOCHS, full_dataset, write

from speclight.errors import InputError
from speclight.plot import figure_names, plot_dataset, plot_file, plot_files

pytest.importorskip("matplotlib")

# A figure with real content has many distinct colours (anti-aliased lines, colour maps);
# an empty or failed canvas has a handful (white, black axes, grey grid).
MIN_COLOURS_LINE_FIGURE = 200
MIN_COLOURS_IMAGE_FIGURE = 500


def _png(path: Path) -> np.ndarray:
    from matplotlib.image import imread

    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    return np.asarray(imread(path))


def _distinct_colours(img: np.ndarray) -> int:
    rgb = np.round(img[..., :3] * 255).astype(np.uint32).reshape(-1, 3)
    packed = (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
    return int(np.unique(packed).size)


def test_geometry_only_dataset_gives_the_geometry_figure(geometry_file: Path, tmp_path: Path):
    out = tmp_path / "geo.png"
    written = plot_files(geometry_file, out)
    assert written == [out]
    img = _png(out)
    # 10 in x 5.4 in at 120 dpi (constrained layout keeps the requested size)
    assert img.shape[1] == 1200
    assert _distinct_colours(img) > MIN_COLOURS_LINE_FIGURE
    assert not (tmp_path / "geo-chain.png").exists()


def test_full_dataset_gives_overview_and_chain(full_file: Path, tmp_path: Path):
    out = tmp_path / "pass.png"
    assert plot_file(full_file, out) == out
    for path in (out, tmp_path / "pass-chain.png"):
        assert _distinct_colours(_png(path)) > MIN_COLOURS_LINE_FIGURE
    assert not (tmp_path / "pass-images.png").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full.nc", "pass-chain.png", "pass.png"]


def test_refuses_to_overwrite_any_file_without_force(image_file: Path, tmp_path: Path):
    out = tmp_path / "pass.png"
    companion = tmp_path / "pass-images.png"
    companion.write_bytes(b"mine")
    with pytest.raises(InputError, match=r"pass-images\.png exists.*--force"):
        plot_files(image_file, out)
    # nothing was written, the existing file is untouched, no temporary files remain
    assert not out.exists()
    assert companion.read_bytes() == b"mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["images.nc", "pass-images.png"]
    # --force overwrites; only the figures asked for are written
    written = plot_files(image_file, out, force=True, kinds=["overview", "images"])
    assert [p.name for p in written] == ["pass.png", "pass-images.png"]
    assert _distinct_colours(_png(companion)) > MIN_COLOURS_IMAGE_FIGURE
    assert not (tmp_path / "pass-chain.png").exists()


def test_a_netcdf_that_is_not_a_speclight_dataset_is_an_input_error(tmp_path: Path):
    other = write(xr.Dataset({"temperature": ("x", np.arange(3.0))}), tmp_path / "other.nc")
    with pytest.raises(InputError, match="lacks the time dimension, range, elevation"):
        plot_file(other, tmp_path / "f.png")
    junk = tmp_path / "junk.nc"
    junk.write_text("not netcdf")
    with pytest.raises(InputError, match="cannot read it as a NetCDF dataset"):
        plot_file(junk, tmp_path / "f.png")
    assert not (tmp_path / "f.png").exists()


def test_bad_options_are_input_errors(image_file: Path, tmp_path: Path):
    with pytest.raises(InputError, match="did you mean 'G-650/30'"):
        plot_file(image_file, tmp_path / "f.png", band="G-650/3")
    with pytest.raises(InputError, match="outside the pass"):
        plot_file(image_file, tmp_path / "f.png", epoch=600)
    with pytest.raises(InputError, match="outside the pass"):
        plot_file(image_file, tmp_path / "f.png", epoch="2021-03-05T00:00:00")
    with pytest.raises(InputError, match=r"cannot write a figure as 'f\.nc'.*pdf.*png"):
        plot_file(image_file, tmp_path / "f.nc")
    with pytest.raises(InputError, match="unknown figure 'chian'; did you mean 'chain'"):
        plot_file(image_file, tmp_path / "f.png", kinds=["overview", "chian"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["images.nc"]


def test_ranging_figure_appears_when_ranging_variables_exist(tmp_path: Path):
    from speclight.plot.ranging import ranging_figure, strongest_return_epoch

    ds = full_dataset()
    assert figure_names(ds) == ["overview", "chain"]
    bins = np.linspace(-2.0, 2.0, 41)
    # returns peak at epoch 12; epoch 3 (below the minimum elevation) has more but is excluded
    strength = np.ones(ds.sizes["time"])
    strength[12], strength[3] = 5.0, 9.0
    hist = np.exp(-0.5 * (bins / 0.5) ** 2)[None, None, :] * strength[:, None, None]
    hist = hist * np.ones((1, 3, 1))
    ds = ds.assign_coords(range_bin=("range_bin", bins, {"units": "m"}))
    ds["range_histogram"] = (("time", "band", "range_bin"), hist, {"units": "1"})
    ds["range_offset"] = (("time", "band"), np.zeros((ds.sizes["time"], 3)), {"units": "m"})
    assert figure_names(ds) == ["overview", "chain", "ranging"]
    assert strongest_return_epoch(ds) == 12
    out = tmp_path / "r-ranging.png"
    ranging_figure(ds, epoch=30).savefig(out, dpi=120)
    assert _distinct_colours(_png(out)) > MIN_COLOURS_LINE_FIGURE


def test_plot_dataset_returns_a_figure_marking_image_epochs():
    from plot_datasets import image_dataset

    ds = image_dataset(size_px=8)
    fig = plot_dataset(ds)
    lines = fig.axes[0].get_lines()
    marked = {np.datetime64(x.get_xdata()[0], "ns") for x in lines if x.get_linestyle() == ":"}
    assert marked == set(ds["time"].values[list(IMAGE_EPOCHS)])


def test_images_figure_shows_the_named_parts() -> None:
    # A 2 x 2 image whose pixels see parts 0 and 1 ("bus", "wing") or nothing.
    import xarray as xr

    from speclight.plot.images import images_figure, part_names

    ds = xr.Dataset(
        {
            "image_radiance": (("image_time", "y", "x", "wavelength"), np.ones((1, 2, 2, 2))),
            "image_depth": (("image_time", "y", "x"), np.array([[[0.1, np.nan], [0.2, 0.3]]])),
            "image_part": (
                ("image_time", "y", "x"),
                np.array([[[0, -1], [1, 1]]], dtype=np.int16),
                {"flag_values": np.array([0, 1]), "flag_meanings": "bus wing"},
            ),
            "image_pixel_size": (("image_time",), [0.5]),
            "range": (("time",), [1e6]),
            "elevation": (("time",), [45.0]),
            "phase_angle": (("time",), [30.0]),
            "sunlit": (("time",), [1.0]),
        },
        coords={
            "time": np.array(["2020-01-01T00:00:00"], dtype="datetime64[ns]"),
            "image_time": np.array(["2020-01-01T00:00:00"], dtype="datetime64[ns]"),
            "wavelength": [500.0, 505.0],
        },
    )
    assert part_names(ds) == ["bus", "wing"]
    fig = images_figure(ds, None)
    labels = [t.get_text() for ax in fig.axes for t in ax.get_yticklabels()]
    assert "bus" in labels and "wing" in labels


def test_figures_get_the_mode_of_any_new_file(full_file: Path, tmp_path: Path):
    # POSIX open(2): a new file's mode is the requested 0666 less the umask; with umask 027
    # that is 0640 (a file from tempfile.mkstemp would stay 0600 whatever the umask).
    import os

    previous = os.umask(0o027)
    try:
        written = plot_files(full_file, tmp_path / "pass.png")
    finally:
        os.umask(previous)
    assert len(written) == 2  # overview and chain
    assert {p.stat().st_mode & 0o777 for p in written} == {0o640}
