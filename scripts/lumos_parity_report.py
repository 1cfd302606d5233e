"""The numbers of docs/real-satellites.md: speclight's Starlink models against lumos-sat on
the grid of scripts/lumos_parity.py (issue 24, items 3 and 4).

Each variant is simulated at the grid's epochs (15 twilight passes, three sites) and its
magnitude compared with lumos-sat's on its own two-plate model (binomial lab fits, its Sun,
no Earthshine). Two magnitudes per variant: ``lumos convention`` (speclight's reflectance
factor through lumos-sat's Sun and zero point: the target alone) and ``V`` (speclight's AB
magnitude in Bessell V, the E490 Sun at its distance, no atmosphere). The variants take
one step each from lumos-sat's model to the built-in example, so that each difference has
one cause.

Run: ``.venv/bin/python scripts/lumos_parity_report.py [--resolution 128] [--only NAME]``
(some minutes; the Earthshine variants render each epoch once per Earth cell).
"""

from __future__ import annotations

import argparse
import copy
import importlib.util
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]


def _parity() -> Any:
    spec = importlib.util.spec_from_file_location("lumos_parity", ROOT / "scripts/lumos_parity.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("lumos_parity", mod)
    spec.loader.exec_module(mod)
    return mod


lp = _parity()
Variant = Callable[[Any, int, Path, int], dict[str, Any]]
BANDS = [{"name": "V", "filter": "bessell-V"}, {"name": "G-532/3"}]
#: The examples' Earthshine: a grey Lambertian Earth of albedo 0.3, 32 cells.
EARTHSHINE = {"albedo": 0.3, "samples": 32}
SPECTRUM = {"min_nm": 400.0, "max_nm": 760.0, "step_nm": 5.0}


def _plates(materials: dict[str, Any] | None = None, earthshine: bool = False) -> Variant:
    def make(site: Any, index: int, mesh: Path, res: int) -> dict[str, Any]:
        d = lp.plates_scenario(site, index, mesh, res)
        d["instrument"]["bands"] = BANDS
        d["spectrum"] = SPECTRUM
        if materials is not None:
            d["target"]["materials"] = materials
        if earthshine:
            _earthshine(d)
        return d

    return make


def _example(name: str, change: Callable[[dict[str, Any]], None] | None = None) -> Variant:
    from speclight.scenario.builtin_examples import example_text

    base = yaml.safe_load(example_text(name))

    def make(site: Any, index: int, mesh: Path, res: int) -> dict[str, Any]:
        d = copy.deepcopy(base)
        d["time"] = lp.window(site)
        d["observer"] = lp.observer(site)
        d["orbit"] = {"tle": lp.pass_tle(site, index)}
        d["atmosphere"] = {"model": "none"}
        d["spectrum"] = SPECTRUM
        d["instrument"] = {"bands": BANDS}
        d["render"]["resolution_px"] = res
        if change is not None:
            change(d)
        return d

    return make


TABLES = {
    "chassis": "starlink_v1p5_chassis_532nm",
    "array": "starlink_v1p5_solar_array_532nm",
}


def _materials(kind: str) -> dict[str, Any]:
    """The plates' materials: lumos-sat's binomial fits, or the lab tables with an extension."""
    if kind == "binomial fits":
        return {
            "chassis": {"bsdf": "binomial", "coefficients": lp.CHASSIS_BINOMIAL},
            "array": {"bsdf": "binomial", "coefficients": lp.ARRAY_BINOMIAL},
        }
    extension = kind.split()[-1]
    return {
        part: {"bsdf": "measured", "brdf_table": table, "extension": extension}
        for part, table in TABLES.items()
    }


def _builtin_materials(kind: str) -> Callable[[dict[str, Any]], None]:
    def change(d: dict[str, Any]) -> None:
        m = _materials(kind)
        d["target"]["materials"] = {
            "bus_nadir": m["chassis"],
            "bus": m["chassis"],
            "array": m["array"],
        }

    return change


def _no_earthshine(d: dict[str, Any]) -> None:
    d["illumination"].pop("earthshine", None)


def _earthshine(d: dict[str, Any]) -> None:
    d["illumination"]["earthshine"] = dict(EARTHSHINE)


def _black_sides(d: dict[str, Any]) -> None:
    d["target"]["materials"]["bus"] = {"bsdf": "lambertian", "reflectance": 0.0}


def _previous(d: dict[str, Any]) -> None:
    """The example before issue 24: array centred above the bus, turned about nadir."""
    d["attitude"] = {"model": "nadir", "nadir_type": "geodetic"}
    d["target"]["shape"] = {
        "builtin": "bus_array",
        "bus_size_m": [2.8, 1.3, 0.3],
        "array_size_m": [8.1, 2.8],
        "array_gap_m": 0.2,
    }
    d["target"]["articulation"] = {
        "array": {
            "axis": [0, 0, 1],
            "hinge_point_m": [0, 0, -1.75],
            "normal": [1, 0, 0],
            "mode": "sun_tracking",
        }
    }
    d["target"]["articulation_step_deg"] = 0.25
    d["target"]["materials"] = {
        part: {"bsdf": "measured", "brdf_table": TABLES[kind], "reflectance": 1.0}
        for part, kind in (("bus_nadir", "chassis"), ("bus", "chassis"), ("array", "array"))
    }
    _no_earthshine(d)


VARIANTS: dict[str, Variant] = {
    "plates, binomial fits (lumos-sat's model)": _plates(),
    "plates, binomial fits, Earthshine (against lumos-sat with Earthshine)": _plates(
        earthshine=True
    ),
    "plates, tables + microfacet extension": _plates(_materials("tables microfacet")),
    "plates, tables + binomial extension": _plates(_materials("tables binomial")),
    "body, binomial fits, bus sides black, no Earthshine": _example(
        "starlink-v1.5",
        lambda d: (_builtin_materials("binomial fits")(d), _black_sides(d), _no_earthshine(d)),
    ),
    "body, binomial fits, no Earthshine": _example(
        "starlink-v1.5",
        lambda d: (_builtin_materials("binomial fits")(d), _no_earthshine(d)),
    ),
    "body, example materials, no Earthshine": _example("starlink-v1.5", _no_earthshine),
    "body, example (Earthshine)": _example("starlink-v1.5"),
    "previous example (before issue 24)": _example("starlink-v1.5", _previous),
    "previous example's body and attitude, binomial fits": _example(
        "starlink-v1.5", lambda d: (_previous(d), _builtin_materials("binomial fits")(d))
    ),
}


def _stats(d: np.ndarray) -> str:
    d = d[np.isfinite(d)]
    if d.size == 0:
        return "no finite rows"
    p5, p50, p95 = np.percentile(d, [5, 50, 95])
    return (
        f"n {d.size:4d}  median {p50:+.3f}  std {np.std(d):.3f}  5-95 % {p5:+.3f} .. {p95:+.3f}"
        f"  |d| > 1: {np.mean(np.abs(d) > 1):.1%}"
    )


def run(only: str | None, resolution_px: int) -> None:
    from lumos.brdf.library import LAMBERTIAN

    import speclight
    from speclight.simulation.pipeline import simulate

    surfaces = lp.lumos_surfaces()
    with tempfile.TemporaryDirectory() as tmp:
        mesh = lp.plates_obj(Path(tmp) / "plates.obj")
        epochs: dict[tuple[str, int], Any] = {}
        lumos: dict[tuple[str, int], np.ndarray] = {}
        lumos_earthshine: dict[tuple[str, int], np.ndarray] = {}
        for site, index in lp.passes():
            loaded = speclight.load(lp.plates_scenario(site, index, mesh, resolution_px))
            times = lp.grid_epochs(loaded)
            epochs[site.name, index] = times
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                flux = lp.lumos_flux_W_m2(surfaces, lp.pass_tle(site, index), site, times)
                earth = lp.lumos_flux_W_m2(
                    surfaces,
                    lp.pass_tle(site, index),
                    site,
                    times,
                    LAMBERTIAN(EARTHSHINE["albedo"]),
                )
            lumos[site.name, index] = lp.lumos_magnitude(flux)
            lumos_earthshine[site.name, index] = lp.lumos_magnitude(earth)
        print(f"grid: {sum(t.size for t in epochs.values())} epochs")
        for name, make in VARIANTS.items():
            if only and only not in name:
                continue
            t0 = time.time()
            conv, band_v, sun = [], [], []
            for site, index in lp.passes():
                times = epochs[site.name, index]
                if times.size == 0:
                    continue
                ds = simulate(
                    speclight.load(make(site, index, mesh, resolution_px)), time_utc=times
                ).dataset
                rf = ds["reflectance_factor"].sel(band="G-532/3").values
                m_conv = lp.lumos_convention_magnitude(rf, ds["range"].values)
                m_v = ds["ab_magnitude"].sel(band="V").values
                ref = (lumos_earthshine if "Earthshine (against" in name else lumos)[
                    site.name, index
                ]
                with np.errstate(invalid="ignore"):
                    conv.append(m_conv - ref)
                    band_v.append(m_v - ref)
                    sun.append(m_v - m_conv)
            print(f"\n{name}  ({time.time() - t0:.0f} s)")
            print("  lumos convention - lumos:", _stats(np.concatenate(conv)))
            print("  V (E490)         - lumos:", _stats(np.concatenate(band_v)))
            print("  V - lumos convention    :", _stats(np.concatenate(sun)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, default=128)
    parser.add_argument("--only", default=None, help="run the variants whose name holds this")
    args = parser.parse_args()
    run(args.only, args.resolution)


if __name__ == "__main__":
    main()
