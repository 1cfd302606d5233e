"""The phase-angle bisector in GCRS, the phase angle and the spin axis for the synodic
correction of ``speclight period`` (see :mod:`.synodic`).

Under the Sun the bisector is the dataset's ``phase_vector_body`` turned to GCRS; under
coaxial lasers (``source="laser"``: the light comes from the observer, phase angle 0) it is
the observer direction.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.estimate.period.periodogram import F64
from speclight.scenario import LoadedScenario


def _dataset_bisector(path: Path, source: str) -> tuple[np.ndarray, F64, F64] | None:
    """(time, PAB in GCRS, phase angle [deg]) from a speclight dataset, if it has the
    attitude and the phase vector (observer direction for lasers) at two epochs at least."""
    from speclight.attitude.quaternion import quat_rotate
    from speclight.io.user_dataset import read_user_dataset, values

    src = str(path)
    vector = "observer_direction_body" if source == "laser" else "phase_vector_body"
    wanted = ("attitude_quaternion", vector, "phase_angle")
    ds = read_user_dataset(path, "MEASURED", what="measurements", variables=wanted)
    if "attitude_quaternion" not in ds or vector not in ds:
        return None
    if source != "laser" and "phase_angle" not in ds:
        return None
    q = values(ds, "attitude_quaternion", ("time", "wxyz"), src, "MEASURED")
    pv = values(ds, vector, ("time", "xyz"), src, "MEASURED")
    t = ds["time"].values.astype("datetime64[ns]")
    if source == "laser":
        phase = np.zeros(t.size)
    else:
        phase = values(ds, "phase_angle", ("time",), src, "MEASURED")
    with np.errstate(invalid="ignore"):
        gcrs = quat_rotate(q, pv)
    if np.sum(np.all(np.isfinite(gcrs), axis=1)) < 2:  # NaN at (nearly) every epoch
        import warnings

        warnings.warn(
            f"{path}: {vector} or attitude_quaternion is NaN at (nearly) every epoch; the "
            "geometry of the synodic correction is the scenario's (where there is one)",
            stacklevel=3,
        )
        return None
    return t, gcrs, phase


def _at(t_out: np.ndarray, t_in: np.ndarray, v: F64) -> F64:
    ok = np.all(np.isfinite(v), axis=1)
    x_in = (t_in[ok] - t_in[0]) / np.timedelta64(1, "s")
    x_out = (t_out - t_in[0]) / np.timedelta64(1, "s")
    out = np.stack([np.interp(x_out, x_in, v[ok, k]) for k in range(3)], axis=1)
    return np.asarray(out / np.linalg.norm(out, axis=1, keepdims=True), dtype=np.float64)


def spin_axis_gcrs(loaded: LoadedScenario | None) -> F64 | None:
    """The spin axis of a scenario with ``attitude.model: spin`` (GCRS unit vector)."""
    from speclight.attitude.quaternion import unit_vector_from_radec
    from speclight.scenario.sections_geometry import SpinAttitude

    if loaded is None or not isinstance(loaded.scenario.attitude, SpinAttitude):
        return None
    a = loaded.scenario.attitude
    return np.asarray(unit_vector_from_radec(a.spin_axis_ra_deg, a.spin_axis_dec_deg))


def pass_geometry(
    measured: str | Path,
    lc: MeasuredLightCurve,
    loaded: LoadedScenario | None,
    source: str = "sun",
) -> tuple[F64, F64 | None, F64] | None:
    """(PAB in GCRS at the light curve's epochs (N, 3), spin axis or None, phase angle at
    the epochs (N,) [deg]), or None when the geometry is unknown (a CSV without a scenario,
    or NaN at all epochs but one).

    The PAB comes from the dataset (``attitude_quaternion`` and ``phase_vector_body``, or
    ``observer_direction_body`` for lasers, interpolated to binned epochs) or else from the
    scenario's geometry at the epochs.
    """
    path = Path(measured)
    found = None
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf", ".h5"):
        found = _dataset_bisector(path, source)
    if found is not None:
        t_in, gcrs, phase = found
    elif loaded is not None:
        from speclight.attitude.quaternion import quat_rotate
        from speclight.simulation.geometry_stage import scenario_geometry

        geo = scenario_geometry(loaded, lc.time_utc)
        vector = geo.observer_direction_body if source == "laser" else geo.phase_vector_body
        gcrs = quat_rotate(geo.quaternion_body_to_gcrs, vector)
        t_in = lc.time_utc
        phase = np.zeros(t_in.size) if source == "laser" else geo.phase_angle_deg
    else:
        return None
    if np.sum(np.all(np.isfinite(gcrs), axis=1)) < 2:
        return None  # no geometry at (nearly) any epoch: as unknown as without a scenario
    pab = _at(lc.time_utc, t_in, gcrs)
    x_in = (t_in - t_in[0]) / np.timedelta64(1, "s")
    x_out = (lc.time_utc - t_in[0]) / np.timedelta64(1, "s")
    ok = np.isfinite(phase)
    phase_at = np.interp(x_out, x_in[ok], phase[ok]) if ok.any() else np.full(x_out.size, np.nan)
    return pab, spin_axis_gcrs(loaded), np.asarray(phase_at, dtype=np.float64)
