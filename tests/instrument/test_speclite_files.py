"""speclite's filter files read without speclite.filters, against speclite itself (the oracle)."""

import numpy as np
import pytest

from speclight.instrument.speclite_files import read_speclite_filter, speclite_filter_folder

filters = pytest.importorskip("speclite.filters")

#: nm and micron files go through Angstrom in speclite (x 10 then / 10): two float64 roundings.
RTOL = 4 * np.finfo(np.float64).eps


def test_every_shipped_filter_matches_speclite() -> None:
    folder = speclite_filter_folder()
    assert folder is not None
    paths = sorted(folder.glob("*.ecsv"))
    assert len(paths) > 50  # speclite ships ~100 filters
    for path in paths:
        reference = filters.load_filter(path.stem)
        wavelength_nm, response = read_speclite_filter(path)
        np.testing.assert_allclose(
            wavelength_nm, np.asarray(reference.wavelength, float) / 10.0, rtol=RTOL, atol=0
        )
        np.testing.assert_allclose(response, np.asarray(reference.response, float), rtol=RTOL)


def test_a_file_without_known_unit_is_refused(tmp_path) -> None:
    path = tmp_path / "x-y.ecsv"
    path.write_text(
        "# %ECSV 0.9\n# ---\n# datatype:\n"
        "# - {name: wavelength, unit: furlong, datatype: float64}\n"
        "# - {name: response, datatype: float64}\nwavelength response\n1 0\n2 1\n3 0\n"
    )
    with pytest.raises(ValueError, match="furlong"):
        read_speclite_filter(path)
