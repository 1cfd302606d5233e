"""Scenario models for the target, illumination, atmosphere, spectrum, render and instrument.

These are the scenario sections (docs/scenario.md) that later stages consume. They validate shapes,
ranges and names here so that a scenario fails early, before any epoch is computed.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    Discriminator,
    Field,
    PrivateAttr,
    Tag,
    field_validator,
    model_validator,
)

from speclight.instrument.bands import MAX_GAUSSIAN_NM
from speclight.scenario.sections_geometry import Strict, Vector3
from speclight.scenario.sections_imaging import Imaging
from speclight.target.bsdf_models import (
    MAX_ROUGHNESS,
    PARAMETERS,
    BsdfModel,
    BsdfName,
    bsdf_model,
    parameter_problems,
)

ConductorName = Literal["Al", "Ag", "Au"]
DielectricName = Literal["SiO2", "Si", "GaAs", "Kapton"]
#: Shipped reflectance tables (``data/materials``, :mod:`speclight.target.material_tables`).
MaterialTableName = Literal["aluminium", "kapton_mli", "solar_cell", "white_paint"]
BuiltinShape = Literal["sphere", "plate", "cube", "cylinder", "box_wing", "bus_array"]

#: Largest ``render.seed``: Mitsuba's sampler seed is a 32-bit unsigned integer (path mode
#: hashes the run's seed, the epoch and the launch into one, :mod:`speclight.render.path_sampling`;
#: the grouped reference reduces its per-pass seeds modulo 2**32).
MAX_RENDER_SEED = 2**32 - 1
#: Largest ``instrument.noise.seed``: numpy's ``SeedSequence`` takes any integer >= 0, the
#: NetCDF writer (h5netcdf) stores integer attributes up to uint64; 2**64 failed at write time.
MAX_NOISE_SEED = 2**64 - 1


class ReflectanceFile(Strict):
    file: str = Field(description="CSV of wavelength and reflectance (header names the units)")


class ReflectancePairs(Strict):
    wavelength_nm: list[float] = Field(min_length=2)
    value: list[float] = Field(min_length=2)

    @model_validator(mode="after")
    def _pairs(self) -> ReflectancePairs:
        if len(self.wavelength_nm) != len(self.value):
            raise ValueError(
                f"wavelength_nm has {len(self.wavelength_nm)} values but value has "
                f"{len(self.value)}; give one reflectance per wavelength"
            )
        if any(b <= a for a, b in zip(self.wavelength_nm, self.wavelength_nm[1:], strict=False)):
            raise ValueError("wavelength_nm must increase strictly")
        if any(not 0.0 <= v <= 1.0 for v in self.value):
            raise ValueError(f"reflectance values must lie in [0, 1], got {self.value}")
        return self


class Conductor(Strict):
    conductor: ConductorName


class Dielectric(Strict):
    dielectric: DielectricName


class ShippedTable(Strict):
    table: MaterialTableName = Field(description="A shipped reflectance table (data/materials)")


REFLECTANCE_FORMS = (
    "a number in [0, 1], {file: table.csv}, {wavelength_nm: [...], value: [...]}, "
    "{conductor: Al|Ag|Au}, {dielectric: SiO2|Si|GaAs|Kapton} or "
    "{table: aluminium|kapton_mli|solar_cell|white_paint}"
)


def _reflectance_form(value: Any) -> str | None:
    if isinstance(value, int | float) and not isinstance(value, bool):
        return "number"
    if isinstance(value, dict):
        for key, tag in (
            ("file", "file"),
            ("wavelength_nm", "pairs"),
            ("value", "pairs"),
            ("conductor", "conductor"),
            ("dielectric", "dielectric"),
            ("table", "table"),
        ):
            if key in value:
                return tag
    if isinstance(value, BaseModel):
        return {
            ReflectanceFile: "file",
            ReflectancePairs: "pairs",
            Conductor: "conductor",
            Dielectric: "dielectric",
            ShippedTable: "table",
        }.get(type(value))
    return None


Reflectance = Annotated[
    Annotated[float, Tag("number")]
    | Annotated[ReflectanceFile, Tag("file")]
    | Annotated[ReflectancePairs, Tag("pairs")]
    | Annotated[Conductor, Tag("conductor")]
    | Annotated[Dielectric, Tag("dielectric")]
    | Annotated[ShippedTable, Tag("table")],
    Discriminator(
        _reflectance_form,
        custom_error_type="reflectance_form",
        custom_error_message=f"not a reflectance; give {REFLECTANCE_FORMS}",
    ),
]


class Material(Strict):
    """A surface material: a BSDF model and its spectral reflectance."""

    bsdf: BsdfName
    reflectance: Reflectance = Field(
        default=1.0,
        description="Albedo (lambertian, measured scale) or Fresnel reflectance (microfacet, "
        "specular); for plastic the coat's dielectric",
    )
    roughness: float | None = Field(
        default=None,
        gt=0,
        le=MAX_ROUGHNESS,
        description="Microfacet alpha (beckmann, ggx; plastic coat)",
    )
    diffuse_reflectance: Reflectance | None = Field(
        default=None, description="Diffuse base of a plastic/coated layer"
    )
    brdf_table: str | None = Field(
        default=None,
        description="Measured BRDF: a shipped table name, a CSV file "
        "(columns phi_i theta_i phi_o theta_o brdf) or a spectral RGL .bsdf file",
    )
    extension: str | None = Field(
        default=None,
        description="Measured lab table: the analytic model fitted to it that holds outside "
        "its support (microfacet, phong, abg, binomial; default microfacet)",
    )
    coefficients: dict[str, Any] | None = Field(
        default=None,
        description="Analytic models (phong, abg, binomial, microfacet): their coefficients "
        "(docs/brdf-models.md; speclight brdf-fit writes them)",
    )

    @model_validator(mode="after")
    def _params(self) -> Material:
        if isinstance(self.reflectance, float) and not 0.0 <= self.reflectance <= 1.0:
            raise ValueError(f"reflectance = {self.reflectance} must lie in [0, 1]")
        kind = _reflectance_kind(self.reflectance)
        problems = parameter_problems(self.bsdf, self.parameters(), kind)
        if problems:
            raise ValueError(problems[0][1])
        return self

    def parameters(self) -> dict[str, Any]:
        """The model parameters given (:data:`speclight.target.bsdf_models.PARAMETERS`)."""
        given = {name: getattr(self, name) for name in PARAMETERS}
        given["brdf_table"] = self.brdf_table or None  # an empty name is none
        return given

    @property
    def model(self) -> BsdfModel:
        """The material's entry (its form) in the table of BSDF models."""
        return bsdf_model(self.bsdf, self.parameters())


