"""``speclight plot --magnitude``: the overview shows the magnitudes asked for (the dataset's
own variables, so the plotted curve must be exactly that variable), and refuses what the
dataset does not hold."""

import numpy as np
import pytest

import speclight
from speclight.errors import InputError
from speclight.plot.figures import plot_files
from speclight.plot.overview import overview_figure

SHORT = {
    "render.resolution_px": 16,
    "time.start": "2020-02-29T21:17:00Z",
    "time.stop": "2020-02-29T21:17:04Z",
}


@pytest.fixture(scope="module")
def dataset():
    return speclight.simulate("calsphere", SHORT).dataset


@pytest.mark.parametrize(
    ("kind", "name"),
    [("ab", "ab_magnitude"), ("exo", "ab_magnitude_exo"), ("standard", "ab_magnitude_standard")],
)
def test_overview_plots_the_chosen_magnitudes(dataset, kind, name):
    fig = overview_figure(dataset, magnitude=kind)
    ax = next(a for a in fig.axes if "mag" in a.get_ylabel())
    first = ax.get_lines()[0].get_ydata()
    expected = dataset[name].transpose("time", "band").values[:, 0]
    np.testing.assert_array_equal(np.asarray(first, dtype=float), expected)


def test_vega_v_is_one_curve(dataset):
    fig = overview_figure(dataset, magnitude="vega")
    ax = next(a for a in fig.axes if "Vega" in a.get_ylabel())
    np.testing.assert_array_equal(
        np.asarray(ax.get_lines()[0].get_ydata(), dtype=float), dataset["vega_v_magnitude"].values
    )


def test_unknown_or_missing_magnitudes_are_refused(dataset, tmp_path):
    path = tmp_path / "pass.nc"
    dataset.to_netcdf(path, engine="h5netcdf")
    with pytest.raises(InputError, match="--magnitude = 'jy'"):
        plot_files(path, tmp_path / "a.png", magnitude="jy")
    dataset.drop_vars("ab_magnitude_exo").to_netcdf(tmp_path / "old.nc", engine="h5netcdf")
    with pytest.raises(InputError, match="has no ab_magnitude_exo"):
        plot_files(tmp_path / "old.nc", tmp_path / "b.png", magnitude="exo")
