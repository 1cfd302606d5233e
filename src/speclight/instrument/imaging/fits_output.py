"""Frames on disk: one FITS file per frame, the truth beside them (docs/frames.md).

``DIR/frame_NNNN_BAND.fits``: the image in ADU (16-bit unsigned when the ADC fits,
else 32-bit; 32-bit floats for noiseless frames), its WCS (astropy; ICRS, TAN, CD matrix)
and the exposure's keywords (``DATE-OBS``, ``DATE-AVG``, ``EXPTIME``, ``FILTER``, ``GAIN``,
``RDNOISE``, ``SATURATE``; the site as ``SITELAT``, ``SITELONG``, ``SITEELEV``, not
``OBSGEO-*``, which astropy's WCS re-derives on every read with a warning).
``DIR/truth.json``: per frame the target's centroid, electrons and streak ends and the stars
on it, in 0-based pixel coordinates (numpy's and astropy's: the first pixel's centre is
(0, 0); FITS's is (1, 1)). ``DIR/frames.csv``: one row per frame. Every file is written to a
hidden folder and moved into place when all are written.
"""

from __future__ import annotations

import csv
import io
import json
import os
import shutil
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from speclight.attitude.quaternion import radec_from_unit_vector
from speclight.errors import InputError
from speclight.instrument.imaging.frame_set import Frame
from speclight.instrument.imaging.sky_projection import frame_wcs
from speclight.scenario.sections_imaging import Imaging

#: Name of the truth file.
TRUTH_FILE = "truth.json"
#: Hidden folder the files are written into before they are moved into place.
PARTIAL = ".frames-partial"
#: Name of the one-row-per-frame table.
TABLE_FILE = "frames.csv"
#: Columns of the table.
TABLE_COLUMNS = (
    "file",
    "band",
    "start_utc",
    "exposure_s",
    "ra_deg",
    "dec_deg",
    "target_x",
    "target_y",
    "target_electrons",
    "start_x",
    "start_y",
    "end_x",
    "end_y",
    "stars",
    "sky_v_mag_arcsec2",
    "resolved",
    "saturated_pixels",
)


def claim_folder(folder: str | Path, force: bool) -> Path:
    """Make ``folder`` (or accept an empty one); with ``force`` remove the files an earlier
    run listed in its truth file. Anything else in a non-empty folder is refused."""
    path = Path(folder)
    if path.exists() and not path.is_dir():
        raise InputError(f"{path} exists and is not a folder", field="--output")
    if path.is_dir() and any(p.name != PARTIAL for p in path.iterdir()):
        if not force:
            raise InputError(
                f"the folder {path} is not empty: give an empty or new folder, or --force to "
                "replace an earlier run's frames",
                field="--output",
            )
        _remove_earlier(path)
    path.mkdir(parents=True, exist_ok=True)
    return path


def _remove_earlier(path: Path) -> None:
    truth = path / TRUTH_FILE
    if not truth.is_file():
        return
    try:
        names = [f["file"] for f in json.loads(truth.read_text())["frames"]]
    except (ValueError, KeyError, TypeError):
        return
    for name in [*names, TRUTH_FILE, TABLE_FILE]:
        target = path / Path(str(name)).name  # a name only, never a path out of the folder
        if target.is_file():
            target.unlink()


