"""Target stage: shapes, meshes, materials and spectral reflectances of the observed object."""

from speclight.target.from_values import material_from_spec, reflectance_from_spec, target_from_spec
from speclight.target.materials import BSDF_NAMES, BsdfName, Material
from speclight.target.mesh_io import load_mesh
from speclight.target.optical_constants import (
    CONDUCTORS,
    DIELECTRICS,
    fresnel_reflectance,
    refractive_index,
)
from speclight.target.parts import Part, Target, assign_materials
from speclight.target.reflectance import Reflectance
from speclight.target.shapes import CUBE_FACES, box_wing, cube, cylinder, plate, sphere

__all__ = [
    "BSDF_NAMES",
    "CONDUCTORS",
    "CUBE_FACES",
    "DIELECTRICS",
    "BsdfName",
    "Material",
    "Part",
    "Reflectance",
    "Target",
    "assign_materials",
    "box_wing",
    "cube",
    "cylinder",
    "fresnel_reflectance",
    "load_mesh",
    "material_from_spec",
    "plate",
    "reflectance_from_spec",
    "refractive_index",
    "sphere",
    "target_from_spec",
]
