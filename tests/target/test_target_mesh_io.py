"""OBJ and PLY loading: parts, materials and geometry survive the round trip through a file."""

import struct

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.target import Material, Reflectance, cube, load_mesh

M = Material("w", "lambertian", Reflectance.constant(0.5))


def _write_obj(path, target):
    lines, off = ["# cube written by the test"], 1
    for p in target.parts:
        lines.append(f"g {p.name}")
        lines += [f"v {x} {y} {z}" for x, y, z in p.vertices_m]
        # One quad per face (the two triangles share the diagonal 0-2) with v//vn syntax.
        lines.append("f " + " ".join(f"{off + i}//1" for i in (0, 1, 2, 3)))
        off += len(p.vertices_m)
    path.write_text("\n".join(lines) + "\n")


def test_obj_groups_become_parts_with_the_cube_geometry(tmp_path):
    ref = cube(2.0, M)
    f = tmp_path / "cube.obj"
    _write_obj(f, ref)
    t = load_mesh(f, {"+x": M, "*": M})
    assert t.part_names == ref.part_names
    for a, b in zip(t.parts, ref.parts, strict=True):
        assert a.area_m2 == pytest.approx(b.area_m2)
        # Same outward normal (winding kept through the fan split).
        na = np.cross(*(a.vertices_m[a.faces[0]][1:] - a.vertices_m[a.faces[0]][0]))
        nb = np.cross(*(b.vertices_m[b.faces[0]][1:] - b.vertices_m[b.faces[0]][0]))
        assert np.dot(na, nb) > 0


def test_unknown_part_in_material_map_names_the_parts_found(tmp_path):
    f = tmp_path / "cube.obj"
    _write_obj(f, cube(1.0, M))
    with pytest.raises(InputError, match=r"'solar_panel'.*parts found: \+x, -x, \+y, -y, \+z, -z"):
        load_mesh(f, {"solar_panel": M, "*": M})


def test_ply_ascii_and_binary_one_part_per_file(tmp_path):
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    head = "ply\nformat {fmt} 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    head += "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    a = tmp_path / "panel.ply"
    a.write_text(
        head.format(fmt="ascii") + "".join(f"{x} {y} {z}\n" for x, y, z in v) + "4 0 1 2 3\n"
    )
    b = tmp_path / "radiator.ply"
    body = b"".join(struct.pack("<3f", *row) for row in v) + struct.pack("<B4i", 4, 0, 1, 2, 3)
    b.write_bytes(head.format(fmt="binary_little_endian").encode() + body)
    t = load_mesh([a, b], {"panel": M, "radiator": M}, scale_m_per_unit=2.0)
    assert t.part_names == ("panel", "radiator")
    assert [p.area_m2 for p in t.parts] == pytest.approx([4.0, 4.0])


def test_bad_mesh_files_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_mesh(tmp_path / "missing.obj", M)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2\n")
    with pytest.raises(InputError, match="line 3"):
        load_mesh(bad, M)
    with pytest.raises(InputError, match=r"accepted: \.obj, \.ply"):
        (tmp_path / "x.stl").write_text("solid")
        load_mesh(tmp_path / "x.stl", M)