def _reflectance_kind(value: Any) -> str:
    """The :class:`~speclight.target.Reflectance` kind a validated reflectance becomes."""
    if isinstance(value, Conductor | Dielectric):
        return "conductor" if isinstance(value, Conductor) else "dielectric"
    return "constant" if isinstance(value, float) else "table"


_SHAPE_SIZES: dict[str, tuple[str, ...]] = {
    "sphere": ("radius_m",),
    "plate": ("width_m", "height_m"),
    "cube": ("edge_m",),
    "cylinder": ("radius_m", "length_m"),
    "box_wing": (
        "bus_size_m",
        "wing_span_m",
        "wing_width_m",
        "wing_gap_m",
        "dish_radius_m",
        "dish_depth_m",
        "dish",
    ),
    "bus_array": ("bus_size_m", "array_size_m", "array_gap_m"),
}
_SHAPE_REQUIRED: dict[str, tuple[str, ...]] = {
    "sphere": ("radius_m",),
    "plate": ("width_m", "height_m"),
    "cube": ("edge_m",),
    "cylinder": ("radius_m", "length_m"),
    "box_wing": (),
    "bus_array": (),
}


class Shape(Strict):
    """A built-in shape with its dimensions, or a mesh file (OBJ, or PLY files one per part)."""

    builtin: BuiltinShape | None = None
    mesh_file: str | list[str] | None = None
    scale_m_per_unit: float = Field(default=1.0, gt=0, description="Mesh units to metres")
    radius_m: float | None = Field(default=None, gt=0)
    width_m: float | None = Field(default=None, gt=0)
    height_m: float | None = Field(default=None, gt=0)
    length_m: float | None = Field(default=None, gt=0)
    edge_m: float | None = Field(default=None, gt=0)
    bus_size_m: Vector3 | None = None
    wing_span_m: float | None = Field(default=None, gt=0)
    wing_width_m: float | None = Field(default=None, gt=0)
    wing_gap_m: float | None = Field(default=None, ge=0)
    dish_radius_m: float | None = Field(default=None, gt=0)
    dish_depth_m: float | None = Field(default=None, gt=0)
    dish: bool | None = Field(default=None, description="box_wing: false leaves out the dish")
    array_size_m: Annotated[list[float], Field(min_length=2, max_length=2)] | None = None
    array_gap_m: float | None = Field(default=None, ge=0)

    @field_validator("builtin", mode="before")
    @classmethod
    def _alias(cls, value: Any) -> Any:
        return "box_wing" if value == "box-wing" else value

    @model_validator(mode="after")
    def _one(self) -> Shape:
        if (self.builtin is None) == (self.mesh_file is None):
            raise ValueError("give exactly one of builtin or mesh_file")
        sizes = [k for k in _SHAPE_FIELDS if getattr(self, k) is not None]
        if self.builtin is None:
            if sizes:
                raise ValueError(f"{', '.join(sizes)} apply to builtin shapes, not mesh_file")
            return self
        _check_sizes(self.builtin, sizes, [k for k in _SHAPE_FIELDS if getattr(self, k) is None])
        _check_dish(self.dish, self.dish_radius_m, self.dish_depth_m)
        _check_scale(self.builtin, {k: getattr(self, k) for k in sizes})
        return self


