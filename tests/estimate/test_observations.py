"""The OBSERVATIONS reader: sites per row or per file, and errors that name the line, the
column, the value and what is accepted (hand-written files)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.inputs.observations import read_observations


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "obs.csv"
    path.write_text(text)
    return path


def test_site_in_the_header_applies_to_every_row(tmp_path) -> None:
    obs = read_observations(
        _file(
            tmp_path,
            "# a comment\n# latitude_deg: 48.5\n# longitude_deg: 9.25\n# altitude_m: 355\n"
            "time,magnitude,magnitude_sigma,band\n"
            "2020-02-29T21:16:00Z,7.5,0.05,V\n2020-02-29T21:15:00,7.75,,bessell-V\n",
        )
    )
    assert obs.band == ["V", "bessell-V"]
    np.testing.assert_array_equal(obs.magnitude, [7.5, 7.75])
    assert obs.magnitude_sigma[0] == 0.05 and np.isnan(obs.magnitude_sigma[1])
    assert obs.time_utc[1] == np.datetime64("2020-02-29T21:15:00")
    assert obs.line.tolist() == [6, 7]
    assert [k for k, _ in obs.site_groups()] == [(48.5, 9.25, 355.0)]
    assert not obs.has_positions


def test_sites_per_row_group_by_site(tmp_path) -> None:
    obs = read_observations(
        _file(
            tmp_path,
            "time,latitude_deg,longitude_deg,altitude_m,magnitude,magnitude_sigma,band\n"
            "2020-02-29T21:16:00Z,48.5,9.25,355,7.5,0.1,V\n"
            "2020-02-29T21:16:00Z,46.9,7.5,951,7.6,0.1,V\n"
            "2020-02-29T21:16:10Z,48.5,9.25,355,7.4,0.1,V\n",
        )
    )
    groups = obs.site_groups()
    assert [k for k, _ in groups] == [(48.5, 9.25, 355.0), (46.9, 7.5, 951.0)]
    assert [g.tolist() for _, g in groups] == [[0, 2], [1]]


HEADER = "time,magnitude,magnitude_sigma,band,latitude_deg,longitude_deg\n"
ROW = "2020-02-29T21:16:00Z,7.5,0.05,V,48.5,9.25\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (HEADER + ROW + "2020-02-29T21:16:10Z,bright,0.05,V,48.5,9.25\n",
         r"line 3, column 'magnitude': 'bright' is not accepted; expected an AB magnitude"),
        (HEADER + ROW + "2020-02-29T21:16:10Z,7.5,-0.1,V,48.5,9.25\n",
         r"line 3, column 'magnitude_sigma': '-0.1' is not accepted; expected a standard"),
        (HEADER + "2020-02-29T21:16:10Z,7.5,0.1,V,95,9.25\n",
         r"line 2, column 'latitude_deg': '95' is not accepted; expected a geodetic latitude "
         r"\[deg\] within -90..90"),
        (HEADER + "2020-02-29 25:00,7.5,0.1,V,45,9.25\n",
         r"line 2, column 'time': '2020-02-29 25:00' is not an ISO 8601 time"),
        (HEADER + "2020-02-29T21:16:10+01:00,7.5,0.1,V,45,9.25\n",
         r"line 2, column 'time': .* give UTC"),
        (HEADER + "2020-02-29T21:16:10Z,7.5,0.1,,45,9.25\n", r"line 2, column 'band': a band"),
        (HEADER + "2020-02-29T21:16:10Z,7.5,0.1,V,45\n", r"line 2: 5 cells, the header names 6"),
        ("time,magnitude,magnitude_sigma,bnd,latitude_deg,longitude_deg\n" + ROW,
         r"line 1: unknown column 'bnd'; did you mean 'band'\?"),
        ("time,magnitude,band,latitude_deg,longitude_deg\n2020-02-29T21:16:00Z,7.5,V,1,2\n",
         r"line 1: missing column\(s\) magnitude_sigma"),
        ("time,magnitude,magnitude_sigma,band\n2020-02-29T21:16:00Z,7.5,0.1,V\n",
         r"no latitude_deg: give the site as columns"),
        ("# latitude_deg: 40\n# longitude_deg: 9\n" + HEADER + ROW,
         r"the site is given both in '# key: value' lines"),
        ("# latitude_deg: north\ntime,magnitude,magnitude_sigma,band\n",
         r"line 1, column 'latitude_deg': 'north' is not accepted"),
        (HEADER.strip() + ",elevation_deg,azimuth_deg\n" + ROW.strip() + ",30,120\n",
         r"line 2: the target's position needs elevation_deg, azimuth_deg and range_m .* "
         r"gives elevation_deg, azimuth_deg"),
        (HEADER.strip() + ",elevation_deg,azimuth_deg,range_m\n" + ROW.strip() + ",30,120,800\n"
         .replace("800", "-800"),
         r"line 2, column 'range_m': '-800' is not accepted; expected a range \[m\]"),
        (HEADER + "1850-01-01T00:00:00Z,7.5,0.1,V,45,9.25\n",
         r"line 2, column 'time': 1850-01-01T00:00:00Z is outside .* accepted: 1899-07-30"),
        (HEADER, r"the file holds a header but no rows"),
        ("", r"the file holds no header and no rows"),
    ],
)  # fmt: skip
def test_errors_name_the_line_column_value_and_what_is_accepted(tmp_path, text, message):
    with pytest.raises(InputError, match=message) as info:
        read_observations(_file(tmp_path, text))
    assert str(info.value).startswith(str(tmp_path / "obs.csv"))
