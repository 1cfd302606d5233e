"""The Zarr store of a sweep (``RUNS.zarr``): layout, resume and append bookkeeping.

Layout (Zarr format 3, a folder; ``xarray.open_zarr(RUNS.zarr)`` reads it as a dataset):

* coordinates ``case`` (0, 1, ...), ``time`` (UTC, ``datetime64[ns]``), ``band`` (names) and,
  with spectra, ``wavelength`` [nm];
* ``count_rate(case, time, band)`` [s-1] and ``ab_magnitude(case, time, band)`` [mag] as the
  ``simulate`` output has them (float64), ``count_rate_measured(case, time, band)`` where a
  case has ``instrument.noise``, ``dolp(case, time, band)`` [1] and ``aolp(case, time, band)``
  [deg] where a case has ``render.polarization``; with spectra ``intensity(case, time, wavelength)``
  [W sr-1 nm-1] and ``spectral_flux(case, time, wavelength)`` [W nm-1] (float32);
  one chunk per case;
* ``param_<field with dots as __>(case)``: each varied field's value (numbers, strings, or
  JSON text for lists and mappings);
* ``error(case)``: ``""`` for a case that ran, else its error (its rows are NaN);
* ``case_state(case)``: 0 to run, 1 done, 2 failed (written after the case's data, so a killed
  run loses at most the cases in flight);
* attributes: ``format``, ``fields`` (the varied fields), ``spectra``, ``segments`` (one per
  sweep file run into the store: ``sha256`` of its cases, ``source``, ``start``, ``n_cases``),
  the base scenario's YAML and source, the speclight version, ``complete``.

The store is written in place: its partial content is the resume state. It is written by the
calling process only (one writer, under the lock beside it).
"""

from __future__ import annotations

import json
import os
import shutil
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from speclight import schema
from speclight.errors import InputError
from speclight.io import zarr_store_path
from speclight.io.store_io import readable
from speclight.scale.sweep_cases import SweepPlan

FIELD = "--output"
FORMAT_NAME = "speclight sweep"
TODO, DONE, FAILED = 0, 1, 2
CURVES = ("count_rate", "ab_magnitude", "count_rate_measured", "dolp", "aolp")
SPECTRA = ("intensity", "spectral_flux")
#: Cases per chunk of the small per-case arrays (parameters, state, error).
SMALL_CHUNK = 4096


def check_store_path(output: str | os.PathLike[str], inputs: dict[str, Path]) -> Path:
    """Refuse a store name that cannot be written (:mod:`speclight.io.zarr_store_path`)."""
    return zarr_store_path.check_store_path(output, inputs, example="runs.zarr")


def open_store(path: Path, plan: SweepPlan, *, force: bool, append: bool) -> tuple[Any, int, bool]:
    """Open, create or extend the store for ``plan``: ``(group, first case index, new)``.

    A store holding a segment with the plan's cases (same ``sha256``) is resumed; with
    ``append``, a store of the same fields, axes and base gets the plan's cases after its
    own; anything else is refused unless ``force`` (which replaces it). A store whose
    creation did not finish (an empty folder, or no segment recorded yet, e.g. on a full
    disk) holds no case and is created again.
    """
    import zarr

    group: Any
    if path.exists() and (force or _unfinished_creation(path)):
        if any(path.iterdir()) and _format_of(path) != FORMAT_NAME:
            raise InputError(
                f"{path} is a folder but not a speclight sweep store; --force replaces only "
                "sweep stores: choose another name",
                field=FIELD,
            )
        shutil.rmtree(path)
    if not path.exists() or not any(path.iterdir()):
        # the format first: a store cut short by a full disk is still known as a sweep's
        group = zarr.open_group(
            str(path), mode="w", zarr_format=3, attributes={"format": FORMAT_NAME}
        )
        _create(group, plan)
        _add_segment(group, plan)
        return group, 0, True
    if _format_of(path) != FORMAT_NAME:
        raise InputError(
            f"{path} exists and is not a speclight sweep store; choose another name",
            field=FIELD,
        )
    group = zarr.open_group(str(path), mode="r+", use_consolidated=False)
    for segment in group.attrs["segments"]:
        if segment["sha256"] == plan.sha256:
            return group, int(segment["start"]), False
    if not append:
        n = group["case"].shape[0]
        raise InputError(
            f"{path} holds {n} cases of another sweep (its sweep file, base scenario or cases "
            "differ from these); rerun with the sweep file it was made from to resume it, "
            "pass --append to add these cases after its own, or --force to start again",
            field=FIELD,
        )
    _check_compatible(group, plan, path)
    start = _add_segment(group, plan)
    return group, start, True