def _check_dish(dish: bool | None, radius_m: float | None, depth_m: float | None) -> None:
    """No dish sizes for a box-wing without its dish."""
    if dish is False and (radius_m or depth_m):
        raise ValueError("dish: false leaves out the dish; drop dish_radius_m, dish_depth_m")


def _check_sizes(builtin: str, given: list[str], left_out: list[str]) -> None:
    """A built-in shape's sizes: every one it needs, none it does not take."""
    missing = [k for k in _SHAPE_REQUIRED[builtin] if k in left_out]
    if missing:
        raise ValueError(f"builtin '{builtin}' needs {', '.join(missing)}")
    extra = [k for k in given if k not in _SHAPE_SIZES[builtin]]
    if extra:
        raise ValueError(
            f"builtin '{builtin}' takes {', '.join(_SHAPE_SIZES[builtin])}, not {', '.join(extra)}"
        )


def _check_scale(builtin: str, sizes: dict[str, Any]) -> None:
    """Refuse a built-in shape whose bounding radius is out of any space object's scale.

    The limits are the mesh reader's (:data:`~speclight.target.mesh_io.MIN_BOUNDING_RADIUS_M`
    .. :data:`~speclight.target.mesh_io.MAX_BOUNDING_RADIUS_M`, 1 mm to 100 km): outside
    them a size is in a wrong unit, and Dr.Jit's single-precision ray tracing aborts the
    process (a 1e-12 m cube, a 1e9 m wing gap). The radius is that of the shape as built
    (:meth:`~speclight.target.parts.Target.bounding_sphere`; the defaults filled in), so no
    size formula is repeated here; building a built-in shape takes well under a millisecond.
    """
    from speclight.target import Material as TargetMaterial
    from speclight.target import Reflectance as TargetReflectance
    from speclight.target.from_values import BUILTIN_SHAPES
    from speclight.target.mesh_io import MAX_BOUNDING_RADIUS_M, MIN_BOUNDING_RADIUS_M

    builder, _ = BUILTIN_SHAPES[builtin]
    white = TargetReflectance.constant(1.0)
    probe = TargetMaterial(name="probe", bsdf="lambertian", reflectance=white)
    kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in sizes.items()}
    with np.errstate(all="ignore"):  # sizes near 1e308 overflow to inf: refused below
        _, radius = builder(materials=probe, **kwargs).bounding_sphere()  # type: ignore[operator]
    if not MIN_BOUNDING_RADIUS_M <= radius <= MAX_BOUNDING_RADIUS_M:
        given = ", ".join(f"{k} = {v}" for k, v in sizes.items()) or "its default sizes"
        raise ValueError(
            f"builtin '{builtin}' has a bounding radius {radius:.3g} m ({given}); accepted: "
            f"{MIN_BOUNDING_RADIUS_M:g} to {MAX_BOUNDING_RADIUS_M:g} m (a 1 mm fragment to "
            "100 km): check the unit of the sizes (metres)"
        )


_SHAPE_FIELDS = sorted({k for sizes in _SHAPE_SIZES.values() for k in sizes})


