"""RGL measured-material files (``.bsdf``): Mitsuba tensor files, read and checked in numpy.

Why not ``mitsuba.TensorFile``: Mitsuba 3.9's Python binding cannot read a field's shape
(``Field.shape`` raises ``TypeError``), cannot convert uint8 fields (``description``,
``jacobian``), and accepts a header whose field runs past the end of the file, then crashes
the process (bus error) when that field is read. This reader checks every field against the
file size and names the file and field in its errors; it also runs where Mitsuba is not
imported (the scenario's load-time checks). tests/target/test_target_rgl.py compares its
values with Mitsuba's and pins those three limits, so a Mitsuba that lifts them is noticed.

The RGL material database (https://rgl.epfl.ch/materials) distributes spectral BRDFs measured
with the adaptive parameterisation of Dupuy & Jakob 2018, "An Adaptive Parameterization for
Efficient Material Acquisition and Rendering", ACM TOG 37(6) 274,
doi:10.1145/3272127.3275059, in Mitsuba's *tensor file* container, which Mitsuba 3's
``measured`` BSDF plugin reads. The container (Mitsuba ``TensorFile``) is: the 12 bytes
``tensor_file\\0``, a version (2 bytes, major 1), a ``uint32`` field count, then per field a
``uint16`` name length and name, ``uint16`` ndim, ``uint8`` dtype (Mitsuba ``Struct::Type``:
1 = uint8, 10 = float32, ...), ``uint64`` data offset and ``ndim`` ``uint64`` sizes; all
little-endian, data in C order.

The ``measured`` plugin needs (shapes as it checks them; ``P``/``T`` incident azimuth/elevation
nodes, ``W`` wavelengths, ``N`` the square sample grid):

=============  =========================  ==========================================
field          dtype, shape               meaning
=============  =========================  ==========================================
description    uint8 (n,)                 text
theta_i        float32 (T,)               incident elevation nodes [rad]
phi_i          float32 (P,)               incident azimuth nodes [rad]; P <= 2: isotropic
wavelengths    float32 (W,)               [nm]
ndf            float32 (2-D)              microfacet normal distribution
sigma          float32 (2-D)              projected microfacet area
vndf           float32 (P, T, a, b)       visible-normal distribution (sampling warp)
luminance      float32 (P, T, N, N)       luminance on the warped domain (sampling)
spectra        float32 (P, T, W, N, N)    reflectance on the warped domain
jacobian       uint8 (1,)                 1: multiply by ndf / (4 sigma)
=============  =========================  ==========================================
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_bytes
from speclight.target.reflectance import Reflectance

RGL_SUFFIX = ".bsdf"
_MAGIC = b"tensor_file\0"
#: Mitsuba ``Struct::Type`` codes of the tensor-file container.
DTYPE_CODES: dict[int, str] = {
    1: "u1", 2: "i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4",
    7: "<u8", 8: "<i8", 9: "<f2", 10: "<f4", 11: "<f8",
}  # fmt: skip
_CODE_OF = {np.dtype(v).str: k for k, v in DTYPE_CODES.items()}
#: field -> (dtype, number of dimensions) required by Mitsuba 3's ``measured`` plugin.
RGL_FIELDS: dict[str, tuple[str, int]] = {
    "description": ("u1", 1),
    "theta_i": ("<f4", 1),
    "phi_i": ("<f4", 1),
    "wavelengths": ("<f4", 1),
    "ndf": ("<f4", 2),
    "sigma": ("<f4", 2),
    "vndf": ("<f4", 4),
    "luminance": ("<f4", 4),
    "spectra": ("<f4", 5),
    "jacobian": ("u1", 1),
}


def is_rgl_path(name_or_path: str | None) -> bool:
    """True if a ``brdf_table`` value names an RGL ``.bsdf`` file (by its suffix)."""
    return name_or_path is not None and Path(str(name_or_path)).suffix.lower() == RGL_SUFFIX


def read_tensor_file(path: str | Path) -> dict[str, NDArray[np.generic]]:
    """All fields of a Mitsuba tensor file as numpy arrays (see the module doc for the layout)."""
    p = Path(path)
    raw = read_user_bytes(p, "brdf_table")
    if len(raw) < 18 or raw[:12] != _MAGIC:
        raise InputError(
            f"'{p}' is not a Mitsuba tensor file (it must start with 'tensor_file'); RGL "
            "measured materials are the .bsdf files of https://rgl.epfl.ch/materials",
            source=str(p),
        )
    if raw[12] != 1:
        raise InputError(f"'{p}': tensor file version {raw[12]} is not 1", source=str(p))
    (n_fields,) = struct.unpack_from("<I", raw, 14)
    pos, out = 18, {}
    try:
        for _ in range(n_fields):
            (n_name,) = struct.unpack_from("<H", raw, pos)
            name = raw[pos + 2 : pos + 2 + n_name].decode("utf-8", "replace")
            pos += 2 + n_name
            ndim, code, offset = struct.unpack_from("<HBQ", raw, pos)
            pos += 11
            shape = struct.unpack_from(f"<{ndim}Q", raw, pos)
            pos += 8 * ndim
            if code not in DTYPE_CODES:
                raise InputError(
                    f"'{p}': field '{name}' has unknown dtype code {code}", source=str(p)
                )
            dt = np.dtype(DTYPE_CODES[code])
            count = math.prod(shape)  # Python integers: a lying header cannot overflow
            if offset + count * dt.itemsize > len(raw):
                raise InputError(
                    f"'{p}': field '{name}' runs past the end of the file (truncated?)",
                    source=str(p),
                )
            out[name] = np.frombuffer(raw, dt, count, offset).reshape(shape)
    except struct.error:
        raise InputError(f"'{p}': tensor file header is truncated", source=str(p)) from None
    return out


def write_tensor_file(path: str | Path, fields: dict[str, NDArray[np.generic]]) -> None:
    """Write arrays as a Mitsuba tensor file (uint8/int/float types; data aligned to 8 bytes)."""
    arrays = {k: np.ascontiguousarray(v) for k, v in fields.items()}
    for k, a in arrays.items():
        if a.dtype.newbyteorder("<").str not in _CODE_OF:
            raise InputError(f"field '{k}': dtype {a.dtype} has no tensor-file code", field=k)
    header = len(_MAGIC) + 2 + 4
    header += sum(2 + len(k.encode()) + 11 + 8 * a.ndim for k, a in arrays.items())
    offset = (header + 7) // 8 * 8
    head = [_MAGIC, bytes([1, 0]), struct.pack("<I", len(arrays))]
    blobs = []
    for k, a in arrays.items():
        le = a.astype(a.dtype.newbyteorder("<"), copy=False)
        name = k.encode()
        code = _CODE_OF[le.dtype.str]
        head.append(struct.pack("<H", len(name)) + name + struct.pack("<HBQ", a.ndim, code, offset))
        head.append(struct.pack(f"<{a.ndim}Q", *a.shape))
        data = le.tobytes()
        pad = (-len(data)) % 8
        blobs.append(data + b"\0" * pad)
        offset += len(data) + pad
    body = b"".join(head)
    body += b"\0" * ((-len(body)) % 8)
    Path(path).write_bytes(body + b"".join(blobs))


@dataclass(frozen=True)
class RGLInfo:
    """Summary of a checked RGL ``.bsdf`` file."""

    path: str
    description: str
    isotropic: bool
    wavelength_nm: NDArray[np.float64]
    resolution: tuple[int, ...]


def _fail(path: str, what: str) -> InputError:
    return InputError(
        f"RGL material file '{path}' {what}; Mitsuba's 'measured' plugin needs the fields "
        f"{', '.join(RGL_FIELDS)} (an RGL database .bsdf file, doi:10.1145/3272127.3275059)",
        source=path,
        field="brdf_table",
    )


@cache
def load_rgl_info(path: str) -> RGLInfo:
    """Check an RGL ``.bsdf`` file as Mitsuba 3's ``measured`` plugin does; its summary.

    Raises
    ------
    InputError
        The file is missing, not a tensor file, or lacks a field, dtype or shape that the
        plugin requires (the message names the file and what is wrong).
    """
    if not Path(path).exists():
        raise InputError(
            f"RGL material file '{path}' does not exist (brdf_table ending in .bsdf must be the "
            "path of an RGL database file; relative paths are taken from the scenario's folder)",
            source=path,
            field="brdf_table",
        )
    f = read_tensor_file(path)
    _check_fields(path, f)
    what = _shape_problem(f)
    if what is not None:
        raise _fail(path, f"is malformed: {what}")
    n_w, spec = len(f["wavelengths"]), f["spectra"].shape
    wl = f["wavelengths"].astype(float)
    if n_w < 1 or not np.all(np.diff(wl) > 0):
        raise _fail(path, "has wavelengths that are not increasing")
    return RGLInfo(
        path=path,
        description=bytes(f["description"]).decode("utf-8", "replace"),
        isotropic=len(f["phi_i"]) <= 2,
        wavelength_nm=wl,
        resolution=tuple(int(s) for s in spec),
    )


def _shape_problem(f: dict[str, NDArray[np.generic]]) -> str | None:
    """Which array shapes do not fit together as the plugin needs (None: they do)."""
    n_p, n_t, n_w = len(f["phi_i"]), len(f["theta_i"]), len(f["wavelengths"])
    spec, lum, vndf = f["spectra"].shape, f["luminance"].shape, f["vndf"].shape
    checks = [
        (vndf[:2] == (n_p, n_t), f"vndf shape {vndf} must start with (phi_i, theta_i)"),
        (lum[:2] == (n_p, n_t) and lum[2] == lum[3],
         f"luminance shape {lum} must be (phi_i, theta_i, N, N)"),
        (spec[:3] == (n_p, n_t, n_w) and spec[3] == spec[4] and spec[3:] == lum[2:],
         f"spectra shape {spec} must be (phi_i, theta_i, wavelengths, N, N) with the N of "
         "luminance"),
        (f["jacobian"].shape == (1,), "jacobian must hold one uint8"),
        (min(n_t, n_w, spec[3], f["ndf"].shape[0], f["ndf"].shape[1], f["sigma"].shape[0],
             f["sigma"].shape[1], vndf[2], vndf[3]) >= 2 or n_t == 1,
         "its grids need at least 2 nodes per axis"),
    ]  # fmt: skip
    return next((what for ok, what in checks if not ok), None)


def _check_fields(path: str, f: dict[str, NDArray[np.generic]]) -> None:
    """Every field the plugin reads is there, with its dtype and number of dimensions."""
    missing = [k for k in RGL_FIELDS if k not in f]
    if missing and "rgb" in f:
        raise _fail(
            path,
            f"is an RGB material file (field 'rgb', no {', '.join(missing)}); Mitsuba's "
            "spectral 'measured' plugin needs the spectral version of the material",
        )
    if missing:
        raise _fail(path, f"lacks the field(s) {', '.join(missing)}")
    for k, (dt, ndim) in RGL_FIELDS.items():
        if f[k].dtype != np.dtype(dt):
            raise _fail(path, f"has field '{k}' of dtype {f[k].dtype}, not {np.dtype(dt)}")
        if f[k].ndim != ndim:
            raise _fail(path, f"has field '{k}' with {f[k].ndim} dimensions, not {ndim}")


def check_rgl_material(path: str, reflectance: Reflectance, field: str) -> RGLInfo:
    """Validate a ``measured`` material that uses an RGL file (called by ``Material``).

    The file must pass :func:`load_rgl_info` and be isotropic (the surface tangent of meshes
    and built-in shapes is undefined, so an anisotropic BRDF would have no orientation), and
    the reflectance must be a constant scale factor in (0, 1] (1: as measured).
    """
    info = load_rgl_info(path)
    if not info.isotropic:
        raise InputError(
            f"RGL material file '{path}' is anisotropic (phi_i has more than 2 nodes); only "
            "isotropic RGL files are supported, because target surfaces carry no tangent "
            "direction to orient it",
            source=path,
            field=f"{field}.brdf_table",
        )
    if reflectance.kind != "constant" or not 0.0 < float(reflectance.value) <= 1.0:
        raise InputError(
            f"an RGL .bsdf material takes reflectance as a constant scale factor in (0, 1] "
            f"(1 = as measured, the default), got a {reflectance.kind} reflectance; the file "
            "already holds the measured spectrum",
            source=path,
            field=f"{field}.reflectance",
        )
    return info
