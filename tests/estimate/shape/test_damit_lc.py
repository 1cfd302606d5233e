"""DAMIT .lc files: the reader against text written here from the format description
(Durech et al. 2010, A&A 513, A46), its errors, and the writer."""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.shape import read_damit_lc, write_damit_lc
from speclight.estimate.shape.inversion_data import from_damit

TEXT = """2
3 0
2451000.5 1.00 0.5 0.5 0.0 0.4 0.6 0.1
2451000.6 1.20 0.5 0.5 0.0 0.4 0.6 0.1
2451000.7 0.90 0.5 0.5 0.0 0.4 0.6 0.1

3 1
2452000.5 2.5D-1 -1.0 0.0 0.0 -0.9 0.1 0.0
2452000.5416 2.6d-1 -1.0 0.0 0.0 -0.9 0.1 0.0
2452000.5832 2.7E-1 -1.0 0.0 0.0 -0.9 0.1 0.0
"""


def test_reader_reads_the_format(tmp_path):
    path = tmp_path / "a.lc"
    path.write_text(TEXT)
    curves = read_damit_lc(path)
    assert [c.time_jd.size for c in curves] == [3, 3]
    assert [c.calibrated for c in curves] == [False, True]
    assert curves[0].brightness.tolist() == [1.0, 1.2, 0.9]
    assert curves[1].brightness.tolist() == [0.25, 0.26, 0.27]  # Fortran exponents
    assert curves[1].sun_ecliptic_au[0].tolist() == [-1.0, 0.0, 0.0]
    assert curves[0].observer_ecliptic_au[0].tolist() == [0.4, 0.6, 0.1]
    data = from_damit(curves, str(path))
    # unit vectors; the phase angle from the vectors (0.5, 0.5, 0) and (0.4, 0.6, 0.1)
    cos = np.dot([0.5, 0.5, 0], [0.4, 0.6, 0.1]) / np.sqrt(0.5) / np.sqrt(0.53)
    assert data.phase_angle_deg[0] == pytest.approx(np.rad2deg(np.arccos(cos)), abs=1e-9)
    assert data.calibrated.tolist() == [False, True]


def test_writer_round_trip(tmp_path):
    path = tmp_path / "a.lc"
    path.write_text(TEXT)
    curves = read_damit_lc(path)
    again = read_damit_lc(write_damit_lc(tmp_path / "b.lc", curves))
    for a, b in zip(curves, again, strict=True):
        assert np.array_equal(a.time_jd, b.time_jd) and np.array_equal(a.brightness, b.brightness)
        assert np.array_equal(a.sun_ecliptic_au, b.sun_ecliptic_au)
        assert a.calibrated == b.calibrated


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty"),
        ("2\n1 0\n2451000.5 1 1 0 0 1 0 0\n", "announces 2 light curves"),
        ("1\n2 0\n2451000.5 1 1 0 0 1 0 0\n", "announces 2 points"),
        ("1\n1 2\n2451000.5 1 1 0 0 1 0 0\n", r"flag 0 \(relative\) or 1"),
        ("1\n1 0\n2451000.5 1 1 0 0 1 0\n", "line 3: 7 numbers"),
        ("1\n1 0\n2451000.5 -1 1 0 0 1 0 0\n", "line 3: brightness -1.0 must be >= 0"),
        ("1\n1 0\n2451000.5 1 0 0 0 1 0 0\n", "the Sun vector is zero"),
        ("1\n1 0\n2451000.5 1 1 0 0 1 0 0\nextra\n", "after the 1 announced"),
        ("x\n", "not 1 numbers"),
    ],
)
def test_reader_errors_name_the_line(tmp_path, text, message):
    path = tmp_path / "bad.lc"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        read_damit_lc(path)
