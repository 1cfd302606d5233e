"""ILRS Consolidated laser ranging Prediction Format (CPF) files, versions 1 and 2.

Format: Ricklefs et al., *Consolidated Laser Ranging Prediction Format*, Version 1.01
(ILRS, 2006) and Version 2.00 (ILRS, 2018), https://ilrs.gsfc.nasa.gov/data_and_products/
formats/cpf.html. Header records H1 (format version, source, target name; v2 adds the
sub-daily sequence number and a notes field), H2 (COSPAR/SIC/NORAD ids, span, step,
reference frame; v2 adds target location/dynamics), H3-H5 (accuracy, transponder,
centre-of-mass offset), H9 (end of header); data records 10 (position), 20 (velocity),
30-70 (corrections, rotation angles...), 00 (comment), 99 (end), read line by line in
:mod:`speclight.orbit.cpf_records`.

Supported: Earth-orbiting targets in reference frame 0 (geocentric true body-fixed, i.e.
ITRF), common-epoch records (direction flag 0). Transmit/receive records (flags 1 and 2,
used for lunar and deep-space targets) are skipped. The leap-second flag of record 10 is
not applied: times are taken as UTC at face value (a file spanning a leap second would be
off by 1 s after it).

Interpolation: 10-point (degree 9) Lagrange in ITRF, as the format's authors recommend; see
:mod:`speclight.orbit.interpolate`. Then ITRF -> GCRS at each epoch.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_text
from speclight.orbit.cpf_records import Records, h2_span, read_records
from speclight.orbit.frames import EarthOrientation, TimeLike, as_time, earth_orientation
from speclight.orbit.interpolate import lagrange_interpolate
from speclight.orbit.timescale import time_from_utc

#: Geocentric distances [m] a position of an Earth-orbiting target can have: from below the
#: Earth's polar radius (6,357 km) to beyond the Sun-Earth L1/L2 points (1.5 million km).
#: A table position outside them is a corrupted record (or a unit mistake).
PLAUSIBLE_RADIUS_M = (6.0e6, 2.0e9)


@dataclass(frozen=True)
class Cpf:
    """Contents of a CPF file needed to compute positions.

    Attributes
    ----------
    path
        File read.
    version
        Format version, 1 or 2.
    source
        Ephemeris source (3-letter code of the prediction centre).
    target_name
        ILRS target name.
    cospar_id, sic, norad_id
        Identifiers as written in H2.
    start_utc, end_utc
        Span announced in H2, ``datetime64[ns]`` UTC.
    step_s
        Time between table entries [s] (H2).
    reference_frame
        0 (only value accepted).
    com_offset_m
        Centre-of-mass to reflector offset [m] from H5, or None.
    times_utc
        (M,) epochs of the position records, ``datetime64[ns]`` UTC.
    r_itrf_m
        (M, 3) positions [m].
    v_itrf_m_s
        (M, 3) velocities [m/s] from records 20, or None when the file has none.
    unusable_lines
        Line numbers of position records left out of the table: a position that is not a
        finite number or whose geocentric distance is outside :data:`PLAUSIBLE_RADIUS_M`.
        Epochs around them fall in a gap and are not valid (see
        :func:`cpf_position_gcrs_m`).
    """

    path: str
    version: int
    source: str
    target_name: str
    cospar_id: str
    sic: str
    norad_id: str
    start_utc: np.datetime64
    end_utc: np.datetime64
    step_s: int
    reference_frame: int
    com_offset_m: float | None
    times_utc: NDArray[np.datetime64]
    r_itrf_m: NDArray[np.float64]
    v_itrf_m_s: NDArray[np.float64] | None
    unusable_lines: tuple[int, ...] = ()


def read_cpf(path: str | Path) -> Cpf:
    """Read an ILRS CPF prediction file (format version 1 or 2).

    Parameters
    ----------
    path
        The CPF file.

    Returns
    -------
    Cpf

    Raises
    ------
    InputError
        Not a CPF file, unsupported version or reference frame, or a malformed record
        (the message names the file, the line number and the record).
    """
    p = str(path)
    lines = read_user_text(path, "orbit.cpf_file", what="CPF file").split("\n")
    rec = read_records(p, lines)
    r_arr = np.array(rec.pos, dtype=np.float64).reshape(-1, 3)
    usable = plausible_position(r_arr)
    if np.count_nonzero(usable) < 2:
        raise InputError(_too_few_records(r_arr, usable, rec.pos_lines), source=p)
    h1, h2 = rec.head["H1"], rec.head["H2"]
    start, end, step_s, frame = h2_span(p, lines, h2)
    t_arr = _increasing_times(p, rec.times)
    return Cpf(
        path=p,
        version=rec.version,
        source=h1[3],
        target_name=h1[9] if rec.version == 1 else h1[10],
        cospar_id=h2[1],
        sic=h2[2],
        norad_id=h2[3],
        start_utc=start,
        end_utc=end,
        step_s=step_s,
        reference_frame=frame,
        com_offset_m=rec.com,
        times_utc=t_arr[usable],
        r_itrf_m=r_arr[usable],
        v_itrf_m_s=_velocities(rec, usable),
        unusable_lines=tuple(ln for ln, ok in zip(rec.pos_lines, usable, strict=True) if not ok),
    )


def _increasing_times(p: str, times: list[np.datetime64]) -> NDArray[np.datetime64]:
    """The position records' epochs, checked to increase strictly."""
    t_arr = np.array(times, dtype="datetime64[ns]")
    if np.any(np.diff(t_arr) <= np.timedelta64(0, "ns")):
        bad = int(np.argmax(np.diff(t_arr) <= np.timedelta64(0, "ns"))) + 1
        raise InputError(
            f"position record {bad + 1} ({t_arr[bad]}) is not after the previous one; "
            "records must be in strictly increasing time order",
            source=p,
        )
    return t_arr


