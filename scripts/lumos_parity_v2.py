"""The built-in starlink-v2-mini against lumos-sat on the grid of scripts/lumos_parity.py
(issue 24, item 5; the numbers of docs/real-satellites.md).

The reference is Kandula et al. 2025's V2 mini model as they run it: a facet sum in
lumos-sat (``get_intensity_satellite_frame``), the eight surfaces of
``starlink_gen2_surfaces.txt`` (areas, normals), each with the BRDF of the built-in
example's material so that the comparison isolates what the body adds (shadowing,
occlusion, finite size): lumos-sat's own ``BINOMIAL``, ``PHONG`` and ``ABG`` with the
example's coefficients, and for the pantograph's microfacet fit (lumos-sat has no such
form) speclight's function of the same cosines. Variants: the example's body in lumos-sat's
geocentric frame without Earthshine (the geometry alone), then the example itself
(geodetic nadir, Earthshine), no atmosphere; differences in lumos-sat's convention
(speclight's reflectance factor through its Sun) and in V (E490).

Run: ``.venv/bin/python scripts/lumos_parity_v2.py [--resolution 128]`` (a few minutes).
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import sys
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]


def _script(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, mod)
    spec.loader.exec_module(mod)
    return mod


report = _script("lumos_parity_report")
lp = report.lp
#: starlink_gen2_surfaces.txt's labels -> the example's parts.
PARTS = {
    "chassis, mirror film": "mirror_film",
    "chassis, bare aluminium": "chassis_bare",
    "pantograph": "pantograph",
    "phased-array dishes Ka": "dishes_ka",
    "dishes Ka/E": "dishes_ka_e",
    '"twist" surfaces': "twist",
    "boom": "boom",
    "chassis offset": "chassis_offset",
}
ROW = re.compile(r"^(?P<name>\S.*?)\s{2,}(?P<area>\d+\.\d+)\s+\((?P<normal>[^)]*)\)")


def _microfacet(coefficients: dict[str, Any]) -> Any:
    """speclight's analytic form as a lumos-sat BRDF f(to Sun, normal, to observer)."""
    from speclight.target.brdf_fit.form_coefficients import evaluate

    def brdf(i: Any, n: Any, o: Any) -> Any:
        i, n, o = (np.asarray(v, dtype=np.float64) for v in (i, n, o))
        h = (i + o) / np.linalg.norm(i + o)
        ci, co = float(i @ n), float(o @ n)
        if ci <= 0 or co <= 0:
            return 0.0
        return float(evaluate("microfacet", coefficients, ci, co, float(h @ n), float(i @ h)))

    return brdf


def _lumos_brdf(material: dict[str, Any]) -> Any:
    from lumos.brdf.library import ABG, BINOMIAL, PHONG

    c = material["coefficients"]
    if material["bsdf"] == "binomial":
        return BINOMIAL(np.array(c["b"]), np.array(c["c"]), c["d"], c["l1"])
    if material["bsdf"] == "phong":
        return PHONG(c["kd"], c["ks"], c["n"])
    if material["bsdf"] == "abg":
        return ABG(c["a"], c["b"], c["g"])
    return _microfacet(c)


def kandula_surfaces(example: dict[str, Any]) -> list[Any]:
    """Kandula et al.'s eight facets as lumos-sat surfaces, with the example's BRDFs."""
    from lumos.geometry import Surface

    text = (ROOT / "src/speclight/data/brdf/starlink_gen2_surfaces.txt").read_text()
    surfaces = []
    for line in text.splitlines():
        m = ROW.match(line)
        if m and m["name"] in PARTS:
            normal = np.array([float(v) for v in m["normal"].split(",")])
            material = example["target"]["materials"][PARTS[m["name"]]]
            surfaces.append(
                Surface(float(m["area"]), normal / np.linalg.norm(normal), _lumos_brdf(material))
            )
    assert len(surfaces) == len(PARTS)
    return surfaces


def _geocentric_no_earthshine(d: dict[str, Any]) -> None:
    d["attitude"]["nadir_type"] = "geocentric"
    d["illumination"].pop("earthshine", None)


VARIANTS = {
    "V2 mini body, lumos-sat's frame (geocentric), no Earthshine": report._example(
        "starlink-v2-mini", _geocentric_no_earthshine
    ),
    "V2 mini example (geodetic, Earthshine)": report._example("starlink-v2-mini"),
}


def run(resolution_px: int) -> None:
    import speclight
    from speclight.scenario.builtin_examples import example_text
    from speclight.simulation.pipeline import simulate

    surfaces = kandula_surfaces(yaml.safe_load(example_text("starlink-v2-mini")))
    with_light: list[np.ndarray] = []
    results: dict[str, tuple[list[np.ndarray], list[np.ndarray]]] = {
        name: ([], []) for name in VARIANTS
    }
    tmp = tempfile.TemporaryDirectory()
    mesh = lp.plates_obj(Path(tmp.name) / "plates.obj")  # the grid's scenarios need one
    for site, index in lp.passes():
        times = lp.grid_epochs(speclight.load(lp.plates_scenario(site, index, mesh, 16)))
        if times.size == 0:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            flux = lp.lumos_flux_W_m2(surfaces, lp.pass_tle(site, index), site, times)
        ref = lp.lumos_magnitude(flux)
        with_light.append(flux > 0)
        for name, make in VARIANTS.items():
            ds = simulate(
                speclight.load(make(site, index, mesh, resolution_px)), time_utc=times
            ).dataset
            rf = ds["reflectance_factor"].sel(band="G-532/3").values
            with np.errstate(invalid="ignore"):
                results[name][0].append(lp.lumos_convention_magnitude(rf, ds["range"].values) - ref)
                results[name][1].append(ds["ab_magnitude"].sel(band="V").values - ref)
    tmp.cleanup()
    lit = np.concatenate(with_light)
    print(f"grid: {lit.size} epochs, {lit.sum()} where lumos-sat returns light")
    for name, (conv, band_v) in results.items():
        print(f"\n{name}")
        print("  lumos convention - lumos:", report._stats(np.concatenate(conv)))
        print("  V (E490)         - lumos:", report._stats(np.concatenate(band_v)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, default=128)
    run(parser.parse_args().resolution)


if __name__ == "__main__":
    main()