class Joint(Strict):
    """An articulated part: turned about a body axis to track the Sun, or by a table."""

    axis: Vector3 = Field(description="Hinge axis, body frame (normalised)")
    hinge_point_m: Vector3 = Field(
        default_factory=lambda: [0.0, 0.0, 0.0], description="A point on the hinge [m]"
    )
    normal: Vector3 = Field(description="The part's normal at angle 0 (not along the axis)")
    mode: Literal["sun_tracking", "table"] = "sun_tracking"
    table_file: str | None = Field(default=None, description="CSV time_utc,angle_deg")

    @model_validator(mode="after")
    def _check(self) -> Joint:
        a, n = np.asarray(self.axis, float), np.asarray(self.normal, float)
        if not np.linalg.norm(a) > 0:
            raise ValueError(f"axis {self.axis} must be non-zero")
        a = a / np.linalg.norm(a)
        if not np.linalg.norm(n - a * (n @ a)) > 1e-6 * np.linalg.norm(n):
            raise ValueError(
                f"normal {self.normal} must be non-zero and not parallel to axis {self.axis}"
            )
        if (self.mode == "table") != (self.table_file is not None):
            raise ValueError("table_file is needed by mode 'table' and used only by it")
        return self


class Target(Strict):
    shape: Shape
    materials: dict[str, Material] = Field(
        min_length=1, description="Part name -> material; '*' covers the parts not named"
    )
    articulation: dict[str, Joint] = Field(
        default_factory=dict, description="Part name -> its hinge (docs/scenario.md)"
    )
    articulation_step_deg: float = Field(
        default=0.5,
        ge=0,
        le=10,
        description="Joint angles are rounded to this step to share one scene (0: exact)",
    )


class Laser(Strict):
    """A ground laser transmitter."""

    name: str
    latitude_deg: float = Field(ge=-90, le=90)
    longitude_deg: float = Field(ge=-180, le=360)
    altitude_m: float = Field(default=0.0, ge=-500, le=9000)
    wavelength_nm: float = Field(gt=0)
    linewidth_nm: float = Field(default=0.1, gt=0)
    spectrum_file: str | None = None
    power_w: float = Field(gt=0, description="Average optical power [W]")
    repetition_rate_hz: float = Field(gt=0)
    divergence_arcsec: float = Field(gt=0, le=36000, description="Full divergence angle [arcsec]")
    pointing_offset_arcsec: float = Field(
        default=0.0, ge=0, le=3600, description="Angle between the beam axis and the target"
    )
    beam_profile: Literal["gaussian", "tophat"] = "gaussian"
    min_elevation_deg: float = Field(
        default=0.0, ge=-5, le=90, description="The transmitter's own horizon limit [deg]"
    )

    @model_validator(mode="after")
    def _physics(self) -> Laser:
        # the rules of speclight.illumination.laser, applied once here (a divergence below the
        # diffraction limit is an angle in the wrong unit); later stages take the values as is
        from speclight.errors import InputError
        from speclight.illumination import laser as lz

        try:
            lz.check_power_w(self.power_w)
            lz.check_repetition_rate_hz(self.repetition_rate_hz)
            lz.check_divergence_arcsec(self.divergence_arcsec, self.wavelength_nm)
        except InputError as exc:
            raise ValueError(exc.message) from None
        return self


class Earthshine(Strict):
    """Sunlight reflected by the Earth (a grey Lambertian sphere) onto the target."""

    albedo: float = Field(default=0.3, ge=0.0, le=1.0, description="The Earth's albedo [1]")
    samples: int = Field(
        default=64,
        ge=4,
        le=4096,
        description="Cells of the visible Earth cap, each one directional source (one more "
        "render per epoch each; 64: about 3 % accuracy)",
    )


class Illumination(Strict):
    sun: bool = True
    solar_disk: bool = Field(
        default=False,
        description="Path mode: the Sun as its 0.53 deg disk (for smooth mirror glints)",
    )
    lasers: list[Laser] = Field(default_factory=list)
    earthshine: Earthshine | None = Field(
        default=None, description="Sunlight reflected by the Earth (off when absent)"
    )


