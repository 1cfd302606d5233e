"""docs/brdf-models.md reports the fits of the shipped tables: its numbers are the fits'.

Not a reference test (the fits are speclight's own): it keeps the page true to the code,
to the page's printed precision (3 decimals in dex, 2 in albedo; half a unit of the last
digit, plus as much again for the optimiser's platform-to-platform differences).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from speclight.target.brdf_fit.log_fit import fit_table_samples
from speclight.target.brdf_samples import read_table_samples

PAGE = Path(__file__).parents[2] / "docs" / "brdf-models.md"
TABLES = {
    "chassis": "starlink_v1p5_chassis_532nm",
    "solar array": "starlink_v1p5_solar_array_532nm",
}


def _rows() -> list[list[str]]:
    text = PAGE.read_text().split("### Fits of the shipped tables", 1)[1]
    text = text.split("## Measured tables", 1)[0]
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines()
            if line.startswith(("| chassis |", "| solar array |"))]  # fmt: skip
    assert len(rows) == 8
    return rows


@pytest.mark.parametrize("row", _rows(), ids=lambda r: f"{r[0]}-{r[1]}")
def test_docs_numbers_are_the_fits(row):
    samples = read_table_samples(TABLES[row[0]])
    model = re.match(r"`(\w+)`", row[1]).group(1)
    fit = fit_table_samples(samples, model)
    clipped = fit_table_samples(samples, model, min_brdf=1e-3)
    got = [*fit.rms_dex, fit.rms_dex_all, clipped.rms_dex_all]
    np.testing.assert_allclose(got, [float(c) for c in row[2:8]], rtol=0, atol=1e-3)
    assert abs(fit.albedo - float(row[8])) <= 1e-2
    assert not fit.constrained  # the page says no fit needed the constraint
