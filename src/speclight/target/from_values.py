"""Build reflectances, materials and targets from plain scenario values (YAML-like dicts).

Accepted forms (docs/scenario.md): ``reflectance`` is a number, ``{file: path}``,
``{wavelength_nm: [...], value: [...]}``, ``{conductor: Al}`` or ``{dielectric: SiO2}``;
a material is ``{bsdf, reflectance, roughness?, diffuse_reflectance?, brdf_table?, extension?,
coefficients?}``; a shape is
``{builtin: sphere|plate|cube|cylinder|box_wing|bus_array, ...sizes}`` or
``{mesh_file: path}`` (or a list of PLY files). Unknown keys are errors with a did-you-mean.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from speclight.errors import InputError, did_you_mean
from speclight.target import shapes
from speclight.target.bsdf_models import BSDF_MODELS, PARAMETERS
from speclight.target.material_tables import material_table_path
from speclight.target.materials import Material
from speclight.target.mesh_io import load_mesh
from speclight.target.parts import Target
from speclight.target.reflectance import Reflectance

#: Built-in shapes: name -> (builder, its size keywords).
BUILTIN_SHAPES = {
    "sphere": (shapes.sphere, ("radius_m",)),
    "plate": (shapes.plate, ("width_m", "height_m")),
    "cube": (shapes.cube, ("edge_m",)),
    "cylinder": (shapes.cylinder, ("radius_m", "length_m")),
    "box_wing": (
        shapes.box_wing,
        ("bus_size_m", "wing_span_m", "wing_width_m", "wing_gap_m", "dish_radius_m",
         "dish_depth_m", "dish"),
    ),
    "bus_array": (shapes.bus_array, ("bus_size_m", "array_size_m", "array_gap_m")),
}  # fmt: skip
_MATERIAL_KEYS = ("bsdf", "reflectance", *PARAMETERS)


def _check_keys(d: Mapping[str, Any], allowed: tuple[str, ...], field: str) -> None:
    for k in d:
        if k not in allowed:
            raise InputError(
                f"unknown key '{k}'{did_you_mean(k, allowed)} (accepted: {', '.join(allowed)})",
                field=f"{field}.{k}",
            )


def _resolve(path: str, base_dir: Path | None) -> Path:
    p = Path(path)
    return p if p.is_absolute() or base_dir is None else base_dir / p


def reflectance_from_spec(
    spec: Any, *, field: str = "reflectance", base_dir: Path | None = None
) -> Reflectance:
    """A :class:`Reflectance` from a scenario value (see the module doc)."""
    if isinstance(spec, int | float) and not isinstance(spec, bool):
        return Reflectance.constant(spec, field=field)
    if isinstance(spec, Mapping):
        keys = set(spec)
        if keys == {"file"}:
            return Reflectance.table_file(_resolve(str(spec["file"]), base_dir), field=field)
        if keys == {"wavelength_nm", "value"}:
            return Reflectance.pairs(spec["wavelength_nm"], spec["value"], field=field)
        if keys == {"conductor"}:
            return Reflectance.conductor(str(spec["conductor"]))
        if keys == {"dielectric"}:
            return Reflectance.dielectric(str(spec["dielectric"]))
        if keys == {"table"}:
            return Reflectance.table_file(material_table_path(str(spec["table"])), field=field)
    raise InputError(
        f"reflectance {spec!r} is not understood; give a number in [0, 1], {{file: x.csv}}, "
        "{wavelength_nm: [...], value: [...]}, {conductor: Al|Ag|Au} or "
        "{dielectric: SiO2|Si|GaAs|Kapton} or {table: aluminium|kapton_mli|solar_cell|white_paint}",
        field=field,
    )


def material_from_spec(
    name: str, spec: Mapping[str, Any], *, base_dir: Path | None = None
) -> Material:
    """A :class:`Material` named ``name`` from ``{bsdf: ..., reflectance: ..., ...}``."""
    field = f"target.materials.{name}"
    if not isinstance(spec, Mapping) or "bsdf" not in spec:
        raise InputError("a material needs at least 'bsdf' and 'reflectance'", field=field)
    _check_keys(spec, _MATERIAL_KEYS, field)
    diffuse = spec.get("diffuse_reflectance")
    table = spec.get("brdf_table")
    if table is not None and Path(str(table)).suffix:
        table = str(_resolve(str(table), base_dir))
    model = BSDF_MODELS.get(str(spec["bsdf"]))  # an unknown name: Material says so
    return Material(
        name=name,
        bsdf=spec["bsdf"],
        reflectance=reflectance_from_spec(
            spec.get("reflectance", None if model is None else model.reflectance_default),
            field=f"{field}.reflectance",
            base_dir=base_dir,
        ),
        roughness=None if spec.get("roughness") is None else float(spec["roughness"]),
        diffuse_reflectance=None
        if diffuse is None
        else reflectance_from_spec(
            diffuse, field=f"{field}.diffuse_reflectance", base_dir=base_dir
        ),
        brdf_table=None if table is None else str(table),
        extension=spec.get("extension"),
        coefficients=spec.get("coefficients"),
    )


def target_from_spec(
    shape: Mapping[str, Any],
    materials: Mapping[str, Mapping[str, Any]],
    *,
    base_dir: Path | None = None,
) -> Target:
    """A :class:`Target` from the scenario's ``target.shape`` and ``target.materials``."""
    mats = {k: material_from_spec(k, v, base_dir=base_dir) for k, v in materials.items()}
    if "mesh_file" in shape:
        _check_keys(shape, ("mesh_file", "scale_m_per_unit"), "target.shape")
        files = shape["mesh_file"]
        paths = [files] if isinstance(files, str) else list(files)
        return load_mesh(
            [_resolve(str(p), base_dir) for p in paths],
            mats,
            scale_m_per_unit=float(shape.get("scale_m_per_unit", 1.0)),
        )
    kind = shape.get("builtin")
    if kind not in BUILTIN_SHAPES:
        raise InputError(
            f"target.shape needs 'builtin' ({', '.join(BUILTIN_SHAPES)}) or 'mesh_file'; got "
            f"{kind!r}{did_you_mean(str(kind), BUILTIN_SHAPES)}",
            field="target.shape.builtin",
        )
    builder, sizes = BUILTIN_SHAPES[kind]
    _check_keys(shape, ("builtin", *sizes), "target.shape")
    kwargs = {
        k: (tuple(v) if isinstance(v, list) else v) for k, v in shape.items() if k != "builtin"
    }
    try:
        return builder(materials=mats, **kwargs)  # type: ignore[operator]
    except TypeError as exc:
        raise InputError(
            f"builtin '{kind}' needs {', '.join(sizes)}: {exc}", field="target.shape"
        ) from None
