"""Every command that reads a user file, on hostile files (issue 22, item 3).

Property: whatever file a user gives ``fit``, ``period``, ``spin-axis``, ``unmix``,
``reflection-map``, ``upsample``, ``compare``, ``plot`` or ``update-data``, the command
exits 0 with a result that holds no NaN where an answer belongs (the albedos, the period,
the spin axes, some abundance, some mapped pixel, the spectrum, the residual statistics),
or exits 2 with one ``error:`` line and writes nothing; never a traceback (exit 1).

The files (``hostile_files.py``): measured CSVs with odd epochs, columns, cells and values;
NetCDF datasets damaged, laid out otherwise or holding odd values; OBSERVATIONS CSVs,
FIT.json files and IERS tables spoilt; and paths that cannot be read (missing, a folder, a
FIFO, a loop of symbolic links, a file this user may not read: tests run as root, who may
read a mode-000 file, so ``open`` is made to refuse it). Two bounded Hypothesis properties
put random values in random cells of the measured CSV and random bytes into the NetCDF.

The inputs are tiny (a box-wing pass of 31 epochs at 16 px, 3 bands, a 48-direction map), so
the module takes about 65 s of CPU (``SPECLIGHT_FUZZ_EXAMPLES`` explores further).
"""

from __future__ import annotations

