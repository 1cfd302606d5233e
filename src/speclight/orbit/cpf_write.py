"""Write positions as an ILRS CPF file (v1 or v2 column layout), e.g. to export predictions.

Column layout per Ricklefs et al., *Consolidated Laser Ranging Prediction Format*, v1.01
(2006) and v2.00 (2018): H1, H2, H9, then records 10 (and 20 when velocities are given)
and 99. Reference frame 0 (ITRF), direction flag 0, leap-second flag 0.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

MJD0 = np.datetime64("1858-11-17T00:00:00", "ns")


def _ymdhms(t: np.datetime64) -> tuple[int, int, int, int, int, int]:
    # datetime_as_string: str() follows numpy print options, which other libraries change
    s = str(np.datetime_as_string(np.asarray(t).astype("datetime64[s]"), unit="s"))
    d, hms = s.split("T")
    y, mo, da = (int(v) for v in d.split("-"))
    h, mi, se = (int(v) for v in hms.split(":"))
    return y, mo, da, h, mi, se


def format_cpf(
    times_utc: NDArray[np.datetime64],
    r_itrf_m: NDArray[np.float64],
    *,
    version: int = 2,
    target_name: str,
    cospar_id: str,
    sic: str,
    norad_id: str,
    source: str = "SPL",
    notes: str = "",
    production_utc: np.datetime64 | None = None,
    sequence: int = 1,
    v_itrf_m_s: NDArray[np.float64] | None = None,
) -> str:
    """Return CPF text for ITRF positions [m] at UTC epochs (equally spaced).

    Parameters
    ----------
    times_utc
        (M,) epochs, ``datetime64``, equally spaced by a whole number of seconds.
    r_itrf_m
        (M, 3) positions [m] in ITRF (frame 0).
    version
        1 or 2.
    target_name, cospar_id, sic, norad_id, source, notes
        Header fields (source: 3 letters).
    production_utc
        Production time written in H1 (default: the first epoch).
    sequence
        Ephemeris sequence number (v2: day of year, 0-366).
    v_itrf_m_s
        Optional (M, 3) velocities [m/s], written as records 20.
    """
    t = np.asarray(times_utc, dtype="datetime64[ns]")
    r = np.asarray(r_itrf_m, dtype=np.float64)
    step = round(float((t[1] - t[0]) / np.timedelta64(1, "s"))) if len(t) > 1 else 0
    y, mo, d, h, _, _ = _ymdhms(production_utc if production_utc is not None else t[0])
    if version == 1:
        h1 = f"H1 CPF {1:2d}  {source:3.3s} {y:4d} {mo:02d} {d:02d} {h:02d}  {sequence:4d} "
        h1 += f"{target_name:10.10s} {notes:10.10s}"
    elif version == 2:
        h1 = f"H1 CPF {2:2d}  {source:3.3s} {y:4d} {mo:02d} {d:02d} {h:02d}  {sequence:3d} "
        h1 += f"{1:2d} {target_name:10.10s} {notes:10.10s}"
    else:
        raise ValueError(f"CPF version must be 1 or 2, got {version}")
    s = _ymdhms(t[0])
    e = _ymdhms(t[-1])
    h2 = f"H2 {cospar_id:>8.8s} {sic:>4.4s} {norad_id:>8.8s} "
    h2 += "{:4d} {:2d} {:2d} {:2d} {:2d} {:2d} ".format(*s)
    h2 += "{:4d} {:2d} {:2d} {:2d} {:2d} {:2d} ".format(*e)
    h2 += f"{step:5d} {1:1d} {1:1d} {0:2d} {0:1d} {0:1d}"
    if version == 2:
        h2 += f" {1:2d}"
    out = [h1.rstrip(), h2, "H9"]
    for i in range(len(t)):
        dt_ns = int((t[i] - MJD0) / np.timedelta64(1, "ns"))
        mjd, sod_ns = divmod(dt_ns, 86_400_000_000_000)
        x, yv, z = r[i]
        out.append(f"10 0 {mjd:5d} {sod_ns / 1e9:13.6f} {0:2d} {x:17.3f} {yv:17.3f} {z:17.3f}")
        if v_itrf_m_s is not None:
            vx, vy, vz = v_itrf_m_s[i]
            out.append(f"20 0 {vx:19.6f} {vy:19.6f} {vz:19.6f}")
    out.append("99")
    return "\n".join(out) + "\n"


def write_cpf(path: str | Path, *args: object, **kwargs: object) -> None:
    """Write :func:`format_cpf` output to ``path``."""
    Path(path).write_text(format_cpf(*args, **kwargs))  # type: ignore[arg-type]