def _velocities(rec: Records, usable: NDArray[np.bool_]) -> NDArray[np.float64] | None:
    """The usable positions' velocities (records 20), when every position has one."""
    if rec.vel and len(rec.vel) == len(rec.times) and rec.vel_times == rec.times:
        return np.array(rec.vel, dtype=np.float64)[usable]
    return None


def plausible_position(r_m: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Rows of ``r_m`` (M, 3) [m] that are finite and :data:`PLAUSIBLE_RADIUS_M` from the
    geocentre: positions an Earth-orbiting target can have."""
    with np.errstate(over="ignore", invalid="ignore"):
        radius_m = np.linalg.norm(r_m, axis=1)
    return (
        np.isfinite(radius_m)
        & (radius_m >= PLAUSIBLE_RADIUS_M[0])
        & (radius_m <= PLAUSIBLE_RADIUS_M[1])
    )


def _too_few_records(r_m: NDArray[np.float64], usable: NDArray[np.bool_], lines: list[int]) -> str:
    msg = (
        f"{len(lines)} position records (type 10, direction 0), {np.count_nonzero(usable)} "
        "of them usable; need >= 2"
    )
    if usable.all():
        return msg
    i = int(np.flatnonzero(~usable)[0])
    lo_km, hi_km = (v / 1e3 for v in PLAUSIBLE_RADIUS_M)
    return (
        f"{msg}. Line {lines[i]}: position {r_m[i].tolist()} m is not a finite point "
        f"{lo_km:,.0f} to {hi_km:,.0f} km from the geocentre"
    )


def interpolate_table_m(
    times_utc: NDArray[np.datetime64],
    r_m: NDArray[np.float64],
    t: TimeLike,
    max_gap_s: float | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Interpolate a table of positions (UTC epochs) at the epochs ``t``, same frame.

    Time differences are taken in TAI from split Julian dates, so they are exact to
    ~1e-11 s and correct across leap seconds. Returns (N, 3) positions and the ok mask
    (False, NaN row, outside the table's span, where the result is not finite, or, if
    ``max_gap_s`` is given, inside a gap between two records longer than ``max_gap_s`` [s]).
    """
    t = as_time(t)
    tn = time_from_utc(np.asarray(times_utc, dtype="datetime64[ns]"))
    w0 = float(np.min(tn.whole))
    x_nodes = ((np.asarray(tn.whole) - w0) + np.asarray(tn.tai_fraction)) * 86400.0
    x = ((np.asarray(t.whole, dtype=np.float64) - w0) + np.asarray(t.tai_fraction)) * 86400.0
    x = np.atleast_1d(x)
    r, ok = lagrange_interpolate(x_nodes, r_m, x)
    if max_gap_s is not None and x_nodes.size > 1:
        i = np.clip(np.searchsorted(x_nodes, x, side="right") - 1, 0, x_nodes.size - 2)
        inside = (x > x_nodes[i]) & (x < x_nodes[i + 1])  # a record's own epoch is known
        in_gap = inside & ((x_nodes[i + 1] - x_nodes[i]) > max_gap_s)
        ok &= ~in_gap
    ok &= np.all(np.isfinite(r), axis=1)  # a non-finite table value never passes as valid
    r[~ok] = np.nan
    return r, ok


def cpf_position_gcrs_m(
    cpf: Cpf, t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Target position in the GCRS from a CPF prediction.

    Parameters
    ----------
    cpf
        From :func:`read_cpf`.
    t
        Epochs (N), skyfield ``Time`` or UTC ``datetime64``.
    orientation
        Precomputed Earth orientation for ``t``.

    Returns
    -------
    r_gcrs_m : ndarray
        (N, 3) [m]; NaN rows outside the file's span and inside gaps longer than 1.5
        times the step announced in H2, including the gap that a left-out record
        (:attr:`Cpf.unusable_lines`) leaves.
    ok : ndarray of bool
        (N,) True where valid.
    """
    # A hole in the table (e.g. records removed around a manoeuvre) is not bridged.
    max_gap = 1.5 * cpf.step_s if cpf.step_s > 0 else None
    r_itrf, ok = interpolate_table_m(cpf.times_utc, cpf.r_itrf_m, t, max_gap_s=max_gap)
    eo = orientation if orientation is not None else earth_orientation(t)
    return eo.itrs_to_gcrs(r_itrf), ok
