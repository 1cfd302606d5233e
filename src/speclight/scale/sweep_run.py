"""Run a sweep: every case through the ``simulate`` pipeline on the executor, into the store.

Each case is one task (:func:`run_case`): it receives the case's scenario as text (plain,
picklable data), runs the normal pipeline where the executor puts it, and returns its light
curves as numpy arrays; the calling process alone writes them into ``RUNS.zarr`` as they
finish (:mod:`.sweep_store`). Mitsuba scenes are built inside the task. What does not change
from case to case is kept per worker: the geometry (orbit, observer, Sun, attitude) of a
sweep that varies neither ``time``, ``observer``, ``orbit`` nor ``attitude`` is computed once
per worker (:func:`~speclight.scale.worker_cached`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from speclight.errors import InputError
from speclight.io.store_io import check_free_space, store_lock, store_writes
from speclight.orbit.orbit_sources import file_keys
from speclight.scale import sweep_store as store
from speclight.scale.executor import open_executor
from speclight.scale.sweep_cases import CaseTask, SweepPlan
from speclight.scale.worker_cache import worker_cached
from speclight.scenario import LoadedScenario, parse_scenario

#: Scenario sections the geometry stage reads (``simulation.geometry_stage``).
GEOMETRY_SECTIONS = {"time", "observer", "orbit", "attitude"}

Task = Callable[[CaseTask], dict[str, np.ndarray]]


@dataclass
class SweepRun:
    """What a :func:`run_sweep` call did."""

    path: Path
    n_cases: int
    first_case: int
    ran: int = 0
    skipped: int = 0
    failed: dict[int, str] = field(default_factory=dict)
    complete: bool = False
    seconds: float = 0.0
    where: str = ""
    #: Cases marked done whose data did not read back (a chunk file cut short): run again.
    damaged: list[int] = field(default_factory=list)

    @property
    def exit_code(self) -> int:
        """1 when every case of the sweep file failed (nothing to read), else 0: failed cases
        are data (their rows are NaN, ``error(case)`` says why; the command line has only
        exit codes 0, 1 and 2: a partly failed batch is flagged row by row, not by its code)."""
        return 1 if self.failed and len(self.failed) >= self.n_cases else 0


def _geometry_key(loaded: LoadedScenario) -> str:
    sc = loaded.scenario
    parts = [sc.model_dump_json(include=GEOMETRY_SECTIONS), str(loaded.base_dir)]
    for name in sorted(file_keys()):  # every orbit source that reads a file
        value = getattr(sc.orbit, name)
        if value:  # a file edited between two sweeps on a long-lived worker is read again
            try:
                st = os.stat(loaded.resolve(value))
                parts.append(f"{st.st_mtime_ns}:{st.st_size}")
            except OSError:
                pass
    return "sweep-geometry:" + hashlib.sha256("\n".join(parts).encode()).hexdigest()


def run_case(task: CaseTask) -> dict[str, np.ndarray]:
    """One case through the pipeline: ``count_rate``, ``ab_magnitude`` (and
    ``count_rate_measured`` with noise; ``intensity``, ``spectral_flux`` with spectra)."""
    from speclight.simulation import simulate
    from speclight.simulation.geometry_stage import scenario_geometry

    loaded = parse_scenario(task.yaml_text, source=task.source, base_dir=Path(task.base_dir))
    try:
        geometry = worker_cached(_geometry_key(loaded), lambda: scenario_geometry(loaded))
    except InputError as exc:  # as simulate reports it: with the case's source
        raise InputError(exc.message, source=exc.source or task.source, field=exc.field) from None
    ds = simulate(loaded, geometry=geometry).dataset
    out = {name: np.asarray(ds[name].values) for name in store.CURVES if name in ds}
    if task.spectra:
        out.update({name: ds[name].values.astype(np.float32) for name in store.SPECTRA})
    return out


def _check_shapes(result: dict[str, np.ndarray], plan: SweepPlan) -> None:
    nt, nb = plan.time_utc.size, len(plan.band_names)
    for name, values in result.items():
        want = (nt, plan.wavelength_nm.size) if name in store.SPECTRA else (nt, nb)
        if values.shape != want:
            raise ValueError(f"{name} has shape {values.shape}, the store {want}")


def run_sweep(
    plan: SweepPlan,
    output: str | os.PathLike[str],
    *,
    scheduler: str | None = "local",
    n_workers: int | None = None,
    force: bool = False,
    append: bool = False,
    progress: bool = False,
    announce: bool = False,
    task: Task = run_case,
) -> SweepRun:
    """Run the plan's cases into the store ``output`` (created, resumed or appended to).

    Parameters
    ----------
    plan
        The validated cases (:func:`~speclight.scale.sweep_cases.plan_sweep`).
    output
        The Zarr store (a folder). A store holding these cases is resumed: cases done are
        skipped, failed ones run again.
    scheduler, n_workers
        Where the cases run (:func:`~speclight.scale.open_executor`).
    force
        Replace an existing store.
    append
        Add the cases after those of an existing store of the same fields and axes.
    progress, announce
        Progress bar over cases on a terminal; one line on where the work runs.
    task
        The function run per case (tests count its calls).

    Returns
    -------
    SweepRun
        Counts, failed cases (store index -> message), whether every case has run.
    """
    inputs = {"sweep file": Path(plan.spec.source)}
    if plan.base.source and Path(plan.base.source).exists():
        inputs["base scenario"] = Path(plan.base.source)
    path = store.check_store_path(output, inputs)
    started = time.perf_counter()
    with store_lock(path):
        with store_writes(path):
            group, start, _ = store.open_store(path, plan, force=force, append=append)
        run = SweepRun(path, len(plan.tasks), start)
        state = store.states(group)[start : start + len(plan.tasks)]
        run.damaged = store.damaged_cases(group, start + np.flatnonzero(state == store.DONE))
        state[np.asarray(run.damaged, dtype=np.int64) - start] = store.TODO  # run them again
        todo = [
            dataclasses.replace(t, index=start + t.index)
            for t in plan.tasks
            if state[t.index] != store.DONE
        ]
        check_free_space(path, len(todo) * store.case_bytes(plan), "the sweep", "the cases")
        run.skipped = len(plan.tasks) - len(todo)
        failed_before = {start + int(i) for i in np.flatnonzero(state == store.FAILED)}
        writer = store.CaseWriter(group, failed_before)
        try:
            if todo:
                with open_executor(
                    scheduler, n_workers=n_workers, announce=announce, task_bytes=plan.case_bytes
                ) as ex:
                    run.where = ex.description
                    for outcome in ex.run(task, todo, label="cases", progress=progress):
                        with store_writes(path):
                            _write(writer, plan, outcome, run)
        except BaseException:  # keep what was done (a full disk may refuse this too)
            with contextlib.suppress(OSError):
                writer.flush()
                store.finish(path, group)
            raise
        with store_writes(path):
            writer.flush()
            run.complete = store.finish(path, group)
        errors = store.errors(group, start, start + len(plan.tasks))
        run.failed = {i: e for i, e in errors.items()}
    run.seconds = time.perf_counter() - started
    return run


def _write(writer: store.CaseWriter, plan: SweepPlan, outcome: Any, run: SweepRun) -> None:
    index = outcome.item.index
    run.ran += 1
    if outcome.error is None:
        try:
            _check_shapes(outcome.result, plan)
        except ValueError as exc:
            writer.failed(index, f"ValueError: {exc}")
            return
        writer.done(index, outcome.result)
    else:
        writer.failed(index, outcome.error)