def _atomic_write(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _time(t: np.datetime64) -> str:
    return str(np.datetime_as_string(np.asarray(t, dtype="datetime64[ms]"), unit="ms"))


def fits_bytes(
    frame: Frame, imaging: Imaging, site: tuple[float, float, float], name: str
) -> bytes:
    """The frame as a FITS file."""
    from astropy.io import fits
    from astropy.time import Time

    exp = frame.exposure
    header = frame_wcs(exp.pointing).to_header()  # type: ignore[attr-defined]
    det = imaging.detector
    end = frame.start_utc + np.timedelta64(round(frame.exposure_s * 1e9), "ns")
    cards: list[tuple[str, Any, str]] = [
        ("OBJECT", name, "scenario name"),
        ("ORIGIN", "speclight", "simulated frame"),
        ("DATE-OBS", _time(frame.start_utc), "start of the exposure (UTC)"),
        ("DATE-AVG", _time(frame.mid_utc), "middle of the exposure (UTC)"),
        ("DATE-END", _time(end), "end of the exposure (UTC)"),
        ("MJD-OBS", float(Time(_time(frame.start_utc), scale="utc").mjd), "start (MJD, UTC)"),
        ("TIMESYS", "UTC", ""),
        ("EXPTIME", frame.exposure_s, "exposure time [s]"),
        ("FILTER", frame.band, "band"),
        ("BUNIT", "adu", ""),
        ("GAIN", det.gain_e_per_adu, "[e-/ADU]"),
        ("RDNOISE", det.read_noise_e, "read noise [e- rms]"),
        ("DARKCUR", det.dark_current_e_per_s, "dark current [e-/s/px]"),
        ("BIASLVL", det.bias_adu, "bias [ADU]"),
        ("FULLWELL", det.full_well_e, "[e-]"),
        ("SATURATE", det.saturation_adu, "largest ADC value [ADU]"),
        ("PIXSCALE", det.scale_arcsec, "[arcsec/px]"),
        ("TRACKING", imaging.tracking, "sidereal: stars fixed; target: target fixed"),
        ("NOISE", imaging.noise, "F: the mean frame (no noise, not rounded)"),
        ("PSFFWHM", frame.meta["psf_fwhm_arcsec"], "PSF FWHM estimate [arcsec]"),
        ("SKYMAG", frame.meta["sky_v_mag_arcsec2"] or 0.0, "sky V [mag/arcsec2] (0: none)"),
        ("SITELAT", site[0], "site geodetic latitude [deg]"),
        ("SITELONG", site[1], "site longitude, east [deg]"),
        ("SITEELEV", site[2], "site height above WGS84 [m]"),
        ("TRUTH", TRUTH_FILE, "target and stars of this frame"),
    ]
    for key, value, comment in cards:
        header[key] = (value, comment)
    data = exp.adu
    if imaging.noise:
        data = data.astype(np.uint16 if det.saturation_adu <= 65_535 else np.int32)
    else:
        data = data.astype(np.float32)
    buffer = io.BytesIO()
    fits.PrimaryHDU(data=data, header=header).writeto(buffer)
    return buffer.getvalue()


def frame_record(frame: Frame, file: str) -> dict[str, Any]:
    """The truth of a frame (JSON-ready)."""
    exp = frame.exposure
    ra, dec = radec_from_unit_vector(exp.pointing.centre)
    return {
        "file": file,
        "index": frame.index,
        "band": frame.band,
        "start_utc": _time(frame.start_utc),
        "mid_utc": _time(frame.mid_utc),
        "exposure_s": frame.exposure_s,
        "ra_deg": float(ra),  # the target at mid-exposure: the frame's reference pixel
        "dec_deg": float(dec),
        **exp.truth,
        **frame.meta,
    }


def write_frames(
    frames: Iterable[Frame],
    folder: Path,
    imaging: Imaging,
    site: tuple[float, float, float],
    name: str,
) -> list[dict[str, Any]]:
    """Write every frame, then the truth and the table; returns the truth records.

    The files are written into a hidden folder inside ``folder`` and moved out together at
    the end, so that a run that fails or is interrupted leaves no partial set of frames.
    """
    partial = folder / PARTIAL
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir()
    try:
        records = []
        for frame in frames:
            file = f"frame_{frame.index:04d}_{_safe(frame.band)}.fits"
            _atomic_write(partial / file, fits_bytes(frame, imaging, site, name))
            records.append(frame_record(frame, file))
        truth = {
            "pixel_convention": "0-based: the first pixel's centre is (0, 0) (FITS: (1, 1))",
            "units": {"electrons": "e-", "x, y": "px", "ra, dec": "deg (ICRS, astrometric)"},
            "frames": records,
        }
        _atomic_write(partial / TRUTH_FILE, json.dumps(truth, indent=1, default=_json).encode())
        _atomic_write(partial / TABLE_FILE, _table(records).encode())
        for r in records:
            os.replace(partial / r["file"], folder / r["file"])
        for file in (TABLE_FILE, TRUTH_FILE):  # the truth last: it marks a complete set
            os.replace(partial / file, folder / file)
    finally:
        shutil.rmtree(partial, ignore_errors=True)
    return records


def _safe(band: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in band)


def _json(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(type(value).__name__)


def _table(records: list[dict[str, Any]]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(TABLE_COLUMNS)
    for r in records:
        t = r["target"]
        writer.writerow(
            [
                r["file"],
                r["band"],
                r["start_utc"],
                r["exposure_s"],
                r["ra_deg"],
                r["dec_deg"],
                t["x"],
                t["y"],
                t["electrons"],
                t["start_x"],
                t["start_y"],
                t["end_x"],
                t["end_y"],
                " ".join(str(s["hip"]) for s in r["stars"]),
                r["sky_v_mag_arcsec2"],
                r["resolved"],
                r["saturated_pixels"],
            ]
        )
    return out.getvalue()
