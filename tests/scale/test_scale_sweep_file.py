"""Sweep files: expansion into cases, seeded draws, and error messages (no simulation).

References: the case count of a product grid is the product of the list lengths and every
combination occurs once (counting); zipped lists pair their k-th values; the draws follow
their distributions within standard-error bounds (the sample mean of N draws of a law of
standard deviation s is within 5 s / sqrt(N) of the law's mean, a 5-sigma bound that a
correct sampler fails with probability 6e-7; the seed is fixed, so the test is
deterministic); the moments used: uniform (a + b) / 2 and (b - a) / sqrt(12), log-uniform:
the log is uniform on [log a, log b].
"""

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from speclight.errors import InputError
from speclight.scale.sweep_cases import plan_sweep
from speclight.scale.sweep_file import load_sweep, parse_sweep

DOCS = Path(__file__).parents[2] / "docs" / "examples"
Z = 5.0  # standard errors


def _values(text: str) -> list[dict]:
    return parse_sweep(text).case_values()


def test_product_grid_in_file_order_first_axis_slowest():
    cases = _values(
        "base: calsphere\nvary:\n  target.materials.body.reflectance: [0.1, 0.2, 0.3]\n"
        "  attitude.quaternion: [[1, 0, 0, 0], [0, 1, 0, 0]]\n"
    )
    assert len(cases) == 6
    expected = itertools.product([0.1, 0.2, 0.3], [[1, 0, 0, 0], [0, 1, 0, 0]])
    assert [tuple(c.values()) for c in cases] == list(expected)


def test_zipped_fields_vary_together_as_one_axis():
    spec = parse_sweep(
        "base: calsphere\nvary:\n  render.resolution_px: [16, 32]\n  zip:\n"
        "    orbit.tle_file: [a.tle, b.tle, c.tle]\n    orbit.norad_id: [1, 2, 3]\n"
    )
    cases = spec.case_values()
    assert spec.n_cases == 6  # 2 x 3, not 2 x 3 x 3
    assert [(c["orbit.tle_file"], c["orbit.norad_id"]) for c in cases[:3]] == [
        ("a.tle", 1),
        ("b.tle", 2),
        ("c.tle", 3),
    ]
    assert [c["render.resolution_px"] for c in cases] == [16, 16, 16, 32, 32, 32]


def test_several_zip_groups_and_a_list_of_them():
    spec = parse_sweep(
        "base: calsphere\nvary:\n  zip:\n    - {orbit.tle_file: [a, b], orbit.norad_id: [1, 2]}\n"
        "    - {observer.latitude_deg: [10, 20, 30], observer.longitude_deg: [1, 2, 3]}\n"
    )
    assert spec.n_cases == 6
    assert {
        (c["observer.latitude_deg"], c["observer.longitude_deg"]) for c in spec.case_values()
    } == {
        (10, 1),
        (20, 2),
        (30, 3),
    }


SEEDED = """base: calsphere
seed: {seed}
draws: {draws}
vary:
  target.materials.body.reflectance: [0.2, 0.4]
  attitude.quaternion: {{choice: [[1, 0, 0, 0], [0, 0, 0, 1]]}}
  instrument.optics_transmission: {{uniform: [0.5, 0.9]}}
"""


def test_seeded_draws_are_reproducible_and_more_draws_keep_the_first():
    a = _values(SEEDED.format(seed=7, draws=3))
    assert a == _values(SEEDED.format(seed=7, draws=3))
    assert a != _values(SEEDED.format(seed=8, draws=3))
    more = _values(SEEDED.format(seed=7, draws=5))
    assert len(more) == 10
    # draw d of grid point g depends on (seed, g, d) only
    assert more[0:3] == a[0:3] and more[5:8] == a[3:6]


