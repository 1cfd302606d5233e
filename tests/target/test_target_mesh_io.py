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
    with pytest.raises(InputError, match=r"accepted: \.obj, \.ply, \.stl, \.gltf, \.glb"):
        (tmp_path / "x.3ds").write_text("solid")
        load_mesh(tmp_path / "x.3ds", M)
    with pytest.raises(InputError, match=r"x\.stl"):  # an STL without a facet
        (tmp_path / "x.stl").write_text("solid")
        load_mesh(tmp_path / "x.stl", M)


# -- malformed and degenerate files (issue 9; reproducers fuzz/0134-0170) -----------------

CUBE_V = [
    (x, y, z) for z in (-0.5, 0.5) for y, x in ((-0.5, -0.5), (-0.5, 0.5), (0.5, 0.5), (0.5, -0.5))
]
CUBE_F = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (0, 3, 2, 1), (4, 5, 6, 7)]
PLY_HEAD = (
    "ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n"
    "property float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
)


def _cube_obj(scale: float = 1.0) -> str:
    lines = ["# unit cube in two groups"] + [
        f"v {x * scale} {y * scale} {z * scale}" for x, y, z in CUBE_V
    ]
    lines += ["g sides"] + [f"f {' '.join(str(i + 1) for i in f)}" for f in CUBE_F[:4]]
    lines += ["g caps"] + [f"f {' '.join(str(i + 1) for i in f)}" for f in CUBE_F[4:]]
    return "\n".join(lines) + "\n"


def _cube_ply(nv: int = 8, nf: int = 6, fmt: str = "ascii") -> str:
    body = "".join(f"{x} {y} {z}\n" for x, y, z in CUBE_V)
    body += "".join(f"{len(f)} {' '.join(map(str, f))}\n" for f in CUBE_F)
    return PLY_HEAD.format(fmt=fmt, nv=nv, nf=nf) + body


BINARY_CUBE_BODY = b"".join(struct.pack("<3f", *v) for v in CUBE_V) + b"".join(
    struct.pack("<B4i", 4, *f) for f in CUBE_F
)

MALFORMED_PLY = {
    # name: (file content, message the InputError must contain)
    "0157-header-only": (PLY_HEAD.format(fmt="ascii", nv=8, nf=6), r"8 vertex rows.*0 data lines"),
    "0158-more-vertices": (_cube_ply(nv=20), r"20 vertex rows.*14 data lines"),
    "0159-more-faces": (_cube_ply(nf=60), r"announces 60 face rows but 6 data lines are left"),
    "0163-text-in-face": (_cube_ply().replace("4 4 5 6 7", "4 a b c d"), r"line 23 .*'a'"),
    "0164-bad-count": (_cube_ply().replace("vertex 8", "vertex eight"), r"line 3 .*'eight'"),
    "0165-no-x": (_cube_ply().replace("float x", "float u"), r"no 'x' property"),
    "0166-binary-ascii-body": (
        _cube_ply(fmt="binary_little_endian"),
        r"binary data is truncated: 72 bytes are left for the 6 face rows",
    ),
    "0167-binary-truncated": (
        PLY_HEAD.format(fmt="binary_little_endian", nv=8, nf=6).encode() + bytes(10),
        r"truncated.*vertex",
    ),
    "0168-unknown-type": (
        _cube_ply().replace("float x", "quad x"),
        r"line 4 .*type 'quad'.*accepted: char",
    ),
    "index-out-of-range": (
        _cube_ply().replace("4 4 5 6 7", "4 4 5 6 8"),
        r"vertex 8.*has 8 vertices",
    ),
    "two-vertex-face": (
        _cube_ply().replace("4 4 5 6 7", "2 4 5"),
        r"face 5 has 2 vertices; a face needs at least 3",
    ),
    "short-vertex-row": (
        _cube_ply().replace("0.5 0.5 0.5\n", "0.5 0.5\n"),
        r"line 16 '0.5 0.5' has 2 values.*vertex properties \(x, y, z",
    ),
    "fewer-claimed": (_cube_ply(nf=5), r"1 line\(s\) after the last element"),
    "no-end-header": ("ply\nformat ascii 1.0\nelement vertex 0\n", r"end_header"),
    "no-magic": ("solid cube\nend_header\n", r"not a PLY file"),
    "bad-format": (_cube_ply(fmt="text"), r"format 'text'.*accepted: ascii"),
    "list-of-floats": (
        _cube_ply().replace("list uchar int", "list uchar float"),
        r"line 8 .*integer",
    ),
    "property-before-element": (
        "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
        r"line 3 .*before any element",
    ),
    "binary-short-face": (
        PLY_HEAD.format(fmt="binary_little_endian", nv=8, nf=6).encode() + BINARY_CUBE_BODY[:-3],
        r"truncated.*face",
    ),
}


