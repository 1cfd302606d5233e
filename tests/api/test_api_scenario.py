"""The Python API (issue 14 item 1): load from anything, overrides validated as a file is,
read-only models, and the recorded YAML always the scenario that ran.

References: the scenario files themselves (a value set by override must read back from the
recorded YAML; an invalid one must get the message the same value gets in a file).
"""

import subprocess
import sys
from datetime import timedelta

import pytest
import yaml

import speclight
from speclight.scenario import example_names, example_text, parse_scenario
from speclight.scenario.load import scenario_yaml
from speclight.scenario.overrides import replace_fields

SHORT = {"render.resolution_px": 16, "time.stop": "2020-02-29T21:13:10Z"}


def test_load_takes_a_file_an_example_text_and_a_mapping(tmp_path):
    path = tmp_path / "cal.yaml"
    path.write_text(example_text("calsphere"))
    from_file = speclight.load(path)
    from_str_path = speclight.load(str(path))
    from_name = speclight.load("calsphere")
    from_text = speclight.load(example_text("calsphere"))
    from_mapping = speclight.load(yaml.safe_load(example_text("calsphere")))
    for loaded in (from_str_path, from_name, from_text, from_mapping):
        assert loaded.scenario == from_file.scenario
    assert from_file.base_dir == tmp_path
    assert speclight.load(from_file) is from_file
    assert set(speclight.examples()) == set(example_names())


def test_load_refuses_what_is_not_a_scenario(tmp_path):
    with pytest.raises(speclight.InputError, match="did you mean 'calsphere'"):
        speclight.load("calsfere")
    with pytest.raises(speclight.InputError, match="got int"):
        speclight.load(42)  # type: ignore[arg-type]
    with pytest.raises(speclight.InputError, match="missing required field 'time'"):
        speclight.load({"name": "x"})


def test_overrides_set_fields_and_leave_the_original_alone():
    base = speclight.load("box-wing")
    changed = speclight.with_overrides(
        base, {"attitude.period_s": 5, "instrument.bands.0.gaussian.center_nm": 450}
    )
    assert changed.scenario.attitude.period_s == 5.0
    assert changed.scenario.instrument.bands[0].gaussian.center_nm == 450
    assert base.scenario.attitude.period_s == 120.0
    # the recorded YAML reads back to the scenario that will run
    assert parse_scenario(changed.yaml_text).scenario == changed.scenario


@pytest.mark.parametrize(
    ("overrides", "expected"),
    [
        ({"attitude.perod_s": 5}, "no field 'perod_s' in attitude; did you mean 'period_s'?"),
        ({"attitude.period_s": -1}, "attitude.period_s = -1: Input should be greater than 0"),
        ({"instrument.bands.99.name": "x"}, "list instrument.bands has 10 entries (indices 0..9)"),
        ({"time.step_s.x": 1}, "time.step_s is a single value: it has no field 'x'"),
    ],
)
def test_bad_overrides_get_the_scenario_files_messages(overrides, expected):
    with pytest.raises(speclight.InputError) as info:
        speclight.with_overrides(speclight.load("box-wing"), overrides)
    assert expected in str(info.value)
    assert "line " not in str(info.value)  # no lines of a generated text


def test_the_same_bad_value_in_a_file_gets_the_same_message():
    text = example_text("box-wing").replace("period_s: 120.0", "period_s: -1")
    with pytest.raises(speclight.InputError) as in_file:
        parse_scenario(text)
    with pytest.raises(speclight.InputError) as by_override:
        speclight.with_overrides(speclight.load("box-wing"), {"attitude.period_s": -1})
    file_msg = in_file.value.message.split(": ", 1)[1]  # after "line N"
    assert file_msg in by_override.value.message


def test_assignment_is_refused_and_changes_nothing():
    loaded = speclight.load("calsphere")
    stop = loaded.scenario.time.stop
    # a cross-field rule (stop before start) used to be checked after the value was set
    with pytest.raises(TypeError, match="with_overrides"):
        loaded.scenario.time.stop = loaded.scenario.time.start - timedelta(hours=1)
    with pytest.raises(TypeError, match="read-only"):
        loaded.scenario.render.resolution_px = 8
    assert loaded.scenario.time.stop == stop
    assert loaded.yaml_text == loaded.text_as_read


def test_a_copy_changed_in_code_records_its_own_yaml():
    loaded = speclight.load("box-wing")
    rough = replace_fields(loaded, {"target.materials.bus.roughness": 0.21})
    recorded = parse_scenario(rough.yaml_text).scenario
    assert recorded.target.materials["bus"].roughness == 0.21
    assert recorded == rough.scenario


@pytest.mark.parametrize("name", example_names())
def test_written_out_scenarios_read_back_equal(name):
    loaded = speclight.load(name)
    assert parse_scenario(scenario_yaml(loaded.scenario)).scenario == loaded.scenario


def test_simulate_returns_the_dataset_of_the_scenario_that_ran():
    result = speclight.simulate("calsphere", SHORT)
    ds = result.dataset
    assert ds.sizes["time"] == 11
    ran = parse_scenario(ds.attrs["scenario_yaml"]).scenario
    assert ran.render.resolution_px == 16
    assert isinstance(result.notes, list)


def test_python_m_speclight_version_and_short_help():
    run = [sys.executable, "-m", "speclight"]
    out = subprocess.run([*run, "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == f"speclight {speclight.__version__}"
    help_text = subprocess.run([*run, "-h"], capture_output=True, text=True, check=True).stdout
    assert "Usage: speclight" in help_text and "simulate" in help_text


def test_an_override_inside_a_missing_section_creates_it():
    # compare adds filter bands to scenarios that have no instrument section this way
    data = yaml.safe_load(example_text("calsphere"))
    data.pop("instrument")
    loaded = speclight.load(data)
    assert loaded.scenario.instrument.bands == []
    bands = [{"name": "bessell-V", "filter": "bessell-V"}]
    changed = speclight.with_overrides(loaded, {"instrument.bands": bands})
    assert [b.name for b in changed.scenario.instrument.bands] == ["bessell-V"]