@pytest.mark.parametrize(
    ("law", "mean", "std", "low", "high", "transform"),
    [
        ("uniform: [2.0, 5.0]", 3.5, 3 / math.sqrt(12), 2.0, 5.0, lambda x: x),
        ("normal: [-1.5, 0.25]", -1.5, 0.25, -np.inf, np.inf, lambda x: x),
        (
            "loguniform: [0.01, 100.0]",
            0.0,
            (math.log(100) - math.log(0.01)) / math.sqrt(12),
            math.log(0.01),
            math.log(100),
            np.log,
        ),
    ],
)
def test_distributions_follow_their_law(law, mean, std, low, high, transform):
    n = 4000
    spec = parse_sweep(
        f"base: calsphere\nseed: 11\ndraws: {n}\nvary:\n  attitude.initial_phase_deg: {{{law}}}\n"
    )
    x = transform(np.array([c["attitude.initial_phase_deg"] for c in spec.case_values()]))
    assert x.size == n and np.all((x >= low) & (x <= high))
    assert abs(x.mean() - mean) < Z * std / math.sqrt(n)
    # the sample standard deviation: standard error s / sqrt(2 (n - 1)) for a normal law,
    # smaller for the uniform laws (negative excess kurtosis), so the bound holds for all
    assert abs(x.std(ddof=1) - std) < Z * std / math.sqrt(2 * (n - 1))


def test_choice_draws_each_value_with_equal_probability():
    n, k = 3000, 3
    spec = parse_sweep(
        f"base: calsphere\nseed: 5\ndraws: {n}\n"
        "vary:\n  atmosphere.aerosol_profile: {choice: [x, y, z]}\n"
    )
    values = [c["atmosphere.aerosol_profile"] for c in spec.case_values()]
    for v in "xyz":  # binomial: mean n/k, standard deviation sqrt(n p (1 - p))
        p = 1 / k
        assert abs(values.count(v) - n * p) < Z * math.sqrt(n * p * (1 - p))


@given(st.lists(st.integers(min_value=1, max_value=4), min_size=1, max_size=3))
@settings(max_examples=30, deadline=None)
def test_every_grid_combination_occurs_once(lengths):
    names = ["observer.latitude_deg", "observer.longitude_deg", "observer.altitude_m"]
    lines = [f"  {names[k]}: {list(range(n))}" for k, n in enumerate(lengths)]
    cases = _values("base: calsphere\nvary:\n" + "\n".join(lines) + "\n")
    assert len(cases) == math.prod(lengths)
    assert len({tuple(c.values()) for c in cases}) == len(cases)


@given(st.integers(min_value=0, max_value=6), st.sampled_from(["vray", "bse", "sed", "drawz"]))
@settings(max_examples=25, deadline=None)
def test_an_unknown_key_is_reported_on_its_line(blank_lines, key):
    text = (
        "base: calsphere\n"
        + "# comment\n" * blank_lines
        + f"{key}: 1\nvary: {{telescope.aperture_diameter_m: [1]}}\n"
    )
    with pytest.raises(InputError, match=rf"^s\.yaml: line {blank_lines + 2}: {key}: unknown key"):
        parse_sweep(text, source="s.yaml")


@pytest.mark.parametrize(
    ("vary", "message"),
    [
        ("attitude.perod_s: [1, 2]", r"line 3: vary\.attitude\.perod_s: .*did you mean 'period_s'"),
        (
            "target.materials.body.roughnes: [0.1]",
            r"line 3: vary\.target\.materials\.body\.roughnes: .*did you mean 'roughness'",
        ),
        ("instrument.bands.first.name: [a]", r"line 3: .*instrument\.bands is a list: index it"),
        (
            "telescope.aperture_diameter_m: {uniform: [3, 1]}",
            r"line 3: vary\.telescope\.aperture_diameter_m = \{'uniform': \[3, 1\]\}: "
            r"uniform takes .*a < b",
        ),
        (
            "telescope.aperture_diameter_m: {normal: [0, 0]}",
            r"line 3: .*normal takes two numbers \[mu, sigma\] with sigma > 0",
        ),
        (
            "telescope.aperture_diameter_m: {loguniform: [0, 1]}",
            r"line 3: .*loguniform takes .* 0 < a < b",
        ),
        ("telescope.aperture_diameter_m: {choice: []}", r"line 3: .*choice needs a non-empty list"),
        (
            "telescope.aperture_diameter_m: {gauss: [0, 1]}",
            r"line 3: vary\.telescope\.aperture_diameter_m = .*one distribution: \{uniform",
        ),
        ("telescope.aperture_diameter_m: {unifrom: [0, 1]}", r"did you mean 'uniform'"),
        (
            "telescope.aperture_diameter_m: 3",
            r"line 3: vary\.telescope\.aperture_diameter_m = 3: give a list of values",
        ),
        (
            "telescope.aperture_diameter_m: []",
            r"line 3: vary\.telescope\.aperture_diameter_m = \[\]: give at least one value",
        ),
        (
            "zip: {orbit.tle_file: [a, b], orbit.norad_id: [1]}",
            r"line 3: vary\.zip\.orbit\.norad_id: has 1 values, orbit\.tle_file has 2",
        ),
        (
            "observer.altitude_m: [1]\n  observer: [2]",
            r"line 4: vary\.observer: overlaps observer\.altitude_m \(line 3\)",
        ),
    ],
)
def test_sweep_file_errors_name_line_field_value_and_what_is_accepted(vary, message):
    with pytest.raises(InputError, match=message):
        parse_sweep(f"base: calsphere\nvary:\n  {vary}\n", source="s.yaml")


