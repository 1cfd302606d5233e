"""Reflectance specs, materials, shapes and part-to-material maps."""

import struct

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.target import (
    CUBE_FACES,
    Material,
    Reflectance,
    box_wing,
    cube,
    cylinder,
    fresnel_reflectance,
    refractive_index,
    sphere,
)
from speclight.target.brdf_table import load_brdf_table
from speclight.target.rgl_file import read_tensor_file


def test_fresnel_dielectric_normal_incidence_and_grazing():
    # ((n - 1) / (n + 1))^2 at normal incidence (Hecht, Optics, eq. 4.67) and 1 at grazing.
    n = 1.5
    assert fresnel_reflectance(1.0, n) == pytest.approx(((n - 1) / (n + 1)) ** 2, rel=1e-12)
    assert fresnel_reflectance(0.0, n) == pytest.approx(1.0)
    # Brewster angle: r_p = 0, so R = r_s^2 / 2 with r_s = cos(2 theta_B) (Hecht, sec. 8.6).
    theta_b = np.arctan(n)
    assert fresnel_reflectance(np.cos(theta_b), n) == pytest.approx(0.5 * np.cos(2 * theta_b) ** 2)


def test_fused_silica_index_matches_malitson():
    # Fused silica n_d = 1.4585 at the helium d line, 587.56 nm (Malitson 1965, Table 1;
    # the standard catalogue value); the shipped table must reproduce it to 1e-4.
    assert refractive_index("SiO2", 587.56).real == pytest.approx(1.4585, abs=1e-4)


def test_reflectance_kinds():
    wl = np.array([400.0, 500.0, 600.0])
    assert np.all(Reflectance.constant(0.3).evaluate(wl) == 0.3)
    t = Reflectance.pairs([400, 600], [0.2, 0.6])
    np.testing.assert_allclose(t.evaluate(wl), [0.2, 0.4, 0.6])
    al = Reflectance.conductor("Al")
    assert al.is_fresnel and al.at_incidence([1.0, 0.5, 0.0], wl).shape == (3, 3)
    with pytest.raises(InputError, match="covers"):
        t.evaluate(np.array([300.0]))
    with pytest.raises(InputError, match="did you mean 'Ag'"):
        Reflectance.conductor("Agg")
    with pytest.raises(InputError, match="other kind"):
        Reflectance.dielectric("Au")
    with pytest.raises(InputError, match="percent"):
        Reflectance.pairs([400, 600], [20, 60])


def test_reflectance_table_file(tmp_path):
    f = tmp_path / "r.csv"
    f.write_text("# white paint\nwavelength_nm,reflectance\n400,0.8\n800,0.9\n")
    np.testing.assert_allclose(Reflectance.table_file(f).evaluate([600.0]), [0.85])
    bad = tmp_path / "bad.csv"
    bad.write_text("400,0.8\n800,x\n")
    with pytest.raises(InputError, match=r"bad\.csv"):
        Reflectance.table_file(bad)


def test_material_validation():
    with pytest.raises(InputError, match="did you mean 'beckmann'"):
        Material("m", "beckman", Reflectance.constant(0.5))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="roughness"):
        Material("m", "ggx", Reflectance.constant(0.5))
    with pytest.raises(InputError, match="roughness is not used"):
        Material("m", "lambertian", Reflectance.constant(0.5), roughness=0.1)


def test_shapes_areas_and_part_maps():
    m = Material("w", "lambertian", Reflectance.constant(0.5))
    assert sphere(2.0, m).parts[0].area_m2 == pytest.approx(16 * np.pi)
    c = cube(2.0, {"+x": m, "*": m})
    assert c.part_names == CUBE_FACES
    assert sum(p.area_m2 for p in c.parts) == pytest.approx(24.0)
    # 96-gon cylinder: side area 2 r L sin(pi/n) n (inscribed polygon).
    cyl = cylinder(1.0, 3.0, m)
    assert cyl.parts[0].area_m2 == pytest.approx(2 * 96 * np.sin(np.pi / 96) * 3.0)
    assert box_wing(m).part_names == ("bus", "wing_+y", "wing_-y", "antenna")
    with pytest.raises(InputError, match=r"did you mean '\+x'.*parts found: \+x, -x"):
        cube(1.0, {"+xx": m, "*": m})
    with pytest.raises(InputError, match="no material for part"):
        cube(1.0, {"+x": m})


