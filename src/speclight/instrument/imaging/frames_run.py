"""``speclight frames``: a simulate dataset and an imaging section in, a folder of frames out.

Why a command of its own and not part of ``simulate``: the frames are many files (FITS
and their truth) where ``simulate`` writes one dataset, and they are made from what the
dataset already holds (the light curve, the track on the sky, the kept renders), so that a
new detector, PSF or cadence costs seconds, not a new render. The imaging section is read
from the scenario the dataset carries (``instrument.imaging``) or from a file of its own.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import ValidationError

from speclight.errors import InputError
from speclight.input_files import read_user_text
from speclight.scenario.sections_imaging import Imaging

#: Largest imaging file [bytes].
MAX_IMAGING_BYTES = 1_000_000


@dataclass
class FramesResult:
    """What a run wrote.

    Attributes
    ----------
    folder
        The output folder.
    records
        The truth of every frame (as in ``truth.json``).
    frames
        The frames themselves (for the figure), the first few only.
    notes
        Lines for the user.
    """

    folder: Path
    records: list[dict[str, Any]]
    frames: list[Any] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def read_imaging(path: str | Path) -> Imaging:
    """An imaging section from a YAML file (the mapping under ``instrument.imaging``)."""
    text = read_user_text(Path(path), what="imaging file", max_bytes=MAX_IMAGING_BYTES)
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise InputError(f"not valid YAML ({exc})", source=str(path)) from None
    if isinstance(data, dict) and set(data) == {"imaging"}:
        data = data["imaging"]
    return imaging_from(data, str(path))


def imaging_from(data: Any, source: str) -> Imaging:
    """Validate an imaging mapping, with the field and what is accepted in the error."""
    if not isinstance(data, dict):
        raise InputError("an imaging section is a mapping (detector, psf, ...)", source=source)
    try:
        return Imaging.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(p) for p in ("instrument", "imaging", *first["loc"]))
        raise InputError(
            f"{first['msg']} (got {first.get('input')!r})", source=source, field=where
        ) from None


def _daylight_frames(inputs: Any, records: list[dict[str, Any]]) -> int:
    """How many frames have the Sun above the twilight model's top at mid-exposure."""
    from speclight.instrument.imaging.sky_brightness import TWILIGHT_TOP_DEG
    from speclight.instrument.imaging.target_path import values_at

    track = inputs.track
    if track.sun_elevation_deg is None or not records:
        return 0
    mids = np.array([r["mid_utc"] for r in records], dtype="datetime64[ns]")
    return int(np.sum(values_at(track, track.sun_elevation_deg, mids) > TWILIGHT_TOP_DEG))


def make_frame_files(
    dataset: str | Path,
    folder: str | Path,
    *,
    imaging_file: str | Path | None = None,
    force: bool = False,
    keep: int = 4,
) -> FramesResult:
    """Write the frames of a dataset into ``folder`` (see docs/frames.md).

    Parameters
    ----------
    dataset
        A NetCDF dataset of ``speclight simulate``.
    folder
        Output folder (new or empty; with ``force`` an earlier run's files are replaced).
    imaging_file
        A YAML imaging section to use instead of the scenario's ``instrument.imaging``.
    force
        Replace an earlier run's frames.
    keep
        How many frames to keep in memory for the figure.
    """
    from speclight.instrument.imaging.fits_output import claim_folder, write_frames
    from speclight.instrument.imaging.frame_inputs import frame_inputs, load_dataset
    from speclight.instrument.imaging.frame_set import make_frames, plan_starts

    source = str(dataset)
    ds = load_dataset(dataset)
    inputs = frame_inputs(ds, source)
    from speclight.scenario import parse_scenario

    scenario = parse_scenario(inputs.scenario_yaml, source=f"{source} (scenario_yaml)").scenario
    if imaging_file is not None:
        imaging = read_imaging(imaging_file)
    elif scenario.instrument.imaging is not None:
        imaging = scenario.instrument.imaging
    else:
        raise InputError(
            "the dataset's scenario has no instrument.imaging: add one to the scenario "
            "(docs/frames.md) or give --imaging IMAGING.yaml",
            source=source,
            field="instrument.imaging",
        )
    exposure_s = imaging.exposure_s or scenario.instrument.exposure_s
    existed = Path(folder).exists()
    out = claim_folder(folder, force)
    kept: list[Any] = []

    def frames() -> Any:
        for frame in make_frames(inputs, imaging, exposure_s):
            if len(kept) < keep:
                kept.append(frame)
            yield frame

    try:
        records = write_frames(frames(), out, imaging, inputs.site, scenario.name)
    except BaseException:
        if not existed and not any(out.iterdir()):
            out.rmdir()  # a folder this run made, left as it was: absent
        raise
    _, skipped = plan_starts(inputs, imaging, exposure_s)
    notes = []
    if skipped:
        notes.append(f"{skipped} exposures skipped: the target below the horizon or no geometry")
    if not records:
        notes.append("no frame written: no exposure fits where the target is above the horizon")
    day = _daylight_frames(inputs, records)
    if day:
        notes.append(
            f"{day} frames with the Sun above -0.9 deg: the sky model is held at its twilight "
            "value there (a daylight sky is not modelled; docs/frames.md, Sky)"
        )
    return FramesResult(out, records, kept, notes)
