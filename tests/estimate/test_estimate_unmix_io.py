"""The Python side of ``speclight unmix`` and ``upsample`` (``speclight.estimate``).

References as in ``tests/cli``: the synthetic mixture and its band signatures are computed
independently of speclight in ``tests/cli/synthetic_mixture.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "cli"))
from synthetic_mixture import (
    SOURCE,
    WL,
    gaussian_responses,
    mixture_dataset,
    random_mixture,
    signatures,
    write_spectra,
)

from speclight.errors import InputError
from speclight.estimate import (
    BandResponses,
    endmembers_from_files,
    read_reflectance_factors,
    unmix_measured,
)

NAMES = ["gold", "cell", "paint"]


def test_unmix_measured_returns_abund_dataset(tmp_path: Path) -> None:
    a = random_mixture(25, 3, seed=11, sum_to_one=True)
    path = tmp_path / "m.nc"
    mixture_dataset(a, NAMES).to_netcdf(path, engine="h5netcdf")
    files = write_spectra(tmp_path)
    ds = unmix_measured(path, endmembers=[str(files[n]) for n in NAMES], method="fcls")
    lit = np.all(np.isfinite(a), axis=1)
    np.testing.assert_allclose(ds["abundance"].values[lit], a[lit], atol=1e-9)
    factors = read_reflectance_factors(path)
    assert factors.material_names == NAMES
    np.testing.assert_allclose(factors.factor[lit], (a @ signatures(NAMES))[lit], rtol=1e-12)


def test_endmember_files_signatures_and_duplicate_names(tmp_path: Path) -> None:
    files = write_spectra(tmp_path)
    bands = BandResponses(["a"] * 6, WL, gaussian_responses() * 0.8 * 0.9)
    # weighted by the source at the aperture (SPEC section 5, eq. 5), here one for 3 epochs
    members = endmembers_from_files([files["gold"], files["paint"]], bands, np.tile(SOURCE, (3, 1)))
    np.testing.assert_allclose(members.signatures, signatures(["gold", "paint"]), rtol=1e-12)
    other = tmp_path / "sub"
    other.mkdir()
    (other / "gold.csv").write_text(files["gold"].read_text())
    np.testing.assert_allclose(members.signatures_epoch[1], members.signatures, rtol=1e-12)
    with pytest.raises(InputError, match="gold given twice"):
        endmembers_from_files([files["gold"], other / "gold.csv"], bands)


def test_options_are_checked_before_reading(tmp_path: Path) -> None:
    missing = tmp_path / "missing.nc"  # never read: the options fail first
    with pytest.raises(InputError, match="one of them"):
        unmix_measured(missing)
    with pytest.raises(InputError, match="unknown extraction 'atgq'; did you mean 'atgp'"):
        unmix_measured(missing, extract="atgq", n=2)
    with pytest.raises(InputError, match="use it with `extract`"):
        unmix_measured(missing, endmembers=["x.csv"], n=2)
