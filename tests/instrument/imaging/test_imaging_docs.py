"""docs/frames.md's example section is a valid ``instrument.imaging``, and the scenario
model rejects what the page says it rejects."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

from speclight.scenario.sections_imaging import Imaging

DOC = Path(__file__).parents[3] / "docs" / "frames.md"


def test_the_documented_section_validates() -> None:
    block = re.search(r"```yaml\n(.*?)```", DOC.read_text(), re.S)
    assert block is not None
    imaging = Imaging.model_validate(yaml.safe_load(block.group(1))["instrument"]["imaging"])
    assert imaging.detector.scale_arcsec == 2.0 and imaging.tracking == "sidereal"


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"detector": {}}, "plate scale is missing"),
        ({"detector": {"plate_scale_arcsec": 1, "pixel_size_um": 9}}, "not both"),
        ({"detector": {"plate_scale_arcsec": 1, "bias_adu": 70000}}, "below saturation_adu"),
        ({"detector": {"plate_scale_arcsec": 1}, "exposure_s": 2, "cadence_s": 1}, "cadence_s"),
        (
            {
                "detector": {"plate_scale_arcsec": 1},
                "psf": {"diffraction": False, "defocus_waves": 1},
            },
            "needs diffraction",
        ),
        ({"detector": {"plate_scale_arcsec": 1}, "sky": {"model": "fixed"}}, "v_mag_arcsec2"),
    ],
)
def test_bad_sections_are_refused_with_the_reason(section, message) -> None:
    with pytest.raises(ValidationError, match=message):
        Imaging.model_validate(section)


def test_plate_scale_from_pixel_and_focal_length() -> None:
    d = Imaging.model_validate(
        {"detector": {"pixel_size_um": 9.0, "focal_length_m": 0.93}}
    ).detector
    import astropy.units as u

    assert d.scale_arcsec == pytest.approx((9e-6 / 0.93 * u.rad).to_value(u.arcsec), rel=1e-12)


def test_a_missing_galsim_says_what_to_install(monkeypatch) -> None:
    from speclight import engine_packages
    from speclight.errors import InputError
    from speclight.instrument.imaging.psf import PsfSpec, psf_kernel

    monkeypatch.setattr(engine_packages, "missing_modules", lambda engine: ["galsim"])
    with pytest.raises(InputError, match=r"pip install 'speclight\[frames\]'"):
        psf_kernel(PsfSpec(), 550.0, 0.5)
