"""The Starlink second-generation ("V2 mini") satellite as Kandula et al. 2025 model it.

Kandula et al. 2025 (repository Phan-Kandula/simulated-satellite-streaks-impact, commit
bce15626, ``gen2_starlink/satellitemodels.py``, MIT; the facts are shipped in
``src/speclight/data/brdf/starlink_gen2_surfaces.txt``) describe the V2 mini as a sum of flat
facets in lumos-sat's frame (z to the satellite's zenith, y toward the Sun's azimuth): seven
nadir-facing surfaces (the chassis's dielectric mirror film and bare aluminium, the
phased-array dish covers, the "twist" surfaces, the boom, a "chassis offset") and the
pantograph, tilted 45 deg toward the Sun's side. Their solar arrays are not in the model
(in the brightness-mitigation attitude they are turned away from the ground).

speclight's body frame for it is a yaw-steered nadir attitude: +z to nadir, +x toward the
Sun's azimuth (so lumos-sat's (x, y, z) is body (y, x, -z)). The facets need positions to be
rendered; here the nadir-facing ones tile one plane (z = 0), side by side, and the
pantograph hangs from the plane's +x (Sun-side) edge, rising outward:

* ``mirror_film``: 4.1 m along y (the bus's length) x 2.854 m along x (11.70 m²);
* beside it on the -x side, a 1.207 m band of the other nadir facets along y:
  ``chassis_bare``, ``dishes_ka``, ``dishes_ka_e``, ``twist``, ``boom``, ``chassis_offset``,
  each as wide as its area needs;
* ``pantograph``: 2.0 m along y x 0.515 m up the slope (1.03 m²), normal (1, 0, 1)/sqrt 2.

Coplanar tiles neither shadow nor hide one another, so for the Sun their sum is Kandula et
al.'s facet sum; the pantograph, above the plane, is hidden from observers on the far
(-x) side by the bus, as it would be. The nadir plane holds 16.65 m², more than the
4.1 x 2.7 m bus (11.07 m²): the boom and the offset stand for structure beyond it.
"""

from __future__ import annotations

import numpy as np

from speclight.target.parts import Target
from speclight.target.shapes import Materials, Mesh, _build, _quad

#: Kandula et al. 2025's facets: part name -> (area [m2], normal in lumos-sat's frame).
KANDULA_FACETS: dict[str, tuple[float, tuple[float, float, float]]] = {
    "mirror_film": (11.70, (0.0, 0.0, -1.0)),
    "chassis_bare": (0.30, (0.0, 0.0, -1.0)),
    "pantograph": (1.03, (0.0, 0.7071, -0.7071)),
    "dishes_ka": (0.66, (0.0, 0.0, -1.0)),
    "dishes_ka_e": (0.19, (0.0, 0.0, -1.0)),
    "twist": (0.60, (0.0, 0.0, -1.0)),
    "boom": (2.20, (0.0, 0.0, -1.0)),
    "chassis_offset": (1.00, (0.0, 0.0, -1.0)),
}
#: The bus's length [m] (public dimensions: 4.1 x 2.7 m), the tiles' extent along y.
BUS_LENGTH_M = 4.1
#: The pantograph plate's extent along y [m].
PANTOGRAPH_WIDTH_M = 2.0
#: The nadir facets beside the mirror film, in order along +y.
_BAND = ("chassis_bare", "dishes_ka", "dishes_ka_e", "twist", "boom", "chassis_offset")


def _nadir_tile(x0: float, x1: float, y0: float, y1: float) -> Mesh:
    """A rectangle in the plane z = 0 with normal +z (nadir)."""
    return _quad((x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0))


def starlink_v2_mini(materials: Materials) -> Target:
    """The V2 mini's facets (module doc) as parts of a target, body frame [m]."""
    area = {name: a for name, (a, _) in KANDULA_FACETS.items()}
    film_x = area["mirror_film"] / BUS_LENGTH_M
    band_x = sum(area[n] for n in _BAND) / BUS_LENGTH_M
    x_min = -(film_x + band_x) / 2
    x_mid, x_max = x_min + band_x, x_min + band_x + film_x
    half_y = BUS_LENGTH_M / 2
    meshes: dict[str, Mesh] = {"mirror_film": _nadir_tile(x_mid, x_max, -half_y, half_y)}
    y = -half_y
    for name in _BAND:
        width = area[name] / band_x
        meshes[name] = _nadir_tile(x_min, x_mid, y, y + width)
        y += width
    slope = area["pantograph"] / PANTOGRAPH_WIDTH_M / np.sqrt(2.0)  # its run and rise [m]
    w = PANTOGRAPH_WIDTH_M / 2
    meshes["pantograph"] = _quad(
        (x_max, -w, 0.0), (x_max + slope, -w, -slope), (x_max + slope, w, -slope), (x_max, w, 0.0)
    )
    return _build({name: meshes[name] for name in KANDULA_FACETS}, materials)
