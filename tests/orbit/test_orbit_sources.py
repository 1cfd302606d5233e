"""The registry of orbit sources (speclight.orbit.orbit_sources): one table that the
scenario's validation, the geometry stage's loading, the output's input hashes and the
messages read; every source is checked here, so a new one cannot be left out of any."""

import hashlib
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.orbit.orbit_sources import (
    ORBIT_SOURCES,
    file_keys,
    orbit_trajectory,
    source_keys,
)
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.scenario.sections_geometry import Orbit
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.input_hashes import input_files

DOCS = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"
EPOCHS = np.array(["2019-08-30T02:20:00"], dtype="datetime64[ns]")


def _scenario_with_orbit(orbit: dict, base_dir: Path):
    d = yaml.safe_load(example_text("box-wing"))
    d["orbit"] = orbit
    return parse_scenario(yaml.safe_dump(d), source="s.yaml", base_dir=base_dir)


def test_the_orbit_model_has_exactly_the_registered_keys_and_options():
    options = {o for s in ORBIT_SOURCES.values() for o in s.options}
    assert set(Orbit.model_fields) == set(ORBIT_SOURCES) | options
    # the list: TLE, CPF, tabulated, OEM, SP3, observed (a TLE inline or in a file)
    assert set(ORBIT_SOURCES) == {
        "tle",
        "tle_file",
        "cpf_file",
        "ephemeris_file",
        "oem_file",
        "sp3_file",
        "observed",
    }


@pytest.mark.parametrize("key", sorted(file_keys()))
def test_every_source_that_reads_a_file_is_hashed(tmp_path: Path, key: str):
    # the reference digest is hashlib's over the bytes written (the run's hash must match it)
    content = f"orbit file of {key}\n".encode() + bytes(range(256))
    (tmp_path / "orbit.dat").write_bytes(content)
    loaded = _scenario_with_orbit({key: "orbit.dat"}, tmp_path)
    hashed = input_files(loaded)
    assert hashed[f"orbit.{key}"] == {
        "path": str((tmp_path / "orbit.dat").resolve()),
        "sha256": hashlib.sha256(content).hexdigest(),
    }


def test_oem_and_sp3_files_are_among_the_hashed():
    # issue 22 item 7: runs that read an OEM or SP3 file recorded no hash of it
    assert {"tle_file", "cpf_file", "ephemeris_file", "oem_file", "sp3_file"} <= file_keys()
    assert not ORBIT_SOURCES["tle"].reads_file and not ORBIT_SOURCES["observed"].reads_file


@pytest.mark.parametrize("key", source_keys(loadable=True))
def test_each_key_loads_through_its_own_reader(tmp_path: Path, key: str):
    # a file that does not exist (or a TLE that is not one): the reader that answers is the
    # one of this key, named in its message
    value = "not a TLE" if key == "tle" else str(tmp_path / "absent")
    with pytest.raises(InputError, match=rf"orbit\.{key}\b"):
        orbit_trajectory({key: value}, Path, EPOCHS, "s.yaml")


def test_the_validation_message_lists_every_source(tmp_path: Path):
    with pytest.raises(InputError) as exc:
        _scenario_with_orbit({}, tmp_path)
    message = str(exc.value)
    assert "found none" in message
    for key in ORBIT_SOURCES:
        assert re.search(rf"\b{key}\b", message), key


def test_an_option_without_its_source_names_the_source(tmp_path: Path):
    for src in ORBIT_SOURCES.values():
        for option in src.options:
            other = "oem_file" if src.key != "oem_file" else "sp3_file"
            value = 1 if "int" in str(Orbit.model_fields[option].annotation) else "X"
            with pytest.raises(InputError, match=rf"{option} selects .* it needs {src.key}"):
                _scenario_with_orbit({other: "a", option: value}, tmp_path)


def test_observed_in_simulate_lists_every_source_that_has_an_orbit(tmp_path: Path):
    loaded = _scenario_with_orbit({"observed": True}, tmp_path)
    with pytest.raises(InputError) as exc:
        scenario_geometry(loaded)
    assert exc.value.field == "orbit.observed"
    message = str(exc.value)
    for key in source_keys(loadable=True):
        assert re.search(rf"\b{key}\b", message), key
    assert source_keys(loadable=True) == tuple(k for k in ORBIT_SOURCES if k != "observed")


def test_docs_list_every_source():
    text = DOCS.read_text()
    section = text[text.index("## `orbit`") : text.index("## `attitude`")]
    rows = re.findall(r"^\| `(\w+)[`:]", section, flags=re.M)
    assert set(rows) == set(ORBIT_SOURCES)