import builtins
import errno
import json
import math
import os
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr
from hostile_files import (
    FIT_JSON,
    IERS_TABLE,
    MEASURED_CSV,
    NETCDF,
    NETCDF_BYTES,
    OBSERVATIONS_CSV,
    damaged,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from speclight.cli import app
from speclight.io.netcdf import dataset_bytes
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.orbit import iers_files, timescale
from speclight.scenario import example_text, load_scenario
from speclight.simulation import simulate

runner = CliRunner()
EXAMPLES = int(os.environ.get("SPECLIGHT_FUZZ_EXAMPLES", "0"))
FUZZ = settings(
    deadline=timedelta(seconds=30),
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


def _pass_text() -> str:
    """The box-wing example cut to 31 epochs, 16 px, 100 nm bins, 3 bands, no noise."""
    text = example_text("box-wing")
    text = re.sub(r"resolution_px: \d+", "resolution_px: 16", text)
    text = re.sub(r"step_nm: \d+", "step_nm: 100", text)
    text = text.replace(
        "stop: 2019-08-30T02:29:59Z, step_s: 1.0", "stop: 2019-08-30T02:22:00Z, step_s: 4.0"
    )
    text = re.sub(r"  noise: \{[^}]*\}\n", "", text)
    lines, bands = [], 0
    for line in text.splitlines():
        bands += line.strip().startswith("- {name:")
        if not (line.strip().startswith("- {name:") and bands > 3):
            lines.append(line)
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("inputs")
    scenario = folder / "pass.yaml"
    scenario.write_text(_pass_text())
    loaded = load_scenario(scenario)
    ds = simulate(loaded).dataset
    assert "count_rate_measured" not in ds and ds.sizes["band"] == 3
    (folder / "pass.nc").write_bytes(dataset_bytes(ds))
    reflectivity_map(
        loaded,
        folder / "map.zarr",
        directions=48,
        phase_angles_deg=[40, 90, 130],
        rolls=4,
        chunk=48,
    )
    bands = [str(b) for b in ds["band"].values]
    times = np.datetime_as_string(ds["time"].values, unit="ms")
    rate = ds["count_rate"].transpose("time", "band").values
    rows = [f"{t}Z," + ",".join(f"{r:.6g}" for r in rs) for t, rs in zip(times, rate, strict=True)]
    (folder / "pass.csv").write_text("time," + ",".join(bands) + "\n" + "\n".join(rows) + "\n")
    site = loaded.scenario.observer
    mag = ds["ab_magnitude"].sel(band=bands[1]).values
    obs = [f"# latitude_deg: {site.latitude_deg}", f"# longitude_deg: {site.longitude_deg}"]
    obs += [f"# altitude_m: {site.altitude_m}", "time,magnitude,magnitude_sigma,band"]
    obs += [
        f"{t}Z,{m:.4f},0.05,{bands[1]}" for t, m in zip(times, mag, strict=True) if np.isfinite(m)
    ]
    (folder / "observed.csv").write_text("\n".join(obs) + "\n")
    (folder / "fit.json").write_text(json.dumps({"bands": {b: {"albedo": 0.5} for b in bands}}))
    (folder / "finals2000A.all").write_bytes(iers_files.shipped_finals_path().read_bytes())
    (folder / "imaging.yaml").write_text(IMAGING)
    names = ("pass.yaml", "pass.nc", "pass.csv", "map.zarr", "observed.csv", "fit.json")
    keys = ("scenario", "nc", "csv", "map", "observed", "fit")
    return {
        **{k: folder / n for k, n in zip(keys, names, strict=True)},
        "finals": folder / "finals2000A.all",
        "imaging": folder / "imaging.yaml",
    }


# --- the commands and what a result must hold ---------------------------------------------------


def _json(path: Path) -> Any:
    return json.loads(path.read_text())


def _finite(*values: Any) -> bool:
    return all(isinstance(v, (int, float)) and math.isfinite(v) for v in values)


def _fit_ok(out: Path) -> bool:
    return _finite(*(b["albedo"] for b in _json(out)["bands"].values()))


def _axis_ok(out: Path) -> bool:
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        keys = ("best_ra_deg", "best_dec_deg", "refined_ra_deg", "refined_dec_deg")
        return _finite(*(float(ds.attrs[k]) for k in keys))


def _some_finite(name: str) -> Callable[[Path], bool]:
    def ok(out: Path) -> bool:
        with xr.open_dataset(out, engine="h5netcdf") as ds:
            return bool(np.isfinite(ds[name].values).any())

    return ok


def _spectrum_ok(out: Path) -> bool:
    rows = [ln for ln in out.read_text().splitlines() if ln and ln[0].isdigit()]
    return bool(rows) and _finite(*(float(r.split(",")[1]) for r in rows))


def _period_ok(result: dict[str, object]) -> bool:
    # a finite period, or no detection said as such (issue 25: null and trend-only data)
    if result.get("detected") is False:
        return bool(str(result.get("verdict") or "").strip())
    return _finite(result["period_s"])


def _frames_ok(out: Path) -> bool:
    frames = _json(out / "truth.json")["frames"]
    return bool(frames) and all(_finite(f["ra_deg"], f["dec_deg"]) for f in frames)


def _compare_ok(out: Path) -> bool:
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        return _finite(float(ds.attrs["residual_rms_mag"]))


@dataclass(frozen=True)
class Command:
    """A command line with ``{IN}`` (the file under test), ``{OUT}`` and the fixture's files."""

    argv: tuple[str, ...]
    output: str | None
    result_ok: Callable[[Path], bool]

    def args(self, files: dict[str, Path], given: Path, out: Path) -> list[str]:
        names = {"IN": str(given), "OUT": str(out / self.output) if self.output else ""}
        names.update({k: str(v) for k, v in files.items()})
        return [a.format(**names) for a in self.argv]


MEASURED = {
    "fit": Command(("fit", "{scenario}", "{IN}", "-o", "{OUT}"), "fit.json", _fit_ok),
    "period": Command(
        ("period", "{IN}", "-o", "{OUT}", "--draws", "1"),
        "period.json",
        lambda out: _period_ok(_json(out)),
    ),
    "spin-axis": Command(
        (
            "spin-axis",
            "{scenario}",
            "{IN}",
            "--map",
            "{map}",
            "-o",
            "{OUT}",
            "--grid-deg",
            "60",
            "--phases",
            "4",
        ),
        "axis.nc",
        _axis_ok,
    ),
    "unmix": Command(
        (
            "unmix",
            "{IN}",
            "--scenario",
            "{scenario}",
            "--extract",
            "atgp",
            "--n",
            "2",
            "-o",
            "{OUT}",
        ),
        "abundance.nc",
        _some_finite("abundance"),
    ),
    "reflection-map": Command(
        ("reflection-map", "{IN}", "--scenario", "{scenario}", "--nside", "2", "-o", "{OUT}"),
        "rmap.nc",
        _some_finite("reflectance_factor"),
    ),
}
OTHERS = {
    "upsample": Command(
        ("upsample", "{scenario}", "{IN}", "-o", "{OUT}"), "spectrum.csv", _spectrum_ok
    ),
    "compare": Command(("compare", "{scenario}", "{IN}", "-o", "{OUT}"), "cmp.nc", _compare_ok),
    "plot": Command(
        ("plot", "{IN}", "-o", "{OUT}", "--kind", "overview"),
        "fig.png",
        lambda out: out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n",
    ),
    "update-data": Command(("update-data", "--from", "{IN}"), None, lambda out: True),
    "frames": Command(
        ("frames", "{IN}", "-o", "{OUT}", "--imaging", "{imaging}"), "frames", _frames_ok
    ),
}
#: The valid file of each command's slot (a fixture name) and the families that spoil it.
SLOTS = {
    "upsample": "fit",
    "compare": "observed",
    "plot": "nc",
    "update-data": "finals",
    "frames": "nc",
}
#: A small camera for ``speclight frames`` (docs/frames.md): no stars, no sky, no noise.
IMAGING = """\
detector: {width_px: 32, height_px: 32, plate_scale_arcsec: 20.0}
exposure_s: 1.0
cadence_s: 30
psf: {seeing: {profile: gaussian, fwhm_arcsec: 40.0}, diffraction: false}
sky: {model: none}
stars: {catalogue: none}
noise: false
"""


def _answer(command: Command, args: list[str], out: Path) -> str:
    """Run the command; '' if the property holds, else what went wrong."""
    out.mkdir(parents=True, exist_ok=True)
    result = runner.invoke(app, args)
    text = result.output
    written = out / command.output if command.output else None
    if "Traceback" in text or result.exit_code not in (0, 2):
        return f"exit {result.exit_code}: {text.strip().splitlines()[-1:]}"
    if result.exit_code == 2:
        errors = [ln for ln in text.splitlines() if ln.startswith("error:")]
        if len(errors) != 1:
            return f"exit 2 without one error line: {text!r}"
        if written is not None and written.exists():
            return f"exit 2 but {written.name} was written"
        return ""
    if written is not None and not command.result_ok(written):
        return f"exit 0 with NaN (or no answer) in {written.name}"
    return ""


@contextmanager
def _user_data(tmp_path: Path) -> Iterator[None]:
    """update-data installs into a folder of the test's, and runs forget it afterwards."""
    before = os.environ.get("SPECLIGHT_DATA_DIR")
    os.environ["SPECLIGHT_DATA_DIR"] = str(tmp_path / "user-data")
    try:
        yield
    finally:
        if before is None:
            os.environ.pop("SPECLIGHT_DATA_DIR")
        else:
            os.environ["SPECLIGHT_DATA_DIR"] = before
        timescale.reload_tables()


def _sweep(
    command: Command,
    files: dict[str, Path],
    tmp_path: Path,
    variants: dict[str, bytes],
    suffix: str,
) -> None:
    failures = []
    tmp_path.mkdir(parents=True, exist_ok=True)
    with _user_data(tmp_path):
        for k, (name, content) in enumerate(variants.items()):
            given = tmp_path / f"in{k}{suffix}"
            given.write_bytes(content)
            problem = _answer(
                command, command.args(files, given, tmp_path / f"out{k}"), tmp_path / f"out{k}"
            )
            if problem:
                failures.append(f"{name}: {problem}")
    assert not failures, "\n".join(failures)


# --- the families -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(MEASURED))
def test_measured_csv_families(files: dict[str, Path], tmp_path: Path, name: str) -> None:
    text = files["csv"].read_text()
    variants = {family: spoil(text).encode() for family, spoil in MEASURED_CSV.items()}
    _sweep(MEASURED[name], files, tmp_path, variants, ".csv")


@pytest.mark.parametrize("name", sorted(MEASURED))
def test_measured_netcdf_families(files: dict[str, Path], tmp_path: Path, name: str) -> None:
    raw = files["nc"].read_bytes()
    ds = xr.load_dataset(files["nc"], engine="h5netcdf")
    variants = {family: spoil(ds) for family, spoil in NETCDF.items()}
    variants.update({family: spoil(raw) for family, spoil in NETCDF_BYTES.items()})
    _sweep(MEASURED[name], files, tmp_path, variants, ".nc")


def test_other_file_families(files: dict[str, Path], tmp_path: Path) -> None:
    """upsample's FIT.json, compare's OBSERVATIONS, plot's and frames' DATASET, update-data's
    table."""
    raw = files["nc"].read_bytes()
    ds = xr.load_dataset(files["nc"], engine="h5netcdf")
    plots = {f: NETCDF[f](ds) for f in ("renamed time", "float time", "2-vectors", "inf rates")}
    plots.update({f: spoil(raw) for f, spoil in NETCDF_BYTES.items() if "damaged" not in f})
    families: dict[str, tuple[dict[str, bytes], str]] = {
        "upsample": (
            {f: s(files["fit"].read_text()).encode() for f, s in FIT_JSON.items()},
            ".json",
        ),
        "compare": (
            {f: s(files["observed"].read_text()).encode() for f, s in OBSERVATIONS_CSV.items()},
            ".csv",
        ),
        "plot": (plots, ".nc"),
        "frames": (plots, ".nc"),
        "update-data": (
            {f: s(files["finals"].read_text()).encode() for f, s in IERS_TABLE.items()},
            ".all",
        ),
    }
    for name, (variants, suffix) in families.items():
        _sweep(OTHERS[name], files, tmp_path / name, variants, suffix)


PATHS = ("missing", "folder", "FIFO", "symlink loop", "unreadable")


@contextmanager
def _bad_path(kind: str, tmp_path: Path, valid: Path) -> Iterator[Path]:
    path = tmp_path / f"{kind.replace(' ', '-')}{valid.suffix}"
    if kind == "folder":
        path.mkdir()
    elif kind == "FIFO":
        os.mkfifo(path)
    elif kind == "symlink loop":
        path.symlink_to(tmp_path / f"back{valid.suffix}")
        (tmp_path / f"back{valid.suffix}").symlink_to(path)
    elif kind == "unreadable":  # mode 000 to anyone but root; tests run as root
        path.write_bytes(valid.read_bytes())
        real_open = builtins.open

        def refuse(file: Any, *args: Any, **kwargs: Any) -> Any:
            if isinstance(file, (str, os.PathLike)) and Path(file) == path:
                raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(file))
            return real_open(file, *args, **kwargs)

        builtins.open = refuse
        try:
            yield path
        finally:
            builtins.open = real_open
        return
    yield path


def test_paths_that_cannot_be_read(files: dict[str, Path], tmp_path: Path) -> None:
    cases = [(n, c, files[kind]) for n, c in MEASURED.items() for kind in ("csv", "nc")]
    cases += [(n, c, files[SLOTS[n]]) for n, c in OTHERS.items()]
    failures = []
    with _user_data(tmp_path):
        for k, (name, command, valid) in enumerate(cases):
            for kind in PATHS:
                folder = tmp_path / f"{k}-{kind.replace(' ', '-')}"
                folder.mkdir()
                with _bad_path(kind, folder, valid) as given:
                    result = runner.invoke(app, command.args(files, given, folder))
                if result.exit_code != 2 or "Traceback" in result.output:
                    failures.append(f"{name} {valid.suffix} {kind}: exit {result.exit_code}")
    assert not failures, "\n".join(failures)


# --- random cells and random bytes ---------------------------------------------------------------

CELLS = st.one_of(
    st.sampled_from(["", "nan", "-nan", "inf", "-inf", "1e309", "5e-324", "-0", "1e300", "0x10",
                     "1_000", "\u0661\u0662\u0663", " 12 ", "None", "true", "9" * 400, "1e-300",
                     "2019-08-30T02:20:00Z", "'", '"', '"1"', "1,2"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(max_size=8),
)  # fmt: skip
TIMES = st.one_of(
    st.datetimes().map(lambda d: d.isoformat() + "Z"),
    st.sampled_from(["0001-01-01T00:00:00Z", "2019-08-30", "2019-08-30T02:20:00+01:00",
                     "2019-02-30T00:00:00Z", "2019-08-30T24:00:00Z", "1e9", ""]),
)  # fmt: skip


@settings(FUZZ, max_examples=EXAMPLES or 12)
@given(
    name=st.sampled_from(sorted(MEASURED)),
    row=st.integers(0, 30),
    column=st.integers(0, 3),
    value=st.data(),
)
def test_random_cells_of_a_measured_csv(
    files: dict[str, Path], tmp_path_factory: pytest.TempPathFactory, name: str, row: int,
    column: int, value: st.DataObject,
) -> None:  # fmt: skip
    lines = files["csv"].read_text().splitlines()
    cells = lines[row + 1].split(",")
    cells[column] = value.draw(TIMES if column == 0 else CELLS)
    lines[row + 1] = ",".join(cells)
    folder = tmp_path_factory.mktemp("cells")
    given = folder / "m.csv"
    given.write_text("\n".join(lines) + "\n", encoding="utf-8", errors="surrogatepass")
    problem = _answer(MEASURED[name], MEASURED[name].args(files, given, folder), folder)
    assert not problem, problem


@settings(FUZZ, max_examples=EXAMPLES or 6)
@given(name=st.sampled_from(sorted(MEASURED)), seed=st.integers(0, 2**16))
def test_random_bytes_in_a_measured_netcdf(
    files: dict[str, Path], tmp_path_factory: pytest.TempPathFactory, name: str, seed: int
) -> None:
    folder = tmp_path_factory.mktemp("bytes")
    given = folder / "m.nc"
    given.write_bytes(damaged(files["nc"].read_bytes(), seed))
    problem = _answer(MEASURED[name], MEASURED[name].args(files, given, folder), folder)
    assert not problem, problem


@pytest.mark.parametrize("name", sorted(OTHERS))
def test_the_valid_files_give_an_answer(files: dict[str, Path], tmp_path: Path, name: str) -> None:
    """The unspoiled file of each slot: exit 0 and a finite answer (the families above are
    then the only difference)."""
    command = OTHERS[name]
    with _user_data(tmp_path):
        problem = _answer(command, command.args(files, files[SLOTS[name]], tmp_path), tmp_path)
    assert not problem, problem
