"""Scenario validation: every error names the file, the line, the field, the value and
what is accepted (SPEC sections 2-3; STYLE.md 6)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.scenario import example_names, example_text, load_scenario, parse_scenario


def _edited(old: str, new: str, name: str = "lcs1") -> str:
    text = example_text(name)
    assert old in text, f"test setup: {old!r} not in the example"
    return text.replace(old, new)


@pytest.mark.parametrize(
    "name",
    ["box-wing", "box-wing-laser", "calsphere", "cube-materials", "cube-materials-laser", "lcs1"],
)
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


def test_duplicate_key_names_the_key_and_both_lines() -> None:
    # issue 9 item 8: the second exposure_s silently replaced the first
    text = _edited("  exposure_s: 1.0\n", "  exposure_s: 1.0\n  exposure_s: 2.0\n")
    lines = text.splitlines()
    first = lines.index("  exposure_s: 1.0") + 1
    with pytest.raises(InputError) as exc:
        parse_scenario(text, source="my.yaml")
    assert str(exc.value) == (
        f"my.yaml:{first + 1}:3: not valid YAML: key 'exposure_s' is given twice in one "
        f"mapping, on line {first} (column 3) and line {first + 1} (column 3); YAML would keep "
        "the last silently: remove one"
    )


def test_keys_replaced_through_a_merge_are_not_duplicates() -> None:
    text = _edited(
        "illumination: {sun: true}", "base: &b {sun: false}\nillumination: {<<: *b, sun: true}"
    )
    with pytest.raises(InputError, match="unknown key 'base'"):  # but no duplicate-key error
        parse_scenario(text)


def test_values_yaml_cannot_construct_name_the_line() -> None:
    # an impossible date matched YAML's timestamp pattern: a ValueError and a traceback
    text = _edited("stop: 2020-07-18T01:38:00Z", "stop: 2020-07-32T01:38:00Z")
    with pytest.raises(InputError, match=r"my\.yaml:5:\d+: not valid YAML: cannot read "):
        parse_scenario(text, source="my.yaml")


@pytest.mark.parametrize(
    ("encode", "fragment"),
    [
        # fuzz/0366: 'Straße' in a Latin-1 comment line
        (lambda t: ("# Straße\n" + t).encode("latin-1"), "byte 0xdf at line 1, column 7"),
        (lambda t: t.encode("utf-16"), "it is UTF-16 text (byte-order mark ff fe)"),  # 0367
        (lambda t: b"\x1etky\xc8B" + t.encode(), "byte 0xc8 at line 1, column 5"),  # 0360
    ],
)
def test_scenario_not_in_utf8_is_an_input_error(
    tmp_path: Path, encode: Callable[[str], bytes], fragment: str
) -> None:
    path = tmp_path / "s.yaml"
    path.write_bytes(encode(example_text("lcs1")))
    with pytest.raises(InputError) as exc:
        load_scenario(path)
    assert str(exc.value).startswith(f"{path}: cannot read scenario file: {fragment}")


def test_pathologically_deep_nesting_is_an_input_error() -> None:
    # fuzz/0365: 5,000 nested lists exhausted Python's stack inside PyYAML (RecursionError)
    with pytest.raises(InputError, match=r"my\.yaml:1:70: .* nested more than 64 levels"):
        parse_scenario("name: " + "[" * 5000 + "]" * 5000, source="my.yaml")
    # 64 levels with the top mapping: the text reaches validation, which names the field
    with pytest.raises(InputError, match=r"line 3: name = \[\[\[.*valid string"):
        parse_scenario(_edited("name: lcs1-pass", "name: " + "[" * 63 + "]" * 63))


def test_cli_exits_2_with_one_line_for_a_utf16_scenario(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"  # fuzz/0367: a UnicodeDecodeError traceback, exit 1
    path.write_bytes(example_text("lcs1").encode("utf-16"))
    result = CliRunner().invoke(app, ["simulate", str(path), "-o", str(tmp_path / "o.nc")])
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: {path}: cannot read scenario file: it is UTF-16 text (byte-order mark ff fe); "
        "save it as UTF-8\n"
    )
