"""Measured light curves in (issue 10, item 1): CSV and speclight NetCDF, checks, binning.

References: files written here with known values; the binning against sums worked by hand
(the mean of n rates, the standard error sqrt(sum sigma^2) / n of their mean).
"""

import numpy as np
import pytest
import xarray as xr
import yaml

from speclight.errors import InputError
from speclight.estimate.inputs.measured import bin_light_curve, measured_from_dataset, read_measured
from speclight.io.netcdf import write_dataset
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

CSV = """# a camera and a SPAD
time,B,R,R_sigma
2020-02-29T21:16:00Z,100.5,20.0,1.5
2020-02-29T21:16:01+00:00,101.0,,2.0
2020-02-29T21:16:02,-3.0,nan,0.5
"""


#: A header and a first row, for cases that spoil the second row.
T1 = "time,B\n2020-01-01T00:00:00Z,1\n"


def _write(tmp_path, text, name="lc.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_csv_is_read_with_nan_cells_and_negative_rates_kept(tmp_path):
    lc = read_measured(_write(tmp_path, CSV))
    assert lc.band_names == ["B", "R"]
    expected = np.array(
        ["2020-02-29T21:16:00", "2020-02-29T21:16:01", "2020-02-29T21:16:02"], "datetime64[ns]"
    )
    np.testing.assert_array_equal(lc.time_utc, expected)
    np.testing.assert_array_equal(lc.rate_per_s, [[100.5, 20.0], [101.0, np.nan], [-3.0, np.nan]])
    assert lc.sigma_per_s is not None
    np.testing.assert_array_equal(lc.sigma_per_s[:, 1], [1.5, 2.0, 0.5])
    assert np.all(np.isnan(lc.sigma_per_s[:, 0]))  # B has no sigma column


def test_rows_out_of_time_order_are_sorted_with_a_notice(tmp_path):
    # issue 25 item 7: sorted instead of refused; the rows keep their values
    path = tmp_path / "unsorted.csv"
    path.write_text(
        "time,B\n2020-01-01T00:00:02Z,3\n2020-01-01T00:00:00Z,1\n2020-01-01T00:00:01Z,2\n"
    )
    with pytest.warns(UserWarning, match=r"line 3 comes before line 2\); sorted by time"):
        lc = read_measured(path)
    np.testing.assert_array_equal(lc.rate_per_s[:, 0], [1.0, 2.0, 3.0])
    assert np.all(np.diff(lc.time_utc) == np.timedelta64(1, "s"))
    # a repeated epoch is still refused, naming the lines it came from
    path.write_text(
        "time,B\n2020-01-01T00:00:01Z,1\n2020-01-01T00:00:00Z,2\n2020-01-01T00:00:01Z,3\n"
    )
    with pytest.warns(UserWarning), pytest.raises(InputError, match=r"line 4: .*repeats .*line 2"):
        read_measured(path)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("t,B\n2020-01-01T00:00:00Z,1\n", "first column must be 'time'"),
        ("time,B\n2020-01-01T00:00:00Z,1\n2020-01-01T00:00:00Z,2\n", "line 3: .*repeats"),
        ("time,B\n2020-01-01T00:00:00+02:00,1\n", "UTC offset \\+02:00"),
        ("time,B\nyesterday,1\n", "line 2: 'yesterday' is not an ISO 8601 time"),
        ("time,B\n2020-01-01T00:00:00Z,lots\n", "line 2: 'lots' in column 'B' is not a number"),
        ("time,B\n2020-01-01T00:00:00Z,1,2\n", "line 2: 3 cells, the header names 2"),
        ("time,B,G_sigma\n2020-01-01T00:00:00Z,1,2\n", "'G_sigma' is the sigma of no band"),
        ("time,B,B_sigma\n2020-01-01T00:00:00Z,1,-2\n", "sigma -2 is negative"),
        ("time,B\n", "a header but no rows"),
        ("# only a comment\n", "no header and no rows"),
        # epochs outside DE421 (1899-07-30..2053-10-08), before datetime64[ns] wraps 0001 to 1755
        (T1 + "0001-01-01T00:00:00Z,1\n", "line 3: 0001-01-01T00:00:00Z is outside .* DE421"),
        (T1 + "2200-01-01T00:00:00Z,1\n", "line 3: 2200-01-01T00:00:00Z is outside"),
        (T1 + "-0001-01-01T00:00:00Z,1\n", "line 3: -0001-01-01T00:00:00Z is outside"),
        # the header: empty, repeated, unnamed cells
        ("time,,R\n2020-01-01T00:00:00Z,1,2\n", "line 1, column 2: the header cell is empty"),
        ("time,B,R,B\n2020-01-01T00:00:00Z,1,2,3\n", "'B' is named twice \\(columns 2 and 4\\)"),
        ("time,B\n2020-01-01T00:00:00Z,1,7\n", "line 2: 3 cells, .*'7' is in a column without"),
        ("time,B,R\n2020-01-01T00:00:00Z,1\n", "line 2: 2 cells, the header names 3 .*cut short"),
        ('"time,B\n2020-01-01T00:00:00Z,1\n', r"first column must be 'time' .*, got 'time,B'"),
        # values no estimation can use
        (T1 + "2020-01-01T00:00:01Z,inf\n", "line 3, column 'B': rate inf is infinite"),
        (T1 + "2020-01-01T00:00:01Z,5e-324\n", "line 3, column 'B': rate 4.94066e-324 is subn"),
        (T1 + "2020-01-01T00:00:01Z,-1e300\n", "line 3, column 'B': rate -1e\\+300 is above 1e"),
        ("time,B,B_sigma\n2020-01-01T00:00:00Z,1,0\n", "line 2, column 'B_sigma': sigma 0 is 0"),
        ("time,B,B_sigma\n2020-01-01T00:00:00Z,100,1e-15\n", "sigma 1e-15 is below the rounding"),
        ("time,B,B_sigma\n2020-01-01T00:00:00Z,1,1e31\n", "sigma 1e\\+31 is above 1e\\+30"),
        ("time,B,R\n2020-01-01T00:00:00Z,1,0\n2020-01-01T00:00:01Z,2,-1\n",
         "band 'R' has no rate above 0 at any epoch"),
    ],
)  # fmt: skip
def test_bad_csv_is_refused_with_the_line(tmp_path, text, match):
    with pytest.raises(InputError, match=match) as err:
        read_measured(_write(tmp_path, text))
    assert err.value.source == str(tmp_path / "lc.csv")