def _attributes(path: Path) -> dict[str, Any]:
    try:
        attrs = json.loads((path / "zarr.json").read_text()).get("attributes", {})
    except (OSError, ValueError, AttributeError):
        return {}
    return attrs if isinstance(attrs, dict) else {}


def _format_of(path: Path) -> str | None:
    value = _attributes(path).get("format")
    return None if value is None else str(value)


def _unfinished_creation(path: Path) -> bool:
    """A sweep store without a recorded segment (see :func:`open_store`)."""
    attrs = _attributes(path)
    return attrs.get("format") == FORMAT_NAME and not attrs.get("segments")


def _segments_end(group: Any) -> int:
    """The first case after the recorded segments (an append cut short left more rows)."""
    return max((int(s["start"]) + int(s["n_cases"]) for s in group.attrs["segments"]), default=0)


def _param_dtype(values: list[Any]) -> str:
    if all(isinstance(v, bool) for v in values):
        return "bool"
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return "int64"
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return "float64"
    return "str"


def _param_values(values: list[Any], dtype: str) -> np.ndarray:
    if dtype == "str":
        return np.array([v if isinstance(v, str) else json.dumps(v) for v in values], dtype=str)
    return np.asarray(values, dtype=dtype)


def _stored_kind(arr: Any) -> str:
    kind = str(arr.dtype)
    return kind if kind in ("float64", "int64", "bool") else "str"


def _array(group: Any, name: str, shape: tuple[int, ...], dims: tuple[str, ...], **kw: Any) -> Any:
    chunks = (1, *shape[1:]) if len(shape) > 1 else (SMALL_CHUNK,)
    arr = group.create_array(name, shape=shape, chunks=chunks, dimension_names=dims, **kw)
    info = schema.VARIABLES.get(name)
    if info is not None:
        arr.attrs.update({"units": info.units, "long_name": info.long_name})
    return arr


def _curves(plan: SweepPlan) -> tuple[str, ...]:
    """The per-band curves the plan's cases write: ``count_rate_measured`` where a case has
    noise, ``dolp`` and ``aolp`` where one has ``render.polarization``."""
    extra = ("count_rate_measured",) if plan.noise else ()
    return (*CURVES[:2], *extra, *(CURVES[3:] if plan.polarization else ()))


