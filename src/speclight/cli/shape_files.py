"""``speclight shape`` from files to files: SHAPE.nc, the OBJ beside it, the figure.

The outputs are claimed before the run and written atomically (:mod:`speclight.io.output`),
as every command's: the NetCDF, ``SHAPE.obj`` (the output's name with ``.obj``; only when
the data constrain a shape) and the figure.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import replace
from pathlib import Path

import xarray as xr

from speclight.errors import InputError
from speclight.estimate.shape.minkowski import format_obj
from speclight.estimate.shape.shape_dataset import shape_dataset
from speclight.estimate.shape.shape_inputs import check_format, read_shape_input
from speclight.estimate.shape.shape_run import ShapeOptions, ShapeRun, resolve_law, run_shape
from speclight.maps.writer.cached_map import MapResolution


def obj_path(output: str | Path) -> Path:
    """The OBJ file written beside ``output`` (its name with the suffix ``.obj``)."""
    return Path(output).with_suffix(".obj")


def shape_files(
    *,
    lc: Path,
    fmt: str,
    scenario: Path | None,
    options: ShapeOptions,
    output: str,
    plot: str | None,
    force: bool,
    bands: list[str] | None = None,
    tumbling_starts: int = 0,
    tumbling_map: Path | None = None,
    no_map: bool = False,
    map_resolution: MapResolution | None = None,
    say: Callable[[str], None] | None = None,
) -> tuple[xr.Dataset, ShapeRun]:
    """Read ``lc``, invert it, write ``output``, its OBJ and the figure ``plot``.

    Parameters
    ----------
    lc
        The light curves (DAMIT ``.lc``, or speclight's NetCDF / CSV).
    fmt
        ``"speclight"`` or ``"damit"``.
    scenario
        Scenario YAML (speclight input; a NetCDF's own by default).
    options
        The run's options.
    output, plot
        SHAPE.nc and the figure (or None).
    force
        Overwrite existing outputs.
    bands
        Bands averaged into the brightness (default all).
    tumbling_starts
        Random starts of the tumbling fit (:mod:`speclight.estimate.shape.tumbling_run`; 0: none).
    tumbling_map
        Reflectivity map of the target as the tumbling fit's light model; its header is
        checked before the run. None: the scenario's map, or one built from the scenario
        and cached (:func:`speclight.estimate.shape.tumbling_run.tumbling_light`).
    no_map
        True: the convex model of the scenario's mesh instead of a map.
    map_resolution
        Resolution of the map built from the scenario (None: the default).
    say
        Where the light model's messages go (the map's build, which model is used).
    """
    from speclight.io.netcdf import dataset_bytes
    from speclight.io.output import OutputClaim
    from speclight.plot.figure_output import claim_outputs

    check_format(fmt)
    if tumbling_map is not None:
        from speclight.maps.map_lookup import read_header

        try:
            read_header(tumbling_map)  # a complete map, before the run
        except InputError as exc:
            raise InputError(exc.message, field="map_path") from None
    inputs = {"light curves": lc, **({"scenario file": scenario} if scenario else {})}
    obj = obj_path(output)
    with claim_outputs(output, plot, force, inputs) as (claim, figure), ExitStack() as stack:
        obj_claim = stack.enter_context(
            OutputClaim(obj, force=force, inputs={**inputs, "output": output})
        )
        loaded = None
        if scenario is not None:
            from speclight.scenario import load_scenario

            loaded = load_scenario(scenario)
        data = read_shape_input(lc, fmt, loaded, bands)
        # DAMIT light curves: the scenario given only for its target (the tumbling fit's)
        tumbling_data = data if data.loaded is not None else replace(data, loaded=loaded)
        light = None
        if tumbling_starts > 0:  # the light model first: its errors before the long run
            from speclight.estimate.shape.tumbling_run import tumbling_light

            light = tumbling_light(
                tumbling_data, resolve_law(options, data), map_path=tumbling_map, no_map=no_map,
                map_resolution=map_resolution, progress=options.progress, say=say,
            )  # fmt: skip
            if say is not None:
                say(light.describe())
        run = run_shape(data, options)
        ds = shape_dataset(run, str(obj) if run.polyhedron is not None else None)
        if light is not None:
            from speclight.estimate.shape.tumbling_run import add_tumbling, tumbling_fit

            fit = tumbling_fit(
                tumbling_data, light.model, min_period_h=options.min_period_h,
                max_period_h=options.max_period_h, n_starts=tumbling_starts, seed=options.seed,
            )  # fmt: skip
            ds = add_tumbling(ds, fit, light)
            if say is not None:
                lo_h, hi_h = fit.searched_period_h
                say(f"tumbling search: periods {lo_h:.4g}-{hi_h:.4g} h (given range, to the span)")
        claim.write(dataset_bytes(ds))
        if run.polyhedron is not None:
            obj_claim.write(format_obj(run.polyhedron, f"speclight shape: EGI of {lc}").encode())
        if figure is not None:
            from speclight.plot.shape_figure import shape_figure

            figure.write(shape_figure(ds, run.polyhedron))
    return ds, run
