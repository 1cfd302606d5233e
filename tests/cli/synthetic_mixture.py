"""A synthetic speclight dataset of known mixtures, and the endmember spectra it is made of.

Everything is computed here from closed forms, independently of speclight: Gaussian bands
bin-averaged with the normal CDF over bins half-way between grid points (a uniform grid,
so every bin is STEP_NM wide), optics and QE constants, and the photon-weighted band
average of eq. 3 of the reference paper (Nussbaum et al. 2022): the weight of a wavelength
is R_j(lambda) lambda d(lambda) (h c cancels in the ratio), times the source spectrum at the
aperture E T: the band reflectance factor of eq. 5 divides by the band-weighted source photon
flux, so a material of reflectance rho enters it as sum rho E T R_j l / sum E T R_j l (SPEC
section 5). The dataset's Sun and transmission are smooth non-flat closed forms, so that
signatures without the source weighting would not fit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from scipy.special import ndtr

STEP_NM = 5.0
WL = np.arange(350.0, 1050.0 + STEP_NM / 2, STEP_NM)
CENTRES_NM = [430.0, 520.0, 600.0, 680.0, 780.0, 900.0]
SIGMA_NM = 25.0
OPTICS = 0.8
QE = 0.9
#: Solar irradiance [W m-2 nm-1] and transmission of the synthetic dataset (closed forms).
SOLAR = 1.9 * np.exp(-(((WL - 480.0) / 380.0) ** 2))
TRANSMISSION = 0.35 + 0.6 * (WL - WL[0]) / (WL[-1] - WL[0])
SOURCE = SOLAR * TRANSMISSION

# endmember spectra: (wavelength_nm, reflectance) nodes, linearly interpolated
SPECTRA = {
    "paint": ([300.0, 1300.0], [0.80, 0.80]),
    "gold": ([300.0, 450.0, 550.0, 650.0, 1300.0], [0.30, 0.35, 0.70, 0.92, 0.97]),
    "cell": ([300.0, 450.0, 600.0, 800.0, 1300.0], [0.18, 0.08, 0.05, 0.10, 0.35]),
}


def gaussian_responses() -> np.ndarray:
    """(B, L) bin-averaged Gaussian responses of peak 1."""
    edges = np.concatenate([[WL[0] - STEP_NM / 2], WL + STEP_NM / 2])
    rows = []
    for c in CENTRES_NM:
        cdf = ndtr((edges - c) / SIGMA_NM)
        rows.append(np.diff(cdf) * SIGMA_NM * np.sqrt(2 * np.pi) / STEP_NM)
    return np.array(rows)


def band_average(
    spectrum: np.ndarray,
    response: np.ndarray,
    wl: np.ndarray = WL,
    source: np.ndarray | float = 1.0,
) -> np.ndarray:
    """Photon-weighted band averages on a uniform grid, ``sum g E R l / sum E R l``: with a
    flat source those of eq. 3 (upsampling), with the source at the aperture those of the
    band reflectance factor (unmixing)."""
    w = response * source * wl
    return np.asarray((w @ spectrum) / w.sum(axis=1))


def spectrum(name: str, wl: np.ndarray = WL) -> np.ndarray:
    x, y = SPECTRA[name]
    return np.interp(wl, x, y)


def signatures(names: list[str]) -> np.ndarray:
    """(K, B) band signatures of the named spectra through the bands x optics x QE,
    weighted by the dataset's source at the aperture."""
    response = gaussian_responses() * OPTICS * QE
    return np.array([band_average(spectrum(n), response, source=SOURCE) for n in names])


def write_spectra(folder: Path) -> dict[str, Path]:
    """One CSV ``wavelength_nm,reflectance`` per endmember; name = file stem."""
    out = {}
    for name, (x, y) in SPECTRA.items():
        path = folder / f"{name}.csv"
        lines = ["wavelength_nm,reflectance"] + [f"{a},{b}" for a, b in zip(x, y, strict=True)]
        path.write_text("\n".join(lines) + "\n")
        out[name] = path
    return out


def mixture_dataset(abundance: np.ndarray, names: list[str]) -> xr.Dataset:
    """A dataset shaped like ``speclight simulate``'s whose reflectance factors are
    ``abundance @ signatures`` [m2 sr-1], with the per-material ground truth."""
    n = abundance.shape[0]
    s = signatures(names)
    truth = abundance[:, :, None] * s[None, :, :]
    factor = truth.sum(axis=1)
    time = np.datetime64("2020-02-29T21:16:00", "ns") + np.arange(n) * np.timedelta64(1, "s")
    bands = [f"G-{c:g}/{SIGMA_NM:g}" for c in CENTRES_NM]
    ds = xr.Dataset(coords={"time": time, "wavelength": WL, "band": bands, "material": names})
    ds["wavelength"].attrs["units"] = "nm"
    ds["band_response"] = (("band", "wavelength"), gaussian_responses(), {"units": "1"})
    ds["optics_transmission"] = (("wavelength",), np.full(WL.size, OPTICS), {"units": "1"})
    ds["detector_qe"] = (("band", "wavelength"), np.full((len(bands), WL.size), QE), {"units": "1"})
    ds["solar_irradiance"] = (
        ("time", "wavelength"),
        np.tile(SOLAR, (n, 1)),
        {"units": "W m-2 nm-1"},
    )
    ds["transmission"] = (("time", "wavelength"), np.tile(TRANSMISSION, (n, 1)), {"units": "1"})
    ds["sunlit"] = (("time",), np.ones(n), {"units": "1"})
    ds["reflectance_factor"] = (("time", "band"), factor, {"units": "m2 sr-1"})
    ds["count_rate"] = (("time", "band"), np.nan_to_num(factor) * 1e4, {"units": "s-1"})
    ds["reflectance_factor_material"] = (
        ("time", "material", "band"),
        truth,
        {"units": "m2 sr-1"},
    )
    return ds


def random_mixture(n: int, k: int, seed: int, sum_to_one: bool) -> np.ndarray:
    """(n, k) contributions: the first k epochs pure, two later epochs NaN (unlit)."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.02, 0.5, size=(n, k))
    if sum_to_one:
        a /= a.sum(axis=1, keepdims=True)
    a[:k] = np.eye(k) * (1.0 if sum_to_one else 0.4)
    a[[k + 3, k + 7]] = np.nan
    return a