def _create(group: Any, plan: SweepPlan) -> None:
    from speclight import __version__

    nt, nb = plan.time_utc.size, len(plan.band_names)
    for name, values, dtype in (
        ("time", plan.time_utc.astype("datetime64[ns]"), "M8[ns]"),
        ("band", np.array(plan.band_names, dtype=str), str),
    ):
        arr = group.create_array(
            name, shape=values.shape, chunks=values.shape, dtype=dtype, dimension_names=(name,)
        )
        arr[...] = values
    _array(group, "case", (0,), ("case",), dtype="int64", fill_value=-1)
    for name in _curves(plan):
        _array(group, name, (0, nt, nb), ("case", "time", "band"), dtype="f8", fill_value=np.nan)
    if plan.spec.spectra:
        wl = plan.wavelength_nm
        arr = group.create_array(
            "wavelength",
            shape=wl.shape,
            chunks=wl.shape,
            dtype="f8",
            dimension_names=("wavelength",),
        )
        arr[...] = wl
        arr.attrs["units"] = "nm"
        for name in SPECTRA:
            _array(
                group, name, (0, nt, wl.size), ("case", "time", "wavelength"), dtype="f4",
                fill_value=np.nan,
            )  # fmt: skip
    _array(group, "case_state", (0,), ("case",), dtype="u1", fill_value=TODO)
    _array(group, "error", (0,), ("case",), dtype=str, fill_value="")
    for f in plan.spec.fields:
        dtype = _param_dtype([v[f.name] for v in plan.values])
        kw: dict[str, Any] = {"fill_value": ""} if dtype == "str" else {}
        _array(group, f.param, (0,), ("case",), dtype=str if dtype == "str" else dtype, **kw)
    group.attrs.update(
        {
            "format": FORMAT_NAME,
            "title": f"speclight sweep of '{plan.base.scenario.name}'",
            "fields": [f.name for f in plan.spec.fields],
            "spectra": plan.spec.spectra,
            "segments": [],
            "base_scenario_yaml": plan.base.yaml_text,
            "base_scenario_source": plan.base.source,
            "speclight_version": __version__,
            "complete": False,
        }
    )


def _check_compatible(group: Any, plan: SweepPlan, path: Path) -> None:
    fields = [f.name for f in plan.spec.fields]
    problems = []
    if list(group.attrs["fields"]) != fields:
        problems.append(
            f"its fields are {', '.join(group.attrs['fields'])}, not {', '.join(fields)}"
        )
    if bool(group.attrs["spectra"]) != plan.spec.spectra:
        problems.append("spectra differ")
    if group.attrs["base_scenario_yaml"] != plan.base.yaml_text:
        problems.append("its base scenario differs")
    if not np.array_equal(group["time"][...], plan.time_utc.astype("datetime64[ns]")):
        problems.append("its time grid differs")
    if list(group["band"][...]) != plan.band_names:
        problems.append("its bands differ")
    if plan.spec.spectra and not np.array_equal(group["wavelength"][...], plan.wavelength_nm):
        problems.append("its wavelength grid differs")
    accepts = {"float64": ("float64", "int64"), "int64": ("int64",), "bool": ("bool",)}
    for f in plan.spec.fields if not problems else ():
        have = _stored_kind(group[f.param])
        new = _param_dtype([v[f.name] for v in plan.values])
        if have in accepts and new not in accepts[have]:
            problems.append(f"{f.name} holds {have} values, the new ones are {new}")
    if problems:
        raise InputError(
            f"cannot append to {path}: {'; '.join(problems)}; append a sweep of the same "
            "fields, base scenario and axes, or write another store",
            field=FIELD,
        )


def _add_segment(group: Any, plan: SweepPlan) -> int:
    """Resize the per-case arrays for the plan's cases and write their parameters; the
    segment is recorded last (a store is resumed from its segments)."""
    start = _segments_end(group)
    stop = start + len(plan.tasks)
    nt, nb = plan.time_utc.size, len(plan.band_names)
    for name in _curves(plan):  # a noisy or polarised segment appended to a store without
        if name not in group:
            _array(group, name, (start, nt, nb), ("case", "time", "band"),
                   dtype="f8", fill_value=np.nan)  # fmt: skip
    for _, arr in group.arrays():
        dims = arr.metadata.dimension_names or ()
        if dims[:1] == ("case",):
            arr.resize((stop, *arr.shape[1:]))
    group["case"][start:stop] = np.arange(start, stop)
    for f in plan.spec.fields:
        arr = group[f.param]
        arr[start:stop] = _param_values([v[f.name] for v in plan.values], _stored_kind(arr))
    segment = {
        "sha256": plan.sha256,
        "source": plan.spec.source,
        "start": start,
        "n_cases": len(plan.tasks),
    }
    group.attrs["segments"] = [*group.attrs["segments"], segment]
    return start