def test_spreadsheet_forms_are_read_as_the_plain_csv(tmp_path):
    """A byte-order mark, quoted and padded cells, CRLF ends and trailing commas (one per row,
    or a whole empty column) read as the plain file does."""
    plain = read_measured(_write(tmp_path, CSV))
    lines = CSV.splitlines()
    odd = [
        "\ufeff" + lines[0],
        '" time ", "B" ,R,  R_sigma  ,',
        *(line + "," for line in lines[2:]),
    ]
    lc = read_measured(_write(tmp_path, "\r\n".join(odd) + "\r\n", name="odd.csv"))
    assert lc.band_names == plain.band_names
    np.testing.assert_array_equal(lc.time_utc, plain.time_utc)
    np.testing.assert_array_equal(lc.rate_per_s, plain.rate_per_s)
    np.testing.assert_array_equal(lc.sigma_per_s, plain.sigma_per_s)


def test_extra_csv_columns_are_refused_unless_bands_are_chosen(tmp_path):
    lc = read_measured(_write(tmp_path, CSV))
    with pytest.raises(InputError, match=r"column 'R' is not a band of the scenario"):
        lc.select_bands(["B"])
    assert lc.select_bands(["B"], subset=True).band_names == ["B"]  # period --bands B


def test_bands_are_checked_against_the_scenario(tmp_path):
    lc = read_measured(_write(tmp_path, CSV))
    assert lc.select_bands(["R", "B"]).band_names == ["R", "B"]
    np.testing.assert_array_equal(lc.select_bands(["R", "B"]).rate_per_s[:, 1], lc.rate_per_s[:, 0])
    with pytest.raises(InputError, match=r"band 'RR' .*did you mean 'R'"):
        lc.select_bands(["B", "RR"])


