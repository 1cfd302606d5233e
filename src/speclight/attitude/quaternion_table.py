"""Tabulated attitude: quaternions from a CSV file, interpolated by slerp.

Format::

    # frame: body_to_gcrs     (or gcrs_to_body; optional, default body_to_gcrs)
    # any other comment lines
    time_utc,w,x,y,z
    2024-03-01T02:00:00Z,1.0,0.0,0.0,0.0
    ...

Quaternions are scalar first (``w`` the scalar part), Hamilton convention. ``body_to_gcrs``
(the default, speclight's own convention) means ``v_gcrs = R(q) v_body``; ``gcrs_to_body``
rows are conjugated on reading. Times are ISO 8601 UTC (a trailing ``Z`` is allowed),
strictly increasing; at least two rows; each quaternion's norm within 1e-3 of 1 (it is
then normalised).

Between two rows the attitude is the spherical linear interpolation (slerp; Shoemake 1985,
"Animating rotation with quaternion curves", SIGGRAPH '85, doi:10.1145/325165.325242) along
the shorter arc (the second quaternion's sign is flipped when ``q0 · q1 < 0``), i.e. a
rotation at constant rate about a fixed axis. Epochs before the first or after the last row
are not extrapolated: they come back as NaN rows with ``inside = False`` (the geometry stage
flags them ``attitude_undefined``).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from speclight.attitude.fixed import QUATERNION_NORM_TOLERANCE
from speclight.attitude.quaternion import FloatArray, quat_conjugate
from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text

FRAMES = ("body_to_gcrs", "gcrs_to_body")
HEADER = ["time_utc", "w", "x", "y", "z"]
#: Below this angle between neighbouring quaternions [rad] slerp is replaced by the
#: normalised linear interpolation (they agree to O(angle^3) ~ 1e-24 there).
SLERP_SMALL_ANGLE_RAD = 1e-8


@dataclass(frozen=True)
class AttitudeTable:
    """A tabulated attitude.

    Attributes
    ----------
    path
        File read.
    times_utc
        (M,) epochs, ``datetime64[ns]`` UTC, strictly increasing.
    q_body_to_gcrs
        (M, 4) unit quaternions, scalar first, body to GCRS (whatever the file's frame).
    """

    path: str
    times_utc: NDArray[np.datetime64]
    q_body_to_gcrs: FloatArray


def _utc(cell: str) -> np.datetime64:
    t = np.datetime64(cell[:-1] if cell.upper().endswith("Z") else cell)
    if np.isnat(t):
        raise ValueError("not a time")
    return t.astype("datetime64[ns]")


def _frame(value: str, lineno: int, p: str) -> Literal["body_to_gcrs", "gcrs_to_body"]:
    frame = value.strip().lower().replace("->", "_to_").replace(" ", "")
    if frame == "body_to_gcrs":
        return "body_to_gcrs"
    if frame == "gcrs_to_body":
        return "gcrs_to_body"
    raise InputError(
        f"line {lineno}: frame {value.strip()!r} is not accepted{did_you_mean(frame, FRAMES)} "
        "(choices: body_to_gcrs, gcrs_to_body)",
        source=p,
        field="frame",
    )


def read_attitude_table(path: str | Path, field: str = "attitude.file") -> AttitudeTable:
    """Read a quaternion table (see the module docstring for the format).

    Raises
    ------
    InputError
        The file is missing or not UTF-8 text, an unknown frame, a wrong column header,
        unreadable or non-finite values, a quaternion whose norm is not within 1e-3 of 1,
        fewer than 2 rows, or times not strictly increasing.
    """
    p = str(path)
    text = read_user_text(path, field, what="attitude table")
    frame: Literal["body_to_gcrs", "gcrs_to_body"] = "body_to_gcrs"
    header: list[str] | None = None
    times: list[np.datetime64] = []
    quats: list[list[float]] = []
    for lineno, line in enumerate(text.split("\n"), start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, _, value = s.lstrip("#").partition(":")
            if key.strip().lower() == "frame":
                frame = _frame(value, lineno, p)
            continue
        try:
            cells = [c.strip() for c in next(csv.reader([s]))]
        except csv.Error as exc:
            raise InputError(f"line {lineno}: not a CSV row ({exc})", source=p) from None
        if header is None:
            header = _header(cells, lineno, p)
            continue
        t, q = _row(s, cells, lineno, p)
        times.append(t)
        quats.append(q)
    t_arr = _increasing(times, p)
    q_arr = np.array(quats, dtype=np.float64)
    if frame == "gcrs_to_body":
        q_arr = quat_conjugate(q_arr)
    return AttitudeTable(path=p, times_utc=t_arr, q_body_to_gcrs=q_arr)


def _increasing(times: list[np.datetime64], p: str) -> NDArray[np.datetime64]:
    """The rows' times: at least 2, strictly increasing."""
    if len(times) < 2:
        raise InputError(f"{len(times)} data rows; need at least 2", source=p)
    t_arr = np.array(times, dtype="datetime64[ns]")
    bad = np.flatnonzero(np.diff(t_arr) <= np.timedelta64(0, "ns"))
    if bad.size:
        raise InputError(
            f"row {bad[0] + 2} ({t_arr[bad[0] + 1]}) is not after the previous row; times must "
            "increase strictly",
            source=p,
        )
    return t_arr


def _header(cells: list[str], lineno: int, p: str) -> list[str]:
    """The column header (it must be :data:`HEADER`)."""
    header = [c.lower() for c in cells]
    if header != HEADER:
        raise InputError(
            f"line {lineno}: column header {','.join(cells)!r} is not accepted; use "
            f"{','.join(HEADER)} (scalar first)",
            source=p,
            field="header",
        )
    return header


def _row(s: str, cells: list[str], lineno: int, p: str) -> tuple[np.datetime64, list[float]]:
    """The time and the unit quaternion (normalised; its norm within the tolerance of 1)
    of a data row."""
    try:
        if len(cells) != 5:
            raise ValueError(f"{len(cells)} columns instead of 5")
        t = _utc(cells[0])
        q = [float(c) for c in cells[1:]]
        if not all(np.isfinite(q)):
            raise ValueError("a component is not finite")
    except ValueError as exc:
        raise InputError(
            f"line {lineno}: cannot read {s!r} ({exc}); expected an ISO UTC time and "
            "four numbers w, x, y, z",
            source=p,
        ) from None
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        raise InputError(
            f"line {lineno}: quaternion {q} has norm {norm:.6g}; it must be within "
            f"{QUATERNION_NORM_TOLERANCE} of 1",
            source=p,
        )
    return t, [c / norm for c in q]


def slerp_table(
    times_utc: NDArray[np.datetime64], q_knots: FloatArray, at_utc: NDArray[np.datetime64]
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Slerp between tabulated quaternions; no extrapolation.

    Parameters
    ----------
    times_utc
        (M,) knot epochs, M >= 2, strictly increasing, ``datetime64``.
    q_knots
        (M, 4) unit quaternions at the knots, scalar first.
    at_utc
        (N,) epochs to evaluate, ``datetime64``.

    Returns
    -------
    q : numpy.ndarray
        (N, 4) interpolated unit quaternions; NaN rows outside ``[times[0], times[-1]]``
        (and at NaT epochs).
    inside : numpy.ndarray
        (N,) True where the epoch is inside the table.
    """
    knots = np.asarray(times_utc, dtype="datetime64[ns]").astype(np.int64)
    at = np.asarray(at_utc, dtype="datetime64[ns]")
    at_ns = at.astype(np.int64)
    inside = ~np.isnat(at) & (at_ns >= knots[0]) & (at_ns <= knots[-1])
    i = np.clip(np.searchsorted(knots, at_ns, side="right") - 1, 0, knots.size - 2)
    u = (at_ns - knots[i]) / (knots[i + 1] - knots[i])
    q0, q1 = q_knots[i], q_knots[i + 1].copy()
    dot = np.einsum("ni,ni->n", q0, q1)
    q1[dot < 0.0] *= -1.0  # the shorter arc: q and -q are the same rotation
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    small = theta < SLERP_SMALL_ANGLE_RAD
    sin_theta = np.where(small, 1.0, np.sin(theta))
    w0 = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / sin_theta)
    w1 = np.where(small, u, np.sin(u * theta) / sin_theta)
    q = w0[:, None] * q0 + w1[:, None] * q1
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[~inside] = np.nan
    return q, inside
