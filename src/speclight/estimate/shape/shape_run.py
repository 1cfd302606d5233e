"""``speclight shape``: from light curves to the convex shape, sidereal period and pole.

Steps (docs/shape.md):

1. the light curves in (:mod:`.shape_inputs`): DAMIT ``.lc``, or speclight's with the
   scenario's geometry;
2. the period scan (:mod:`.period_scan`) on the coarse facet set (``search_nside``);
3. the pole map and its refined minima and mirror (:mod:`.pole_search`), coarse facets;
4. the best and the mirror refined on the fine facets (``nside``), everything free;
5. uncertainties (:mod:`.uncertainty`): covariance, optional bootstrap, mirror, null tests;
6. the polyhedron of the best EGI (:mod:`.minkowski`);
7. with several bands: the facets' band factors with the geometry held, and with a scenario
   and the Lambert law their split into its materials (:mod:`.facet_spectra`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.shape.convex_fit import ConvexSolution, fit_convex
from speclight.estimate.shape.convex_model import N_ROTATION, ConvexModel
from speclight.estimate.shape.egi import facet_normals
from speclight.estimate.shape.facet_spectra import facet_band_factors, facet_materials
from speclight.estimate.shape.minkowski import Polyhedron, minkowski_polyhedron
from speclight.estimate.shape.period_scan import (
    N_START_POLES,
    PeriodScan,
    period_grid_h,
    scan_periods,
)
from speclight.estimate.shape.pole_search import (
    DISTINCT_DEG,
    PoleSearch,
    distinct_solutions,
    nearest_solution,
    pole_distance_deg,
    search_poles,
)
from speclight.estimate.shape.scattering import ScatteringLaw, scattering_law
from speclight.estimate.shape.shape_inputs import ShapeInput
from speclight.estimate.shape.uncertainty import (
    Covariance,
    bootstrap,
    covariance,
    mirror_ambiguous,
    shape_p_value,
    spans,
)

F64 = NDArray[np.float64]
NULL_P_VALUE = 1e-3
BLAS_THREADS = 1
#: Steps of a fit on the fine facets: the best and its mirror are compared by their
#: chi-square, so both must end at their minimum (192 facets take up to about 70 steps).
REFINE_ITERATIONS = 150


@dataclass(frozen=True)
class ShapeOptions:
    """Options of :func:`run_shape` (the plain-array names of the CLI's flags).

    Attributes
    ----------
    min_period_h, max_period_h
        Period range scanned [h].
    law
        Scattering law name (:data:`.scattering.LAW_NAMES`) or ``material:NAME`` (a
        material of the scenario); ``"auto"``: ``ls-lambert`` for DAMIT files, ``lambert``
        for speclight's.
    lambert_weight
        Lambert weight ``c`` of ``ls-lambert``.
    nside, search_nside
        HEALPix resolution of the final EGI and of the scan and pole map.
    pole_step_deg
        Pole-map grid step [deg].
    n_start_poles
        Poles each trial period starts from.
    bootstrap_draws
        Bootstrap refits (0: none).
    seed
        Seed of the bootstrap.
    wavelength_nm
        Wavelength of a material law [nm].
    progress
        Show progress bars.
    workers
        Processes the period scan is shared among (None: every core this process may use;
        :func:`.period_scan.scan_periods`).
    """

    min_period_h: float
    max_period_h: float
    law: str = "auto"
    lambert_weight: float = 0.1
    nside: int = 4
    search_nside: int = 2
    pole_step_deg: float = 30.0
    n_start_poles: int = N_START_POLES
    bootstrap_draws: int = 0
    seed: int = 0
    wavelength_nm: float = 550.0
    progress: bool = False
    workers: int | None = None


@dataclass(frozen=True)
class ShapeRun:
    """Everything :func:`run_shape` found (fields as named; ``model`` is the fine one).

    ``best`` has the lowest chi-square of all refined solutions; ``mirror`` is the solution
    at its mirror pole, a minimum of its own when ``mirror_is_minimum`` (else the fit with
    the pole held there); ``others`` are the other distinct refined minima."""

    inputs: ShapeInput
    options: ShapeOptions
    law: ScatteringLaw
    model: ConvexModel
    scan: PeriodScan
    poles: PoleSearch
    best: ConvexSolution
    mirror: ConvexSolution
    others: list[ConvexSolution]
    cov: Covariance
    mirror_cov: Covariance
    samples: F64
    sample_areas: F64
    shape_p: float
    mirror_reported: bool
    pole_constrained: bool
    period_constrained: bool
    polyhedron: Polyhedron | None
    band_factor: F64 | None
    seconds: float
    materials: tuple[list[str], F64] | None = None
    mirror_is_minimum: bool = True

    @property
    def equivalent_minima(self) -> list[ConvexSolution]:
        """Other refined pole minima (not the mirror) whose chi-square is within the mirror's
        bound of the best (:func:`.uncertainty.mirror_ambiguous`): poles the data do not
        separate from the best either."""
        return [m for m in self.others if mirror_ambiguous(self.best, m, self.cov)]

    @property
    def shape_constrained(self) -> bool:
        """True when the fit beats a sphere at p < :data:`NULL_P_VALUE`."""
        return self.shape_p < NULL_P_VALUE


def resolve_law(options: ShapeOptions, inputs: ShapeInput) -> ScatteringLaw:
    """The scattering law of ``options.law`` (``auto`` and ``material:NAME`` resolved)."""
    name = options.law
    if name == "auto":
        name = "lambert" if inputs.unit == "m2 sr-1" else "ls-lambert"
    if name.startswith("material:"):
        material = name.split(":", 1)[1]
        if inputs.loaded is None or inputs.loaded.scenario.target is None:
            raise InputError(f"law '{name}' needs a scenario with that material", field="law")
        from speclight.target.from_values import material_from_spec

        mats = inputs.loaded.scenario.target.model_dump()["materials"]
        if material not in mats:
            raise InputError(
                f"law '{name}': no material '{material}' in the scenario "
                f"(materials: {', '.join(mats)})",
                field="law",
            )
        m = material_from_spec(material, mats[material], base_dir=inputs.loaded.base_dir)
        return scattering_law("material", material=m, wavelength_nm=options.wavelength_nm)
    return scattering_law(name, lambert_weight=options.lambert_weight)


def _refine_fine(
    model: ConvexModel, coarse: ConvexModel, sol: ConvexSolution, free_pole: bool = True
) -> ConvexSolution:
    """Refit ``sol`` on the fine facets from its pole and period, twice: the areas starting
    from its nearest coarse facet's area (divided by the number of fine facets per coarse
    one), and from a sphere; the lower chi-square is kept. The coarse start is blocky (each
    coarse facet's area on every fine facet around it), and on DAMIT's example data (43
    Ariadne) the sphere start ended lower in fewer steps (3182 against 3193 after 150 steps),
    as Kaasalainen, Torppa & Muinonen 2001 (sec. 2.3) found the sphere start as good as any."""
    nearest = np.argmax(model.normals @ coarse.normals.T, axis=1)
    ratio = len(model.normals) / len(coarse.normals)
    starts = (sol.theta[N_ROTATION:][nearest] - np.log(ratio), None)
    fits = [
        fit_convex(
            model,
            sol.lambda_deg,
            sol.beta_deg,
            sol.period_h,
            log_areas=g,
            free_pole=free_pole,
            max_iterations=REFINE_ITERATIONS,
        )
        for g in starts
    ]
    return min(fits, key=lambda f: f.chi2)


def _mirror(
    fine: ConvexModel, coarse: ConvexModel, best: ConvexSolution, others: list[ConvexSolution]
) -> tuple[ConvexSolution, bool]:
    """The solution at the mirror pole ``(lambda + 180, beta)`` of ``best`` and whether it
    is a minimum: a refined minimum near it (:func:`.pole_search.nearest_solution`), else a
    fit from it (areas and period first, the pole held, then everything free); when that
    fit leaves the mirror pole for another minimum, or ends in the best's own (for a pole
    near the ecliptic pole the mirror is close to it), the fit with the pole held there."""
    lam, bet = best.lambda_deg + 180.0, best.beta_deg
    found = nearest_solution(others, lam, bet)
    if found is not None:
        return found, True
    held = fit_convex(coarse, lam, bet, best.period_h, free_pole=False)
    free = _refine_fine(fine, coarse, held)
    if (
        pole_distance_deg(free, lam, bet) < DISTINCT_DEG
        and pole_distance_deg(free, best.lambda_deg, best.beta_deg) >= DISTINCT_DEG
    ):
        return free, True
    return _refine_fine(fine, coarse, held, free_pole=False), False


def run_shape(inputs: ShapeInput, options: ShapeOptions) -> ShapeRun:
    """Convex inversion of ``inputs`` (module doc).

    BLAS runs on one thread here (:data:`BLAS_THREADS`): the matrices are small (points x
    at most a few hundred facets), and threads on a busy 2-core machine made one trial
    period 25 times slower (BENCHMARKS.md, "Shape inversion").
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
        return _run_shape(inputs, options)