#: The first bytes of the audit's garbage files (fuzz/0172/refl.csv, fuzz/0191/brdf.csv).
GARBAGE = bytes.fromhex("1e746b79c84295ebda3c6c5133f46f8860da135bf96ae44a")


def test_reflectance_table_file_bad_content_names_file_and_line(tmp_path):
    # Reproducer fuzz/0172: binary garbage raised UnicodeDecodeError (an internal error).
    cases = {
        "garbage.csv": (GARBAGE, r"garbage\.csv.*byte 0xc8 at line 1, .*is not UTF-8"),
        "nan.csv": (b"wavelength_nm,reflectance\n400,0.5\n600,nan\n", r"line 3 .*not a finite"),
        "two_headers.csv": (b"wavelength\nreflectance\n400,0.5\n", r"line 2 .*not two numbers"),
        "one_row.csv": (b"400,0.5\n", r">= 2 .*pairs"),
    }
    for name, (content, message) in cases.items():
        (tmp_path / name).write_bytes(content)
        with pytest.raises(InputError, match=message) as err:
            Reflectance.table_file(tmp_path / name, field="target.materials.bus.reflectance")
        assert err.value.source == str(tmp_path / name)
        assert err.value.field == "target.materials.bus.reflectance"
    (tmp_path / "folder.csv").mkdir()
    with pytest.raises(InputError, match="is a folder"):
        Reflectance.table_file(tmp_path / "folder.csv")
    with pytest.raises(InputError, match="finite numbers"):
        Reflectance.pairs([400, 600], [0.2, float("nan")])


def test_brdf_table_bad_content_names_file_and_line(tmp_path):
    # Reproducer fuzz/0191: binary garbage raised UnicodeDecodeError (an internal error).
    good = ["0 0 10 180 0.3", "10 0 20 180 0.2", "20 0 30 180 0.1", "30 0 0 180 0.1"]
    cases = {
        "garbage.csv": (GARBAGE, r"byte 0xc8 at line 1, .*is not UTF-8"),
        "nan.csv": ("\n".join(["# lambda = 532 nm", *good[:2], "20 0 30 180 nan"]).encode(),
                    r"line 4 '20 0 30 180 nan' is not 5 finite numbers"),
        "text.csv": ("\n".join([*good, "a b c d e"]).encode(), r"line 5 'a b c d e'"),
        "short.csv": ("\n".join(good[:2]).encode(), r"at least 3 rows.*found 2"),
        "negative.csv": ("\n".join([*good, "5 0 5 180 -1"]).encode(), r"line 5.*must be >= 0"),
        # Every sample at theta_h = theta_d = 5 deg, i.e. one point: no area to interpolate.
        "one_point.csv": ("\n".join(["0 0 10 180 0.3"] * 3).encode(), r"do not span an area"),
    }  # fmt: skip
    for name, (content, message) in cases.items():
        (tmp_path / name).write_bytes(content)
        with pytest.raises(InputError, match=message) as err:
            load_brdf_table(str(tmp_path / name))
        assert err.value.source == str(tmp_path / name)
    (tmp_path / "folder.csv").mkdir()
    with pytest.raises(InputError, match="is a folder"):
        load_brdf_table(str(tmp_path / "folder.csv"))


def test_tensor_file_with_a_lying_shape_is_refused(tmp_path):
    # A field of 2**40 x 2**40 floats: the product overflowed int64 to 0 and numpy then
    # failed to reshape (a ValueError, an internal error) instead of reporting truncation.
    header = b"tensor_file\0" + bytes([1, 0]) + struct.pack("<I", 1)
    header += struct.pack("<H", 7) + b"spectra" + struct.pack("<HBQ", 2, 10, 0)
    header += struct.pack("<2Q", 2**40, 2**40)
    f = tmp_path / "lying.bsdf"
    f.write_bytes(header)
    with pytest.raises(InputError, match="'spectra' runs past the end of the file"):
        read_tensor_file(f)
    (tmp_path / "folder.bsdf").mkdir()
    with pytest.raises(InputError, match="is a folder"):
        read_tensor_file(tmp_path / "folder.bsdf")
