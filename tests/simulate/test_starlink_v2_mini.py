"""The built-in starlink-v2-mini example against Kandula et al. 2025's surface model (issue 24,
item 5).

Reference: ``starlink_gen2_surfaces.txt`` (shipped with the tables, facts from Kandula et al.
2025, repository Phan-Kandula/simulated-satellite-streaks-impact, gen2_starlink/): each
surface's area, its normal in lumos-sat's frame (z to the zenith, y toward the Sun's
azimuth) and the lab table its BRDF comes from. The example's parts must have those areas
and normals (lumos-sat's (x, y, z) is body (y, x, -z) in the yaw-steered nadir frame the
example flies), and each part's analytic material must fit the table the file names for it
better than it fits any other second-generation table (the material is that table's fit).
docs/real-satellites.md's table of the parts is held to the example (not a reference test:
it keeps the page true).
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from speclight.scenario import load_example
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.reflection import build_target
from speclight.target.brdf_fit.directional_albedo import max_albedo
from speclight.target.brdf_fit.form_coefficients import evaluate
from speclight.target.brdf_samples import read_table_samples

#: The file's surface labels -> the example's part names.
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
_ROW = re.compile(
    r"^(?P<name>\S.*?)\s{2,}(?P<area>\d+\.\d+)\s+\((?P<normal>[^)]*)\)\s+(?P<brdf>.+)$"
)
#: Float64 rounding of the mesh's triangle areas and normals (vertices from the areas).
ROUNDING = 1e-9


def _surfaces() -> dict[str, tuple[float, np.ndarray, str]]:
    text = resources.files("speclight").joinpath("data/brdf/starlink_gen2_surfaces.txt")
    rows = {}
    for line in text.read_text().splitlines():
        m = _ROW.match(line)
        if m and m["name"] in PARTS:
            normal = np.array([float(v) for v in m["normal"].split(",")])
            rows[PARTS[m["name"]]] = (float(m["area"]), normal, m["brdf"])
    assert set(rows) == set(PARTS.values()), "every surface of the file is read"
    return rows


def _normal(part) -> np.ndarray:
    t = part.vertices_m[part.faces]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    return n.sum(axis=0) / np.linalg.norm(n.sum(axis=0))


def test_parts_are_kandulas_surfaces_areas_and_normals():
    target = build_target(load_example("starlink-v2-mini"))
    parts = {p.name: p for p in target.parts}
    surfaces = _surfaces()
    assert set(parts) == set(surfaces)
    for name, (area, normal_lumos, _) in surfaces.items():
        assert parts[name].area_m2 == pytest.approx(area, rel=ROUNDING), name
        x, y, z = normal_lumos / np.linalg.norm(normal_lumos)
        np.testing.assert_allclose(_normal(parts[name]), [y, x, -z], atol=ROUNDING, err_msg=name)


def test_the_frame_is_lumos_sats():
    # yaw-steered nadir: the Sun in the body x-z plane on +x, body +z on nadir, so that a
    # normal (x, y, z) of lumos-sat's frame is body (y, x, -z)
    loaded = load_example("starlink-v2-mini")
    geo = scenario_geometry(loaded)
    lit = geo.observable & (geo.sunlit_fraction > 0)
    assert lit.sum() >= 5
    sun = geo.sun_direction_body[lit]
    np.testing.assert_allclose(sun[:, 1], 0.0, atol=1e-9)
    assert np.all(sun[:, 0] > 0)
    assert loaded.scenario.attitude.nadir_type == "geodetic"


def _log_rms(material, table: str) -> float:
    samples = read_table_samples(table)
    keep = samples.usable() & (samples.brdf > 0)
    cos = [c[keep] for c in samples.cosines()]
    model = evaluate(material.bsdf, dict(material.coefficients), *cos)
    return float(np.sqrt(np.mean((np.log10(model) - np.log10(samples.brdf[keep])) ** 2)))


def test_each_material_is_the_fit_of_its_table():
    target = build_target(load_example("starlink-v2-mini"))
    materials = {p.name: p.material for p in target.parts}
    tables = {
        name: "starlink_gen2_" + m.group(1)
        for name, (_, _, brdf) in _surfaces().items()
        if (m := re.match(r"table starlink_gen2_(\w+)", brdf))
    }
    assert len(tables) == 6  # boom and chassis offset: Kandula et al.'s own ABg and Phong
    others = sorted(set(tables.values()))
    for part, table in tables.items():
        rms = {t: _log_rms(materials[part], t) for t in others}
        assert min(rms, key=rms.get) == table, (part, rms)


def _docs_rows() -> dict[str, list[str]]:
    page = Path(__file__).resolve().parents[2] / "docs" / "real-satellites.md"
    text = page.read_text().split("## The Starlink V2 mini model", 1)[1].split("\n\n**", 1)[0]
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines()
            if line.startswith("| `")]  # fmt: skip
    return {re.match(r"`(\w+)`", r[0]).group(1): r for r in rows}


def test_docs_table_is_the_examples_materials():
    # docs/real-satellites.md's V2 mini table, to its printed precision (3 decimals in dex and
    # albedo: half a unit of the last digit, and the albedo quadrature's 2e-5)
    rows = _docs_rows()
    assert set(rows) == set(PARTS.values())
    target = build_target(load_example("starlink-v2-mini"))
    materials = {p.name: p.material for p in target.parts}
    surfaces = _surfaces()
    for part, row in rows.items():
        area, _, brdf = surfaces[part]
        assert float(row[1]) == area
        m = materials[part]
        if row[5]:
            table = "starlink_gen2_" + re.match(r"table starlink_gen2_(\w+)", brdf).group(1)
            assert _log_rms(m, table) == pytest.approx(float(row[5]), abs=5e-4), part
        c = dict(m.coefficients)
        albedo, _ = max_albedo(lambda *cos, m=m, c=c: evaluate(m.bsdf, c, *cos))
        assert albedo == pytest.approx(float(row[6]), abs=6e-4), part
