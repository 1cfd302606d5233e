"""STL, glTF and OBJ material groups (issue 14 item 12): a unit cube with two material groups
written in each format loads with the cube's area, outward normals and the groups' names."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from speclight.errors import InputError
from speclight.render import render_intensity
from speclight.target import Material, Reflectance, cube, load_mesh

WHITE = Material("white", "lambertian", Reflectance.constant(0.8))
GREY = Material("grey", "lambertian", Reflectance.constant(0.3))
#: the cube's +z and -z faces are the "panel" material group, the other four the "bus"
PANEL_FACES = ("+z", "-z")
MATERIALS = {"panel": WHITE, "bus": GREY}


def _unit_cube():  # type: ignore[no-untyped-def]
    return cube(1.0, {"*": WHITE})


def _group_mesh(names: tuple[str, ...]) -> trimesh.Trimesh:
    parts = [p for p in _unit_cube().parts if p.name in names]
    verts, faces, off = [], [], 0
    for p in parts:
        verts.append(p.vertices_m)
        faces.append(p.faces + off)
        off += len(p.vertices_m)
    return trimesh.Trimesh(np.concatenate(verts), np.concatenate(faces), process=False)


def _groups() -> dict[str, trimesh.Trimesh]:
    side = tuple(n for n in _unit_cube().part_names if n not in PANEL_FACES)
    return {"panel": _group_mesh(PANEL_FACES), "bus": _group_mesh(side)}


def _write_obj_usemtl(path) -> None:  # type: ignore[no-untyped-def]
    # by hand: one object, two material groups (Wavefront OBJ appendix B, 'usemtl')
    lines, off = ["mtllib cube.mtl", "o cube"], 1
    for name, mesh in _groups().items():
        lines += [f"v {x} {y} {z}" for x, y, z in mesh.vertices]
        lines.append(f"usemtl {name}")
        lines += [f"f {a + off} {b + off} {c + off}" for a, b, c in mesh.faces]
        off += len(mesh.vertices)
    path.write_text("\n".join(lines) + "\n")


def _write_gltf(path, named_materials: bool) -> None:  # type: ignore[no-untyped-def]
    scene = trimesh.Scene()
    for name, mesh in _groups().items():
        if named_materials:
            mat = trimesh.visual.material.PBRMaterial(name=name)
            mesh.visual = trimesh.visual.TextureVisuals(material=mat)
            scene.add_geometry(mesh, geom_name=f"mesh_{name}")
        else:
            scene.add_geometry(mesh, geom_name=name)
    scene.export(str(path))


def _check_cube(target, names: set[str]) -> None:  # type: ignore[no-untyped-def]
    assert set(target.part_names) == names
    assert sum(p.area_m2 for p in target.parts) == pytest.approx(6.0)  # unit cube
    for p in target.parts:
        tri = p.vertices_m[p.faces]
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        # outward: along the face centre (the cube is centred on the origin), unit length x 2A
        assert np.all(np.einsum("ij,ij->i", normal, tri.mean(1)) > 0)
    if names == {"panel", "bus"}:
        areas = {p.name: p.area_m2 for p in target.parts}
        assert areas["panel"] == pytest.approx(2.0) and areas["bus"] == pytest.approx(4.0)


def test_obj_material_groups_become_parts(tmp_path) -> None:
    f = tmp_path / "cube.obj"
    _write_obj_usemtl(f)
    _check_cube(load_mesh(f, MATERIALS), {"panel", "bus"})


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_gltf_material_names_become_parts(tmp_path, suffix: str) -> None:
    f = tmp_path / f"cube{suffix}"
    _write_gltf(f, named_materials=True)
    _check_cube(load_mesh(f, MATERIALS), {"panel", "bus"})


def test_gltf_mesh_names_become_parts_without_material_names(tmp_path) -> None:
    f = tmp_path / "cube.glb"
    _write_gltf(f, named_materials=False)
    _check_cube(load_mesh(f, MATERIALS), {"panel", "bus"})


def test_stl_is_one_part_named_for_the_file(tmp_path) -> None:
    f = tmp_path / "debris.stl"
    trimesh.util.concatenate(list(_groups().values())).export(str(f))
    _check_cube(load_mesh(f, WHITE), {"debris"})


def test_unknown_part_and_unsupported_file_are_refused(tmp_path) -> None:
    f = tmp_path / "cube.glb"
    _write_gltf(f, named_materials=True)
    with pytest.raises(InputError, match="panel"):  # the message lists the parts found
        load_mesh(f, {"solar_array": WHITE, "*": GREY})
    bad = tmp_path / "cube.3ds"
    bad.write_bytes(b"\0" * 16)
    with pytest.raises(InputError, match=r"unsupported mesh format '\.3ds'.*\.glb"):
        load_mesh(bad, WHITE)
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF not really")
    with pytest.raises(InputError, match=r"broken\.glb"):
        load_mesh(broken, WHITE)


def test_obj_cube_renders_like_the_built_in_cube(tmp_path) -> None:
    # Same triangles, same materials per face: the single-scattering render must agree to
    # float rounding at every epoch (no Monte Carlo in single mode).
    f = tmp_path / "cube.obj"
    _write_obj_usemtl(f)
    from_obj = load_mesh(f, MATERIALS)
    built_in = cube(1.0, {**dict.fromkeys(PANEL_FACES, WHITE), "*": GREY})
    rng = np.random.default_rng(7)
    sun = rng.normal(size=(5, 3))
    obs = sun + rng.normal(scale=0.7, size=(5, 3))
    sun /= np.linalg.norm(sun, axis=1, keepdims=True)
    obs /= np.linalg.norm(obs, axis=1, keepdims=True)
    e = np.ones((5, 2))
    a, b = (
        render_intensity(
            t, sun, obs, e, np.array([500.0, 600.0]), resolution_px=64
        ).intensity_W_sr_nm
        for t in (from_obj, built_in)
    )
    assert np.all(b > 0)
    assert np.allclose(a, b, rtol=1e-5, atol=0.0)
