"""Regenerate the shipped material reflectance tables (src/speclight/data/materials/*.csv).

The reference paper's cube experiment (Nussbaum et al. 2022, section 5.2) used DLR lab
spectra of a solar cell, Kapton MLI and aluminium, and a flat "white paint"; we have none of
those measurements, so the four spectra are derived from the shipped optical constants
(``src/speclight/data/optical_constants``) with the formulas below, all at normal incidence.
``data/materials/PROVENANCE.md`` says the same in prose. Run from the repository root::

    python scripts/make_material_spectra.py [OUTPUT_FOLDER]

Formulas (Born & Wolf, *Principles of Optics*, 7th ed., sections 1.5.3 and 1.6.4; H. A.
Macleod, *Thin-Film Optical Filters*, 4th ed., CRC 2010, chapter 2):

* interface a | b at normal incidence: ``r = (N_a - N_b) / (N_a + N_b)``, ``R = |r|^2``; for
  vacuum | n + ik this is ``((n-1)^2 + k^2) / ((n+1)^2 + k^2)``;
* a thick (incoherent) layer with front reflectance ``R1``, back reflectance ``R2`` and
  single-pass transmission ``tau`` sums its multiple reflections in intensity (a geometric
  series): ``R = R1 + (1 - R1)^2 tau^2 R2 / (1 - R1 R2 tau^2)``;
* single-pass transmission through absorbing thickness ``d``: ``tau = exp(-4 pi k d / lambda)``
  (absorption coefficient ``alpha = 4 pi k / lambda``);
* a thin (coherent) film of index ``n1`` and thickness ``d1`` between media 0 and 2:
  ``r = (r01 + r12 e^{2i delta}) / (1 + r01 r12 e^{2i delta})``, ``delta = 2 pi n1 d1 / lambda``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
ROOT = Path(__file__).resolve().parents[1]
NK_DIR = ROOT / "src" / "speclight" / "data" / "optical_constants"
OUT_DIR = ROOT / "src" / "speclight" / "data" / "materials"
#: Output grid [nm]: where every n,k table used is defined (Si: 250-1450 nm).
GRID_NM = np.arange(250.0, 1450.0 + 1e-9, 5.0)
#: Kapton film of aluminised-Kapton MLI outer covers: 25 um (1 mil), aluminium on the back.
KAPTON_THICKNESS_NM = 25_000.0
#: Tabulated Kapton k used to fit its Urbach tail (the k table ends at 430 nm) [nm].
KAPTON_TAIL_FIT_NM = (400.0, 430.0)
#: Solar cell anti-reflection coating: a silicon-nitride-like film of constant index 2.0,
#: a quarter wave thick at 600 nm (75 nm), between the cover glass and the silicon.
AR_INDEX = 2.0
AR_QUARTER_WAVE_NM = 600.0
#: White paint: spectrally flat, as the paper's "uniform distribution".
WHITE_PAINT_REFLECTANCE = 0.8
HC_EV_NM = 1239.84198  # h c [eV nm] (CODATA 2018), photon energy = HC_EV_NM / wavelength


def nk(name: str, wavelength_nm: F64) -> NDArray[np.complex128]:
    """n + ik of a shipped table, linearly interpolated (as speclight.target does)."""
    t = np.loadtxt(NK_DIR / f"{name}.csv", delimiter=",", comments="#", skiprows=2)
    return np.interp(wavelength_nm, t[:, 0], t[:, 1]) + 1j * np.interp(
        wavelength_nm, t[:, 0], t[:, 2]
    )


def interface_r(n_a: NDArray, n_b: NDArray) -> NDArray[np.complex128]:
    """Amplitude reflection coefficient of the a | b interface at normal incidence."""
    return np.asarray((n_a - n_b) / (n_a + n_b), dtype=complex)


def incoherent(r1: F64, r2: F64, tau: F64 | float = 1.0) -> F64:
    """Reflectance of a thick layer: front ``r1``, back ``r2``, single-pass ``tau``."""
    t2 = np.asarray(tau) ** 2
    return np.asarray(r1 + (1.0 - r1) ** 2 * t2 * r2 / (1.0 - r1 * r2 * t2))


def kapton_nk(wavelength_nm: F64) -> NDArray[np.complex128]:
    """Kapton n + ik with an Urbach tail of k beyond the table's absorption data.

    Arakawa et al. list k down to 430 nm and the shipped table sets k = 0 beyond; the
    absorption edge of polyimide continues as an exponential (Urbach) tail in photon energy,
    ``k(E) = k0 exp((E - E0) / E_U)`` (F. Urbach, Phys. Rev. 92, 1324 (1953),
    doi:10.1103/PhysRev.92.1324), fitted to the tabulated k between 400 and 430 nm.
    """
    t = np.loadtxt(NK_DIR / "Kapton.csv", delimiter=",", comments="#", skiprows=2)
    fit = (t[:, 0] >= KAPTON_TAIL_FIT_NM[0]) & (t[:, 0] <= KAPTON_TAIL_FIT_NM[1])
    slope, intercept = np.polyfit(HC_EV_NM / t[fit, 0], np.log(t[fit, 2]), 1)
    base = nk("Kapton", wavelength_nm)
    tail = np.exp(intercept + slope * HC_EV_NM / wavelength_nm)
    k = np.where(wavelength_nm > KAPTON_TAIL_FIT_NM[1], tail, base.imag)
    return base.real + 1j * k


def aluminium(wl: F64) -> F64:
    """Bare aluminium: vacuum | Al (Rakic 1995)."""
    return np.abs(interface_r(np.ones_like(wl), nk("Al", wl))) ** 2


def kapton_mli(wl: F64) -> F64:
    """Aluminised Kapton: vacuum | Kapton film (d = 25 um, incoherent) | Al."""
    n_k = kapton_nk(wl)
    r1 = np.abs(interface_r(np.ones_like(wl), n_k.real)) ** 2
    r2 = np.abs(interface_r(n_k.real, nk("Al", wl))) ** 2
    tau = np.exp(-4.0 * np.pi * n_k.imag * KAPTON_THICKNESS_NM / wl)
    return incoherent(r1, r2, tau)


def solar_cell(wl: F64) -> F64:
    """Silicon cell: vacuum | SiO2 cover glass (thick, lossless) | AR film | Si."""
    n_g = nk("SiO2", wl).real
    r1 = np.abs(interface_r(np.ones_like(wl), n_g)) ** 2
    d1 = AR_QUARTER_WAVE_NM / (4.0 * AR_INDEX)
    phase = np.exp(2j * 2.0 * np.pi * AR_INDEX * d1 / wl)
    r01 = interface_r(n_g, np.full_like(wl, AR_INDEX))
    r12 = interface_r(np.full_like(wl, AR_INDEX), nk("Si", wl))
    r2 = np.abs((r01 + r12 * phase) / (1.0 + r01 * r12 * phase)) ** 2
    return incoherent(r1, r2)


def white_paint(wl: F64) -> F64:
    """Spectrally flat diffuse white."""
    return np.full_like(wl, WHITE_PAINT_REFLECTANCE)


MATERIALS = {
    "aluminium": (aluminium, "bare aluminium, Fresnel at normal incidence from Rakic 1995 n,k"),
    "kapton_mli": (
        kapton_mli,
        "aluminised Kapton MLI: 25 um Kapton (Arakawa 1981 n,k, Urbach tail of k) over Al",
    ),
    "solar_cell": (
        solar_cell,
        "Si cell (Green 2008) with a 75 nm n=2.0 AR film under SiO2 cover glass (Malitson)",
    ),
    "white_paint": (white_paint, "white paint, flat 0.8 (the paper's uniform distribution)"),
}


def write_all(out_dir: Path) -> list[Path]:
    """Write one ``NAME.csv`` per material into ``out_dir``; returns the paths."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, (func, note) in MATERIALS.items():
        values = func(GRID_NM)
        assert np.all((values >= 0) & (values <= 1)), name
        lines = [
            f"# {note}; made by scripts/make_material_spectra.py (see PROVENANCE.md)",
            "wavelength_nm,reflectance",
        ]
        lines += [f"{w:.1f},{r:.6f}" for w, r in zip(GRID_NM, values, strict=True)]
        path = out_dir / f"{name}.csv"
        path.write_text("\n".join(lines) + "\n")
        paths.append(path)
    return paths


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else OUT_DIR
    for p in write_all(target):
        print(p)
