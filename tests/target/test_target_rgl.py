"""RGL .bsdf measured materials: the tensor-file container and the checks on load.

The container layout is Mitsuba 3's ``TensorFile`` (src/core/tensor.cpp) and the required
fields those of its ``measured`` plugin (src/bsdfs/measured.cpp); where Mitsuba is installed
the tests ask it, an independent reader, to confirm what the numpy reader/validator says.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.render.variant import available_variants
from speclight.target import Material, Reflectance, material_from_spec
from speclight.target.rgl_file import (
    RGL_FIELDS,
    load_rgl_info,
    read_tensor_file,
    write_tensor_file,
)

F32 = np.float32
needs_mitsuba = pytest.mark.skipif(
    "scalar_spectral" not in available_variants(), reason="needs Mitsuba's scalar_spectral"
)


def _fields(n_phi: int = 1, n_theta: int = 3, n_wl: int = 2, n: int = 4) -> dict:
    """Structurally valid RGL fields (values positive, no physical meaning)."""
    return {
        "description": np.frombuffer(b"tiny", np.uint8),
        "theta_i": np.linspace(0, 1.5, n_theta).astype(F32),
        "phi_i": np.linspace(0, np.pi, n_phi).astype(F32),
        "wavelengths": np.linspace(400, 700, n_wl).astype(F32),
        "ndf": np.ones((n, n), F32),
        "sigma": np.ones((n, n), F32),
        "vndf": np.ones((n_phi, n_theta, n, n), F32),
        "luminance": np.ones((n_phi, n_theta, n, n), F32),
        "spectra": np.full((n_phi, n_theta, n_wl, n, n), 0.1, F32),
        "jacobian": np.ones(1, np.uint8),
    }


def _write(tmp_path: Path, name: str = "m.bsdf", **changes) -> str:
    f = _fields()
    for k, v in changes.items():
        if v is None:
            del f[k]
        else:
            f[k] = v
    path = tmp_path / name
    write_tensor_file(path, f)
    load_rgl_info.cache_clear()
    return str(path)


def _mitsuba_fields(path: str) -> dict[str, tuple[str, tuple[int, ...]]]:
    """Field name -> (dtype, shape) as Mitsuba's own TensorFile reader lists them."""
    from speclight.render.variant import activate

    mi = activate("scalar_spectral")
    text = str(mi.TensorFile(path))
    out = {}
    for name, dtype, shape in re.findall(
        r'"(\w+)" => \[\s*dtype = (\w+),\s*offset = \d+,\s*shape = \[([\d, ]*)\]', text
    ):
        out[name] = (dtype, tuple(int(s) for s in shape.split(",") if s.strip()))
    return out


def test_valid_file_is_accepted_and_summarised(tmp_path):
    path = _write(tmp_path)
    info = load_rgl_info(path)
    assert info.isotropic and info.description == "tiny"
    np.testing.assert_array_equal(info.wavelength_nm, [400.0, 700.0])
    assert info.resolution == (1, 3, 2, 4, 4)
    m = Material("paint", "measured", Reflectance.constant(1.0), brdf_table=path)
    assert m.brdf_table == path
    back = read_tensor_file(path)
    for k, v in _fields().items():
        np.testing.assert_array_equal(back[k], v)


@needs_mitsuba
def test_mitsuba_reads_the_container_and_loads_the_plugin(tmp_path):
    path = _write(tmp_path)
    listed = _mitsuba_fields(path)
    names = {"u1": "uint8", "<f4": "float32"}
    for k, (dt, ndim) in RGL_FIELDS.items():
        assert listed[k][0] == names[dt]
        assert listed[k][1] == _fields()[k].shape and len(listed[k][1]) == ndim
    from speclight.render.variant import activate

    mi = activate("scalar_spectral")
    bsdf = mi.load_dict({"type": "measured", "filename": path})
    assert "Measured" in str(bsdf)


@needs_mitsuba
def test_a_malformed_file_is_rejected_by_both_the_validator_and_mitsuba(tmp_path):
    # spectra with 3 wavelengths while the wavelengths field holds 2
    path = _write(tmp_path, spectra=np.ones((1, 3, 3, 4, 4), F32))
    with pytest.raises(InputError, match=r"m\.bsdf.*spectra shape"):
        load_rgl_info(path)
    from speclight.render.variant import activate

    mi = activate("scalar_spectral")
    with pytest.raises(Exception, match="Invalid file structure"):
        mi.load_dict({"type": "measured", "filename": path})


@pytest.mark.parametrize("field", ["spectra", "jacobian", "vndf", "wavelengths"])
def test_missing_field_is_named(tmp_path, field):
    path = _write(tmp_path, **{field: None})
    with pytest.raises(InputError, match=rf"m\.bsdf' lacks the field\(s\) {field}"):
        Material("x", "measured", Reflectance.constant(1.0), brdf_table=path)


def test_rgb_file_is_refused_with_a_pointer_to_the_spectral_one(tmp_path):
    # RGB RGL files hold 'rgb' instead of 'spectra' and 'wavelengths' (rgl-epfl/brdf-loader,
    # powitacq_rgb); Mitsuba's measured plugin reads spectral files only.
    f = _fields()
    f["rgb"] = f.pop("spectra")[:, :, :1].repeat(3, axis=2)
    del f["wavelengths"]
    path = tmp_path / "rgb.bsdf"
    write_tensor_file(path, f)
    with pytest.raises(InputError, match="is an RGB material file"):
        load_rgl_info(str(path))