def _run_shape(inputs: ShapeInput, options: ShapeOptions) -> ShapeRun:
    start = time.perf_counter()
    d = inputs.data
    law = resolve_law(options, inputs)
    t0 = float(np.floor(d.time_jd[0]))
    coarse = ConvexModel(d, facet_normals(options.search_nside), law, t0)
    fine = ConvexModel(d, facet_normals(options.nside), law, t0)
    grid = period_grid_h(options.min_period_h, options.max_period_h, d.baseline_d)
    scan = scan_periods(
        coarse,
        grid,
        n_start_poles=options.n_start_poles,
        progress=options.progress,
        workers=options.workers,
    )
    poles = search_poles(
        coarse, scan.best.period_h, step_deg=options.pole_step_deg, progress=options.progress
    )
    # the refined minima and the mirror of the map's best, on the fine facets; the best of
    # them all is the solution (the map's best can refine to a higher chi-square than
    # another start), its mirror found again from there
    refined = distinct_solutions(
        [_refine_fine(fine, coarse, s) for s in (*poles.solutions, poles.mirror)]
    )
    best = refined[0]
    mirror, mirror_is_minimum = _mirror(fine, coarse, best, refined[1:])
    others = [s for s in refined[1:] if s is not mirror]
    cov, mirror_cov = covariance(fine, best), covariance(fine, mirror)
    samples, sample_areas = (
        bootstrap(fine, best, options.bootstrap_draws, options.seed)
        if options.bootstrap_draws > 0
        else (np.zeros((0, 3)), np.zeros((0, len(fine.normals))))
    )
    s = cov.residual_scale
    p_shape = shape_p_value(fine, best)
    constrained = p_shape < NULL_P_VALUE
    poly = minkowski_polyhedron(fine.normals, best.areas) if constrained else None
    band, materials = None, None
    if inputs.band_factor is not None and inputs.band_factor.shape[1] > 1:
        band = facet_band_factors(fine, best, inputs.band_factor, inputs.band_sigma)
        if inputs.loaded is not None and inputs.bands is not None and law.name == "lambert":
            materials = facet_materials(band, inputs.loaded, inputs.bands)
    return ShapeRun(
        inputs=inputs,
        options=options,
        law=law,
        model=fine,
        scan=scan,
        poles=poles,
        best=best,
        mirror=mirror,
        others=others,
        cov=cov,
        mirror_cov=mirror_cov,
        samples=samples,
        sample_areas=sample_areas,
        shape_p=p_shape,
        mirror_reported=mirror_is_minimum and mirror_ambiguous(best, mirror, cov),
        mirror_is_minimum=mirror_is_minimum,
        pole_constrained=constrained and spans(poles.chi2, s),
        period_constrained=constrained and spans(scan.chi2, s, "median"),
        polyhedron=poly,
        band_factor=band,
        seconds=time.perf_counter() - start,
        materials=materials,
    )