def test_a_speclight_dataset_gives_its_noisy_rates(tmp_path):
    d = yaml.safe_load(example_text("calsphere"))
    d["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:16:10Z", "step_s": 2.0}
    d["render"]["resolution_px"] = 32
    ds = simulate(parse_scenario(yaml.safe_dump(d), source="test")).dataset
    path = write_dataset(ds, tmp_path / "pass.nc")
    lc = read_measured(path)
    assert lc.band_names == [str(b) for b in ds["band"].values]
    np.testing.assert_array_equal(lc.time_utc, ds["time"].values)
    np.testing.assert_array_equal(lc.rate_per_s, ds["count_rate_measured"].values)
    assert lc.sigma_per_s is None


def test_binning_averages_rates_and_combines_sigmas(tmp_path):
    rows = ["time,A,A_sigma"]
    rates = [1.0, 3.0, 5.0, np.nan, 11.0]
    sig = [1.0, 2.0, 2.0, 1.0, 4.0]
    for k, (r, s) in enumerate(zip(rates, sig, strict=True)):
        rows.append(f"2020-01-01T00:00:0{k}.5Z,{r},{s}")
    lc = read_measured(_write(tmp_path, "\n".join(rows) + "\n"))
    binned = bin_light_curve(lc, 2.0)  # bins [0, 2), [2, 4), [4, 6) s from the first epoch
    np.testing.assert_array_equal(binned.n_samples, [2, 2, 1])
    np.testing.assert_allclose(binned.rate_per_s[:, 0], [2.0, 5.0, 11.0])  # the NaN is skipped
    np.testing.assert_allclose(binned.sigma_per_s[:, 0], [np.sqrt(5) / 2, 2.0, 4.0])
    expected = np.array(
        ["2020-01-01T00:00:01", "2020-01-01T00:00:03", "2020-01-01T00:00:04.5"], "datetime64[ns]"
    )
    np.testing.assert_array_equal(binned.time_utc, expected)
    with pytest.raises(InputError, match="bin_s = "):  # the Python parameter, not the flag
        bin_light_curve(lc, 0.0)


def _rates_dataset(rate, t=None, bands=("B", "R")):
    n = len(rate)
    t = (
        np.datetime64("2020-01-01T00:00:00", "ns") + np.arange(n) * np.timedelta64(1, "s")
        if t is None
        else t
    )
    return xr.Dataset(
        {"count_rate": (("time", "band"), np.asarray(rate, dtype=float))},
        coords={"time": t, "band": list(bands)},
    )


@pytest.mark.parametrize(
    ("ds", "match"),
    [
        (_rates_dataset([[1.0, 2.0], [np.inf, 1.0]]),
         r"time index 1 \(2020-01-01T00:00:01.000000000\), band 'B': rate inf is infinite"),
        (_rates_dataset([[1.0, 2.0]], bands=("B", "B")), "band 2 .* the name 'B' of an earlier"),
        (_rates_dataset([[1.0, 2.0]], bands=("B", " ")), "band 2 .* an empty name"),
        (_rates_dataset(np.zeros((0, 2))), "holds no epochs"),
        (_rates_dataset([[1.0, 2.0]], t=np.array(["2100-01-01"], "datetime64[s]")),
         r"time index 0 .* is outside what the shipped Sun ephemeris"),
        (_rates_dataset([[1.0, 0.0], [2.0, np.nan]]), "band 'R' has no rate above 0"),
    ],
)  # fmt: skip
def test_a_dataset_s_rates_get_the_checks_of_a_csv(ds, match):
    with pytest.raises(InputError, match=match):
        measured_from_dataset(ds, "pass.nc")