class Atmosphere(Strict):
    """The atmosphere model and its parameters.

    The parameters' ranges and names are those of :mod:`speclight.atmosphere.params`, which
    checks them when the scenario is loaded (:attr:`params`); the stages use the result.
    """

    model: Literal["none", "spectrl2", "6s", "table"] = "spectrl2"
    water_vapour_cm: float = 1.42
    ozone_atm_cm: float = 0.344
    aod_500nm: float = 0.1
    angstrom_exponent: float = 1.14
    atmosphere_profile: str = Field(
        default="user",
        description="6S gas profile; 'user' takes water_vapour_cm and ozone_atm_cm",
    )
    aerosol_profile: str = "continental"
    table_file: str | None = None
    fallback_to_spectrl2: bool = False
    _params: Any = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _table(self) -> Atmosphere:
        if self.model == "table" and not self.table_file:
            raise ValueError("model 'table' needs table_file: a CSV of wavelength_nm x airmass")
        from speclight.atmosphere.params import model_keys, parse_params
        from speclight.errors import InputError

        try:
            self._params = parse_params(
                self.model, {k: getattr(self, k) for k in model_keys(self.model, type(self))}
            )
        except InputError as exc:
            raise ValueError(exc.message) from None
        return self

    @property
    def params(self) -> Any:
        """The validated :class:`speclight.atmosphere.params.AtmosphereParams` (paths as
        written; :func:`speclight.simulation.radiometry.atmosphere_params` resolves them)."""
        return self._params


class Spectrum(Strict):
    min_nm: float = Field(default=300.0, ge=200, le=4000)
    max_nm: float = Field(default=1240.0, ge=200, le=4000)
    step_nm: float = Field(default=5.0, gt=0, le=500)

    @model_validator(mode="after")
    def _order(self) -> Spectrum:
        if self.max_nm < self.min_nm:
            raise ValueError(f"max_nm = {self.max_nm} must be >= min_nm = {self.min_nm}")
        return self


#: Most path-mode samples per pixel: the Monte Carlo noise falls as spp**-0.5 from 4.1 % per
#: 5 nm bin and epoch at 16 spp (BENCHMARKS.md, "Rendering"), to 0.064 % at 65536, below any
#: measurement's precision; more only costs time.
MAX_SAMPLES_PER_PIXEL = 65_536
#: Path-mode samples traced per second (box-wing, coated, ``llvm_ad_spectral``, 128 px,
#: 2 cores: BENCHMARKS.md "Path mode", 64 -> 256 spp adds 3.1e6 samples in 0.26 s per epoch,
#: 1.2e7 samples/s, under load from other processes; rounded down).
PATH_SAMPLES_PER_S = 1.0e7
#: Fixed path-mode cost per epoch [s] (the Sun's update, one launch, the bin sums: the same
#: measurement, extrapolated to 0 spp).
PATH_SECONDS_PER_EPOCH = 0.02


class Render(Strict):
    mode: Literal["single", "path", "map"] = "single"
    map_file: str | None = Field(
        default=None,
        description="mode map: a reflectivity map (Zarr store of speclight reflectivity-map) "
        "interpolated instead of rendering",
    )
    resolution_px: int = Field(default=256, ge=8, le=8192)
    samples_per_pixel: int = Field(default=16, ge=1)
    seed: int = Field(default=0, ge=0, le=MAX_RENDER_SEED)
    variant: str | None = Field(default=None, description="Force a Mitsuba variant")
    save_images_at: list[int] = Field(
        default_factory=list, description="Epoch indices whose images and depth maps are saved"
    )
    per_material: bool = Field(
        default=False,
        description="Also write reflectance_factor_material(time, material, band): each "
        "material's share of the band reflectance factors (single mode only)",
    )
    polarization: bool = Field(
        default=False,
        description="Also compute Stokes Q, U, V (north-east sky frame) and the degree and "
        "angle of linear polarisation per band (modes single and path; docs/polarization.md)",
    )

    @model_validator(mode="after")
    def _samples(self) -> Render:
        if (self.mode == "map") != (self.map_file is not None):
            raise ValueError(
                "mode: map needs map_file (a store written by speclight reflectivity-map), "
                "and map_file needs mode: map"
            )
        if self.mode == "map" and self.save_images_at:
            raise ValueError("save_images_at needs mode single or path: mode map renders nothing")
        if self.polarization and self.mode == "map":
            raise ValueError(
                "polarization: true needs mode single or path: a reflectivity map (mode: map) "
                "holds intensity only"
            )
        if self.per_material and self.mode != "single":
            raise ValueError(
                f"per_material: true needs mode: single (got mode: {self.mode}); the shares "
                "come from single-scattering renders of each material alone"
            )
        if self.samples_per_pixel > MAX_SAMPLES_PER_PIXEL:
            samples = self.resolution_px**2 * self.samples_per_pixel
            per_epoch_s = PATH_SECONDS_PER_EPOCH + samples / PATH_SAMPLES_PER_S
            raise ValueError(
                f"samples_per_pixel = {self.samples_per_pixel} would take about "
                f"{per_epoch_s:.3g} s per epoch at {self.resolution_px} px "
                f"({PATH_SAMPLES_PER_S:.2g} samples/s); accepted: at most "
                f"{MAX_SAMPLES_PER_PIXEL} (0.06 % Monte Carlo noise per bin and epoch)"
            )
        return self


