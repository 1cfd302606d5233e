"""Scenario validation: every error names the file, the line, the field, the value and
what is accepted (SPEC sections 2-3; STYLE.md 6)."""

from __future__ import annotations

from pathlib import Path

import pytest

from speclight.errors import InputError
from speclight.scenario import example_names, example_text, load_scenario, parse_scenario


def _edited(old: str, new: str, name: str = "lcs1") -> str:
    text = example_text(name)
    assert old in text, f"test setup: {old!r} not in the example"
    return text.replace(old, new)


@pytest.mark.parametrize("name", ["box-wing", "box-wing-laser", "calsphere", "lcs1"])
def test_builtin_examples_validate(name: str) -> None:
    assert name in example_names()
    loaded = parse_scenario(example_text(name), source=name)
    assert loaded.scenario.time.stop > loaded.scenario.time.start


def test_misspelt_key_gets_did_you_mean_and_line() -> None:
    text = _edited("period_s: 12.0", "periodd: 12.0")
    with pytest.raises(InputError) as err:
        parse_scenario(text, source="my.yaml")
    msg = str(err.value)
    assert msg.startswith("my.yaml")
    assert "attitude.periodd: unknown key 'periodd'; did you mean 'period_s'?" in msg
    line = next(i for i, s in enumerate(text.splitlines(), 1) if "periodd" in s)
    assert f"line {line}: attitude.periodd" in msg


def test_wrong_unit_in_key_is_rejected_with_the_right_key() -> None:
    # A user writing milliseconds: the key carries the unit, so it is an unknown key.
    text = _edited("step_s: 2.0", "step_ms: 2000")
    with pytest.raises(InputError, match=r"did you mean 'step_s'"):
        parse_scenario(text, source="my.yaml")


def test_out_of_range_value_names_value_and_bound() -> None:
    text = _edited("step_s: 2.0", "step_s: -1")
    with pytest.raises(InputError, match=r"time\.step_s = -1: Input should be greater than 0"):
        parse_scenario(text)


def test_bad_enum_lists_choices() -> None:
    text = _edited("bsdf: beckmann", "bsdf: beckman")
    with pytest.raises(InputError) as err:
        parse_scenario(text)
    assert "target.materials.body.bsdf = 'beckman'" in str(err.value)
    assert "'beckmann'" in str(err.value) and "'lambertian'" in str(err.value)


def test_bad_reflectance_form_lists_accepted_forms() -> None:
    text = _edited("{conductor: Al}", "{metal: Al}")
    with pytest.raises(InputError, match=r"reflectance: not a reflectance; give a number"):
        parse_scenario(text)


def test_orbit_needs_exactly_one_source(tmp_path: Path) -> None:
    text = _edited("orbit:\n", "orbit:\n  cpf_file: x.cpf\n")
    with pytest.raises(InputError, match=r"exactly one of tle, tle_file, cpf_file"):
        parse_scenario(text)


def test_stop_before_start() -> None:
    text = _edited("stop: 2020-07-18T01:38:00Z", "stop: 2020-07-18T01:00:00Z")
    with pytest.raises(InputError, match=r"stop .* is before start"):
        parse_scenario(text)


def test_invalid_yaml_reports_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("name: x\ntime: {start: 2020-01-01T00:00:00Z, stop: [\n")
    with pytest.raises(InputError, match=r"bad\.yaml:\d+:\d+: not valid YAML"):
        load_scenario(path)


def test_missing_file() -> None:
    with pytest.raises(InputError, match=r"nope\.yaml: cannot read scenario file"):
        load_scenario("nope.yaml")


def test_not_a_mapping() -> None:
    with pytest.raises(InputError, match=r"a scenario is a YAML mapping"):
        parse_scenario("- 1\n- 2\n")


def test_unknown_example_suggests() -> None:
    with pytest.raises(InputError, match=r"did you mean 'lcs1'"):
        example_text("lcs")
