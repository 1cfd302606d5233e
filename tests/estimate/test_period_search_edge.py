"""A period at the edge of the searched range is said and gets no standard deviation (issue 25).

References: the truths are set by construction against the range the options define (the
default shortest period ``2 K dt``, Nyquist for the K-th harmonic; a longest period given
as ``max_period_s``); a light curve that repeats in ``P`` also repeats in ``2P``, so a truth
below the range shows as its double; a truth well inside the range is the control.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from speclight.estimate import estimate_period
from speclight.estimate.period.peak_refinement import Peak
from speclight.estimate.period.period_decision import RotationDecision
from speclight.estimate.period.periodogram import BandSeries
from speclight.estimate.period.search_edge import search_edge

START = np.datetime64("2020-02-29T21:16:00", "s")


def _csv(path: Path, period_s: float, n: int = 300, harmonics: int = 2) -> Path:
    """Two bands at 1 s cadence of a one- or two-harmonic light curve, shot noise, fixed seed."""
    rng = np.random.default_rng(0)
    x = 2 * np.pi * np.arange(n) / period_s
    mag = 0.3 * np.cos(x) + (0.1 * np.cos(2 * x + 0.5) if harmonics > 1 else 0.0)
    rows = ["time,B1,B1_sigma,B2,B2_sigma"]
    for i in range(n):
        cells = [f"{START + np.timedelta64(i, 's')}Z"]
        for scale in (1e5, 5e4):
            rate = scale * 10 ** (-0.4 * mag[i])
            cells += [f"{rate + rng.normal(0, np.sqrt(rate)):.8g}", f"{np.sqrt(rate):.6g}"]
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n")
    return path


def test_a_truth_at_the_shortest_period_searched_is_said(tmp_path: Path) -> None:
    # 4 s = 2 K dt (K = 2, dt = 1 s): the default shortest period
    out = estimate_period(_csv(tmp_path / "lc.csv", 4.0), if_symmetric="keep").to_json()
    assert out["detected"] and abs(out["frequency_grid_hz"]["max"] - 0.25) < 1e-12
    edge = out["search_edge"]
    assert edge["side"] == "shortest" and abs(edge["bound_s"] - 4.0) < 1e-9
    assert "shortest period searched" in out["verdict"]
    assert out["period_std_s"] is None and "period_std_s" in out["undetermined"]


def test_a_truth_below_the_shortest_period_is_said(tmp_path: Path) -> None:
    # 3.5 s < 4 s: the light curve also repeats in 7 s, found inside the range
    out = estimate_period(_csv(tmp_path / "lc.csv", 3.5), if_symmetric="keep").to_json()
    assert out["detected"] and abs(out["photometric_period_s"] - 7.0) < 0.01
    assert out["search_edge"]["side"] == "shortest"
    assert "P/2 = 3.5" in out["verdict"] and "below the shortest one searched" in out["verdict"]
    assert out["period_std_s"] is None


def test_a_truth_beyond_the_longest_period_is_said(tmp_path: Path) -> None:
    # 100 s in a 299 s span, searched up to 60 s: no period, a lower bound at 60 s
    data = _csv(tmp_path / "lc.csv", 100.0, harmonics=1)
    out = estimate_period(data, max_period_s=60.0, if_symmetric="keep").to_json()
    assert not out["detected"] and out["period_s"] is None
    assert abs(out["period_lower_bound_s"] - 60.0) < 1e-9
    assert "longer than 60 s" in out["verdict"] and "a larger max_period_s" in out["verdict"]


def test_a_truth_inside_the_range_has_no_edge(tmp_path: Path) -> None:
    out = estimate_period(_csv(tmp_path / "lc.csv", 4.1), if_symmetric="keep").to_json()
    assert out["search_edge"] is None and out["period_std_s"] > 0
    # within 4 of its sigma of the truth (the sigma is calibrated, BENCHMARKS.md)
    assert abs(out["photometric_period_s"] - 4.1) < 4 * out["period_std_s"]


def test_a_peak_at_the_longest_period_searched_is_at_the_edge() -> None:
    t = np.arange(100.0)
    series = BandSeries(t, np.sin(t / 5), np.ones(100), np.zeros(100, dtype=np.int64), 1)
    freq = np.linspace(0.01, 0.2, 50)
    decision = RotationDecision(100.0, 100.0, 1.0, "", [])
    at_bound = Peak(0.01, 1e-5, 1.0, 90)
    edge = search_edge(series, at_bound, freq, 2, decision)
    assert edge is not None and edge.side == "longest" and abs(edge.bound_s - 100.0) < 1e-9
    # three of its standard deviations inside: not at the edge
    inside = Peak(0.01 + 3e-5, 1e-5, 1.0, 90)
    decision = RotationDecision(1 / inside.frequency_hz, 1 / inside.frequency_hz, 1.0, "", [])
    assert search_edge(series, inside, freq, 2, decision) is None


def test_the_cli_line_says_the_edge(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from speclight.cli import app

    data = _csv(tmp_path / "lc.csv", 4.0)
    args = ["period", str(data), "-o", str(tmp_path / "p.json"), "--if-symmetric", "keep"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "+- undetermined s" in result.output
    assert "at the edge of the searched range" in result.output