SpectralCurve = float | str | ReflectanceFile


def _fraction(value: SpectralCurve | None) -> SpectralCurve | None:
    """A curve given as one number must be a fraction (checked at load, as the instrument
    stage would at run time: a sweep validates every case up front)."""
    if isinstance(value, float | int) and not 0.0 <= float(value) <= 1.0:
        raise ValueError(f"{value!r} must be a fraction in 0..1 (write 0.85, not 85)")
    return value


class GaussianBand(Strict):
    # the instrument stage's bound (a band wider than 100 um is flat across any grid)
    center_nm: float = Field(gt=0, le=MAX_GAUSSIAN_NM)
    sigma_nm: float = Field(gt=0, le=MAX_GAUSSIAN_NM)


class Band(Strict):
    name: str
    gaussian: GaussianBand | None = None
    filter: str | None = Field(default=None, description="speclite filter name, e.g. bessell-V")
    file: str | None = Field(default=None, description="CSV of wavelength and response")
    detector_qe: SpectralCurve | None = Field(
        default=None, description="This band's detector, if not instrument.detector_qe"
    )
    _qe_fraction = field_validator("detector_qe")(_fraction)

    @model_validator(mode="after")
    def _one(self) -> Band:
        given = [k for k in ("gaussian", "filter", "file") if getattr(self, k) is not None]
        if len(given) > 1:
            raise ValueError(f"give one of gaussian, filter, file (found {', '.join(given)})")
        if not given and not self.name.startswith("G-"):
            raise ValueError(
                f"band '{self.name}' needs gaussian, filter or file (or a name G-<centre>/<sigma>)"
            )
        return self


#: The elementary charge [C] (exact, SI 2019; CODATA 2018).
ELEMENTARY_CHARGE_C = 1.602176634e-19
#: Largest dark current summed over the photometric aperture [e- s-1]: 1 uA, three decades
#: above an uncooled large-area silicon or InGaAs photodiode (~1 nA) and far above any
#: photon-counting sensor; a larger value is a unit mistake (A or e- per hour for e- s-1).
MAX_DARK_CURRENT_E_PER_S = 1e-6 / ELEMENTARY_CHARGE_C
#: Largest read noise of the whole aperture [e- rms]: the noisiest scientific sensors read
#: ~100 e- rms per pixel, and 1e6 pixels summed (sqrt N) give 1e5; one decade of room.
MAX_READ_NOISE_E = 1e6
#: Largest photometric aperture radius [arcsec]: 180 deg, half a great circle.
MAX_APERTURE_RADIUS_ARCSEC = 180 * 3600.0
#: Longest exposure [s]: one day; a ground site cannot expose longer in one night.
MAX_EXPOSURE_S = 86_400.0


class Noise(Strict):
    enabled: bool = True
    seed: int = Field(default=0, ge=0, le=MAX_NOISE_SEED)
    sky_background_mag_arcsec2: float = Field(default=21.0, ge=10, le=30)
    aperture_radius_arcsec: float = Field(default=3.0, gt=0, le=MAX_APERTURE_RADIUS_ARCSEC)
    dark_current_e_per_s: float = Field(default=0.0, ge=0, le=MAX_DARK_CURRENT_E_PER_S)
    read_noise_e: float = Field(default=0.0, ge=0, le=MAX_READ_NOISE_E)


class Instrument(Strict):
    optics_transmission: SpectralCurve = 1.0
    detector_qe: SpectralCurve = 1.0
    exposure_s: float = Field(default=1.0, gt=0, le=MAX_EXPOSURE_S)
    bands: list[Band] = Field(default_factory=list)
    noise: Noise | None = None
    imaging: Imaging | None = Field(
        default=None, description="Detector frames (speclight frames; docs/frames.md)"
    )
    _fractions = field_validator("optics_transmission", "detector_qe")(_fraction)