def test_wrong_dtype_is_named(tmp_path):
    path = _write(tmp_path, ndf=np.ones((4, 4), np.float64))
    with pytest.raises(InputError, match="field 'ndf' of dtype float64, not float32"):
        load_rgl_info(path)


def test_missing_and_foreign_files(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        Material("x", "measured", Reflectance.constant(1.0), brdf_table=str(tmp_path / "no.bsdf"))
    csv = tmp_path / "table.bsdf"
    csv.write_text("# phi_i theta_i phi_o theta_o brdf\n0 0 0 10 0.3\n")
    with pytest.raises(InputError, match="not a Mitsuba tensor file"):
        load_rgl_info(str(csv))
    good = Path(_write(tmp_path))
    cut = tmp_path / "cut.bsdf"
    cut.write_bytes(good.read_bytes()[:600])
    with pytest.raises(InputError, match=r"past the end of the file|truncated"):
        load_rgl_info(str(cut))


def test_anisotropic_file_is_refused(tmp_path):
    f = _fields(n_phi=3)
    path = tmp_path / "aniso.bsdf"
    write_tensor_file(path, f)
    assert not load_rgl_info(str(path)).isotropic
    with pytest.raises(InputError, match="anisotropic"):
        Material("x", "measured", Reflectance.constant(1.0), brdf_table=str(path))


def test_reflectance_must_be_a_constant_scale(tmp_path):
    path = _write(tmp_path)
    Material("x", "measured", Reflectance.constant(0.4), brdf_table=path)
    for bad in (Reflectance.constant(0.0), Reflectance.pairs([400, 700], [0.2, 0.3])):
        with pytest.raises(InputError, match="constant scale factor"):
            Material("x", "measured", bad, brdf_table=path)


def test_scenario_spec_resolves_a_relative_bsdf_path(tmp_path):
    _write(tmp_path, name="paint.bsdf")
    spec = {"bsdf": "measured", "brdf_table": "paint.bsdf"}
    m = material_from_spec("paint", spec, base_dir=tmp_path)
    assert Path(str(m.brdf_table)) == tmp_path / "paint.bsdf"
    assert m.reflectance.value == 1.0
    with pytest.raises(InputError, match="does not exist"):
        material_from_spec("paint", {**spec, "brdf_table": "other.bsdf"}, base_dir=tmp_path)


# --- Why the numpy reader is kept instead of ``mitsuba.TensorFile`` (issue 14, item 12) ---
# Mitsuba 3.9's Python binding of TensorFile cannot replace it: a field's ``shape`` cannot be
# read, uint8 fields (``description``, ``jacobian``) cannot be converted, and a header whose
# field runs past the end of the file is accepted and crashes the process when read. These
# tests pin those facts: when one fails, Mitsuba has fixed it and the reader can be revisited.


@needs_mitsuba
def test_mitsuba_reads_the_same_float_values_as_the_numpy_reader(tmp_path):
    import drjit as dr

    path = _write(tmp_path)
    from speclight.render.variant import activate

    tensors = activate("scalar_spectral").TensorFile(path)
    ours = read_tensor_file(path)
    for k, (dt, _) in RGL_FIELDS.items():
        if dt == "<f4":
            theirs = np.array(tensors[k].to(dr.scalar.TensorXf))
            np.testing.assert_array_equal(theirs, ours[k])


@needs_mitsuba
def test_mitsuba_tensorfile_binding_lacks_shapes_and_uint8_fields(tmp_path):
    import drjit as dr

    path = _write(tmp_path)
    from speclight.render.variant import activate

    tensors = activate("scalar_spectral").TensorFile(path)
    with pytest.raises(TypeError, match="Unable to convert function return value"):
        _ = tensors["spectra"].shape  # the binding cannot return std::vector<size_t>
    with pytest.raises(Exception, match="incompatible dtype"):
        tensors["description"].to(dr.scalar.TensorXu8)


@needs_mitsuba
def test_a_lying_header_is_refused_here_but_crashes_mitsuba(tmp_path):
    # one float32 field claiming 10^6 x 10 values in a 88-byte file
    head = b"tensor_file\0\x01\x00" + (1).to_bytes(4, "little") + b"\x01\x00a\x02\x00\x0a"
    head += (48).to_bytes(8, "little") + (10**6).to_bytes(8, "little")
    head += (10).to_bytes(8, "little")
    path = tmp_path / "lying.bsdf"
    path.write_bytes(head.ljust(88, b"\0"))
    with pytest.raises(InputError, match=r"field 'a' runs past the end of the file"):
        read_tensor_file(path)
    probe = (
        "import drjit as dr, mitsuba as mi\n"
        "mi.set_variant('scalar_spectral')\n"
        f"mi.TensorFile({str(path)!r})['a'].to(dr.scalar.TensorXf)\n"
    )
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, timeout=120)
    assert done.returncode != 0  # a signal (bus error / segfault) or an exception, not data