@pytest.mark.parametrize("case", MALFORMED_PLY)
def test_malformed_ply_is_an_input_error_naming_the_file(tmp_path, case):
    content, message = MALFORMED_PLY[case]
    f = tmp_path / "part.ply"
    f.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(InputError, match=message) as err:
        load_mesh([f], M)
    assert err.value.source == str(f)


def test_binary_ply_big_endian_with_extra_elements_and_mixed_polygons(tmp_path):
    # A header with an extra element (edges, skipped), extra vertex properties and faces of
    # 3 and 4 vertices (so the per-face fallback reader is used): area of the unit square.
    head = (
        "ply\nformat binary_big_endian 1.0\ncomment test\nelement vertex 4\nproperty double x\n"
        "property double y\nproperty double z\nproperty uchar red\nelement edge 1\n"
        "property int vertex1\nproperty int vertex2\nelement face 2\n"
        "property list uchar uint vertex_indices\nend_header\n"
    )
    v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
    body = b"".join(struct.pack(">3dB", *p, 255) for p in v) + struct.pack(">2i", 0, 1)
    body += struct.pack(">B3I", 3, 0, 1, 2) + struct.pack(">B3I", 3, 0, 2, 3)
    f = tmp_path / "square.ply"
    f.write_bytes(head.encode() + body)
    (part,) = load_mesh([f], M).parts
    assert part.area_m2 == pytest.approx(1.0, rel=1e-12)


DEGENERATE = {
    # name: (OBJ text, scale_m_per_unit, message)
    "0134-zero-area-faces-only": (
        "v 0 0 0\nv 1 0 0\nv 2 0 0\ng sides\nf 1 2 3\nf 1 1 1\n",
        1.0,
        r"part 'sides' has no face of positive area \(all its 2 face\(s\)",
    ),
    "0135-all-vertices-identical": (
        "v 0 0 0\nv 0 0 0\nv 0 0 0\ng sides\nf 1 2 3\n",
        1.0,
        r"part 'sides' has no face of positive area",
    ),
    "0143-coordinates-1e30": (
        _cube_obj(1e30),
        1.0,
        r"bounding radius 8\.66e\+29 m.*accepted: 0\.001 to 100000 m",
    ),
    "0148-scale-1e12": (
        _cube_obj(),
        1e12,
        r"bounding radius 8\.66e\+11 m.*scale_m_per_unit = 1e\+12",
    ),
    "0149-scale-1e-12": (_cube_obj(), 1e-12, r"bounding radius 8\.66e-13 m"),
    "nan-coordinate": (
        _cube_obj().replace("v 0.5 0.5 0.5", "v nan 0.5 0.5"),
        1.0,
        r"part 'sides'.*not finite",
    ),
    "coordinates-1e200": (
        _cube_obj(1e200),
        1.0,
        r"part 'sides' has a bounding radius 8\.66e\+199 m",
    ),
    "far-from-origin": (
        _cube_obj().replace("v -0.5 ", "v 1e6 "),
        1.0,
        r"reaches 1e\+06 m from the body origin",
    ),
    "inf-scale": (_cube_obj(), float("inf"), r"scale_m_per_unit = inf must be a finite number > 0"),
}


@pytest.mark.parametrize("case", DEGENERATE)
def test_degenerate_or_out_of_scale_mesh_is_refused_with_the_reason(tmp_path, case):
    text, scale, message = DEGENERATE[case]
    f = tmp_path / "sat.obj"
    f.write_text(text)
    with pytest.raises(InputError, match=message) as err:
        load_mesh(f, M, scale_m_per_unit=scale)
    assert err.value.source == str(f)


def test_ply_with_only_zero_area_faces_is_refused(tmp_path):
    # Reproducer fuzz/0170: three collinear vertices; the render aborted in Dr.Jit.
    f = tmp_path / "part.ply"
    f.write_text(PLY_HEAD.format(fmt="ascii", nv=3, nf=1) + "0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n")
    with pytest.raises(InputError, match=r"part 'part' has no face of positive area"):
        load_mesh([f], M)


def test_zero_area_faces_among_good_ones_are_dropped_with_a_count(tmp_path):
    f = tmp_path / "sat.obj"
    f.write_text(_cube_obj() + "f 1 1 2\nf 1 2 2 2\n")  # 1 + 2 degenerate triangles in 'caps'
    with pytest.warns(UserWarning, match=r"part 'caps': dropped 3 of 7 faces of zero area"):
        t = load_mesh(f, M)
    caps = t.parts[t.part_names.index("caps")]
    assert caps.faces.shape == (4, 3) and caps.area_m2 == pytest.approx(2.0, rel=1e-12)
