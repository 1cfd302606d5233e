"""What `speclight plot` says about the figures and epochs a user asks for (issue 14, item 7)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from plot_datasets import full_dataset
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.plot import plot_files
from speclight.plot.chain import chain_figure
from speclight.plot.selection import resolve_epoch

pytest.importorskip("matplotlib")

# plot_datasets.geometry_dataset: epochs 47-49 in the penumbra (half the disk), 50-59 eclipsed
PENUMBRA, ECLIPSED, LIT = 48, 55, 37


@pytest.mark.parametrize(
    ("kind", "reason"),
    [("images", "no saved images"), ("ranging", "no laser ranging")],
)
def test_asking_for_a_figure_the_dataset_cannot_fill_is_an_input_error(
    full_file: Path, tmp_path: Path, kind: str, reason: str
) -> None:
    out = tmp_path / "pass.png"
    expected = rf"--kind: asked for {kind}, but the dataset has {reason}.*fill: overview, chain$"
    with pytest.raises(InputError, match=expected):
        plot_files(full_file, out, kinds=["overview", kind])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full.nc"]  # nothing written
    result = CliRunner().invoke(app, ["plot", str(full_file), "-o", str(out), "--kind", kind])
    assert result.exit_code == 2, result.output
    assert reason in result.stderr and not out.exists()


def test_chain_without_spectra_is_an_input_error(geometry_file: Path, tmp_path: Path) -> None:
    with pytest.raises(InputError, match="asked for chain, but the dataset has no spectra"):
        plot_files(geometry_file, tmp_path / "g.png", kinds=["overview", "chain"])


def test_a_bad_epoch_index_suggests_a_time_within_the_pass() -> None:
    ds = full_dataset()
    with pytest.raises(InputError, match="outside the pass") as caught:
        resolve_epoch(ds, 600)
    suggested = re.search(r"such as (\S+)", str(caught.value))
    assert suggested is not None
    when = np.datetime64(suggested.group(1), "ns")
    assert ds["time"].values[0] <= when <= ds["time"].values[-1]
    assert resolve_epoch(ds, suggested.group(1)) == ds.sizes["time"] // 2


def _sun_panel_curve(fig) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.asarray(fig.axes[0].get_lines()[0].get_ydata())


def test_chain_at_an_eclipsed_epoch_says_so_and_shows_no_sunlight() -> None:
    ds = full_dataset()
    solar = ds["solar_irradiance"].values
    fig = chain_figure(ds, ECLIPSED, "chosen with --epoch")
    title = fig._suptitle.get_text()
    assert "eclipsed (in the Earth's shadow)" in title and "not observable" not in title
    assert np.all(_sun_panel_curve(fig) == 0.0)  # sunlit fraction 0
    fig = chain_figure(ds, PENUMBRA, "chosen with --epoch")
    assert "in the penumbra (50 % of the solar disk)" in fig._suptitle.get_text()
    np.testing.assert_allclose(_sun_panel_curve(fig), 0.5 * solar[PENUMBRA], rtol=1e-12)
    fig = chain_figure(ds, LIT)
    assert "[" not in fig._suptitle.get_text()
    np.testing.assert_allclose(_sun_panel_curve(fig), solar[LIT], rtol=1e-12)


def test_one_kind_asked_for_is_written_to_exactly_the_file_named(
    full_file: Path, tmp_path: Path
) -> None:
    # issue 22 item 9: `plot -o bw-chain.png --kind chain` wrote the overview to
    # bw-chain.png and the chain to bw-chain-chain.png
    from matplotlib.image import imread

    plot_files(full_file, tmp_path / "all.png")  # the overview and, beside it, the chain
    out = tmp_path / "bw-chain.png"
    result = CliRunner().invoke(app, ["plot", str(full_file), "-o", str(out), "--kind", "chain"])
    assert result.exit_code == 0, result.output
    assert result.stdout == f"wrote {out}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "all-chain.png",
        "all.png",
        "bw-chain.png",
        "full.nc",
    ]
    # the chain figure (its size), not the overview
    chain, overview = imread(tmp_path / "all-chain.png"), imread(tmp_path / "all.png")
    assert chain.shape != overview.shape
    assert imread(out).shape == chain.shape
    # several kinds: the first goes to the file named, the others beside it
    written = plot_files(full_file, tmp_path / "two.png", kinds=["chain", "overview"])
    assert [p.name for p in written] == ["two.png", "two-chain.png"]


def test_a_missing_or_unreadable_dataset_is_a_one_line_error(tmp_path: Path) -> None:
    # issue 22 item 9: `speclight plot missing.nc` printed h5py's errno message
    junk = tmp_path / "junk.nc"
    junk.write_bytes(b"\x00" * 4096)
    cases = {
        tmp_path / "missing.nc": "cannot read dataset: no such file: it does not exist",
        tmp_path: "cannot read dataset: it is a folder; give the path of a file in it",
        junk: "cannot read it as a NetCDF dataset: it is not a NetCDF4 (HDF5) file; give a "
        "file written by `speclight simulate`",
    }
    for path, message in cases.items():
        result = CliRunner().invoke(app, ["plot", str(path), "-o", str(tmp_path / "f.png")])
        assert result.exit_code == 2, result.output
        assert result.stderr == f"error: {path}: {message}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["junk.nc"]


def test_the_band_panel_says_what_g_names_mean() -> None:
    # issue 22 item 9: G-420/26 reads like a FWHM of 26 nm; it is a sigma
    ds = full_dataset()  # bands G-450/30, G-650/30, G-850/30
    title = chain_figure(ds, LIT).axes[-1].get_title(loc="left")
    assert "G-c/s: Gaussian, centre c, sigma s [nm], not FWHM" in title
    renamed = ds.assign_coords(band=["blue", "red", "nir"])
    assert "sigma" not in chain_figure(renamed, LIT).axes[-1].get_title(loc="left")