def test_seed_is_required_with_distributions_and_draws_without_them_is_refused():
    with pytest.raises(InputError, match="give seed: N"):
        parse_sweep("base: calsphere\nvary: {telescope.aperture_diameter_m: {uniform: [0, 1]}}\n")
    with pytest.raises(InputError, match=r"line 2: draws = 3: without a random distribution"):
        parse_sweep("base: calsphere\ndraws: 3\nvary: {telescope.aperture_diameter_m: [1, 2]}\n")


def test_an_invalid_case_is_reported_with_its_vary_line_before_anything_runs():
    text = (
        "base: calsphere\nvary:\n  render.resolution_px: [32]\n"
        "  target.materials.body.reflectance: [0.5, 1.5]\n"
    )
    with pytest.raises(
        InputError,
        match=r"^s\.yaml: line 4: vary\.target\.materials\.body\.reflectance: case 1 .*"
        r"reflectance = 1\.5 must lie in \[0, 1\]",
    ):
        plan_sweep(parse_sweep(text, source="s.yaml"))


def test_a_field_the_base_section_lacks_and_a_changing_time_grid_are_refused():
    with pytest.raises(
        InputError, match=r"line 2: vary\.attitude\.period_s: case 0 .*does not take"
    ):
        plan_sweep(parse_sweep("base: calsphere\nvary: {attitude.period_s: [10]}\n"))
    with pytest.raises(InputError, match=r"line 2: vary\.time\.step_s: case 1 .*changes the time"):
        plan_sweep(parse_sweep("base: calsphere\nvary: {time.step_s: [1, 2]}\n"))


def test_base_is_an_example_or_a_file_next_to_the_sweep_file(tmp_path):
    with pytest.raises(InputError, match=r"line 1: base = 'calspher'.*did you mean 'calsphere'"):
        plan_sweep(
            parse_sweep("base: calspher\nvary: {render.resolution_px: [16]}\n", folder=tmp_path)
        )
    (tmp_path / "sub").mkdir()
    from speclight.scenario import example_text

    (tmp_path / "sub" / "cs.yaml").write_text(example_text("calsphere"))
    (tmp_path / "sweep.yaml").write_text("base: sub/cs.yaml\nvary: {render.resolution_px: [16]}\n")
    plan = plan_sweep(load_sweep(tmp_path / "sweep.yaml"))
    assert plan.base.source.endswith("cs.yaml") and len(plan.tasks) == 1


def test_the_shipped_example_expands_as_its_comment_says():
    plan = plan_sweep(load_sweep(DOCS / "sweep-calsphere.yaml"))
    assert len(plan.tasks) == 24 and len(plan.band_names) == 7 and plan.time_utc.size == 31
    albedo = [v["target.materials.body.reflectance"] for v in plan.values]
    assert albedo == [0.3] * 8 + [0.6] * 8 + [0.9] * 8