class CaseWriter:
    """Writes cases as they finish: each case's arrays at once, its state in batches.

    The states of the cases written since the last :meth:`flush` are written together (at
    most every ``flush_s`` seconds, and on :meth:`flush`): always after the cases' data, so a
    killed run re-runs at most those cases. Array handles are opened once.
    """

    def __init__(self, group: Any, failed_before: set[int], flush_s: float = 1.0) -> None:
        names = [n for n in (*CURVES, *SPECTRA) if n in group]
        self.arrays = {name: group[name] for name in names}
        self.state = group["case_state"]
        self.error = group["error"]
        self.failed_before = failed_before
        self.pending: dict[int, int] = {}
        self.flush_s = flush_s
        self.last = time.monotonic()

    def done(self, index: int, result: dict[str, np.ndarray]) -> None:
        """Write one case's arrays (NaN rows of a retried case are overwritten)."""
        for name, values in result.items():
            if name in self.arrays:
                self.arrays[name][index] = values
        if index in self.failed_before:
            self.error[index] = ""
        self._mark(index, DONE)

    def failed(self, index: int, message: str) -> None:
        """Record a case's error; its rows stay NaN (or become NaN if it had run)."""
        for arr in self.arrays.values():
            arr[index] = np.nan
        self.error[index] = message
        self._mark(index, FAILED)

    def _mark(self, index: int, state: int) -> None:
        self.pending[index] = state
        if time.monotonic() - self.last >= self.flush_s:
            self.flush()

    def flush(self) -> None:
        """Write the pending states."""
        if self.pending:
            index = np.fromiter(self.pending, dtype=np.int64)
            values = np.fromiter(self.pending.values(), dtype=np.uint8)
            self.state.set_coordinate_selection(index, values)
            self.pending.clear()
        self.last = time.monotonic()


def states(group: Any) -> np.ndarray:
    return np.asarray(group["case_state"][...], dtype=np.uint8)


def damaged_cases(group: Any, cases: np.ndarray) -> list[int]:
    """Cases among ``cases`` (marked done) whose per-case arrays do not read back (a chunk
    file cut short: :func:`speclight.io.store_io.readable`); the caller runs them again."""
    arrays = [group[name] for name in (*CURVES, *SPECTRA) if name in group]
    bad: list[int] = []
    for lo in range(0, cases.size, SMALL_CHUNK):  # a block at once, one by one where it fails
        block = cases[lo : lo + SMALL_CHUNK]
        if block.size and readable(arrays, slice(int(block[0]), int(block[-1]) + 1)):
            continue
        bad += [int(i) for i in block if not readable(arrays, slice(int(i), int(i) + 1))]
    return bad


def case_bytes(plan: SweepPlan) -> int:
    """The data of one case in the store, uncompressed [bytes]."""
    nt = plan.time_utc.size
    n = len(_curves(plan)) * nt * len(plan.band_names) * 8
    if plan.spec.spectra:
        n += len(SPECTRA) * nt * plan.wavelength_nm.size * 4
    return n


def finish(path: Path, group: Any) -> bool:
    """Record whether every case ran (done or failed) and consolidate the metadata."""
    import zarr

    complete = bool(np.all(states(group) != TODO))
    group.attrs["complete"] = complete
    with warnings.catch_warnings():  # "not part of the Zarr format 3 specification" yet
        warnings.simplefilter("ignore", category=UserWarning)
        zarr.consolidate_metadata(str(path))
    return complete


def errors(group: Any, start: int, stop: int) -> dict[int, str]:
    """Failed cases in ``start:stop``: store index -> message."""
    state = states(group)[start:stop]
    failed = np.flatnonzero(state == FAILED)
    if failed.size == 0:
        return {}
    text = group["error"][start:stop]
    return {start + int(i): str(text[i]) for i in failed}
