"""Sky orientation of a saved image: celestial north, the observer's zenith and the Sun.

An image is drawn in the body frame (axes ``image_right_body``, ``image_up_body`` as seen
by the observer). A direction ``d`` in the body frame appears in the image along its
component across the line of sight, ``(d . right, d . up)``; the length of that component
(the sine of the angle between ``d`` and the line of sight) says how foreshortened it is.

* north: the celestial pole, GCRS +z, in the body frame through ``attitude_quaternion``
  (body to GCRS, scalar first);
* zenith: the geocentric up direction at the observer, whose GCRS position is the target's
  plus ``range`` times the target-to-observer direction (geocentric rather than geodetic
  up: within 0.2 degrees, invisible on a compass);
* Sun: ``sun_direction_body``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.attitude.quaternion import quat_to_matrix

#: A direction closer than this to the line of sight (sine) points at or away from the
#: observer: its arrow would have no direction.
MIN_ACROSS = 0.05


def _epoch(ds: xr.Dataset, k: int) -> int:
    when = np.atleast_1d(ds["image_time"].values)[k]
    return int(np.argmin(np.abs(ds["time"].values - when)))


def sky_directions_body(ds: xr.Dataset, k: int) -> dict[str, NDArray[np.float64]]:
    """Unit vectors (body frame) of north, zenith and the Sun at saved image ``k``.

    Only those the dataset can give: north needs ``attitude_quaternion``; zenith also
    ``target_position_gcrs``, ``range`` and ``observer_direction_body``; the Sun
    ``sun_direction_body``.
    """
    i = _epoch(ds, k)
    out: dict[str, NDArray[np.float64]] = {}
    if "attitude_quaternion" in ds:
        q = np.asarray(ds["attitude_quaternion"].values[i], dtype=np.float64)
        if np.all(np.isfinite(q)):
            body_to_gcrs = quat_to_matrix(q)
            out["N"] = body_to_gcrs.T @ np.array([0.0, 0.0, 1.0])
            needed = ("target_position_gcrs", "range", "observer_direction_body")
            if all(n in ds for n in needed):
                to_obs = body_to_gcrs @ np.asarray(ds["observer_direction_body"].values[i], float)
                site = (
                    np.asarray(ds["target_position_gcrs"].values[i], float)
                    + float(ds["range"].values[i]) * to_obs
                )
                if np.all(np.isfinite(site)) and np.linalg.norm(site) > 0:
                    out["Z"] = body_to_gcrs.T @ (site / np.linalg.norm(site))
    if "sun_direction_body" in ds:
        sun = np.asarray(ds["sun_direction_body"].values[i], dtype=np.float64)
        if np.all(np.isfinite(sun)) and np.linalg.norm(sun) > 0:
            out["☉"] = sun / np.linalg.norm(sun)
    return out


def image_plane_directions(ds: xr.Dataset, k: int) -> dict[str, tuple[float, float]]:
    """(right, up) components of north ``N``, zenith ``Z`` and the Sun ``☉`` in image ``k``.

    Unnormalised: the length is the sine of the angle to the line of sight. Empty without
    ``image_right_body`` / ``image_up_body``; a direction within :data:`MIN_ACROSS` of the
    line of sight is left out.
    """
    if "image_right_body" not in ds or "image_up_body" not in ds:
        return {}
    right = np.asarray(ds["image_right_body"].values[k], dtype=np.float64)
    up = np.asarray(ds["image_up_body"].values[k], dtype=np.float64)
    out = {}
    for name, d in sky_directions_body(ds, k).items():
        x, y = float(d @ right), float(d @ up)
        if np.hypot(x, y) >= MIN_ACROSS:
            out[name] = (x, y)
    return out


#: Arrow colours: north, zenith, Sun.
_COLOURS = {"N": "#4fc3f7", "Z": "#aed581", "☉": "#ffd54f"}


#: Arrow length of a direction across the line of sight, and the radius of the compass's
#: backing disc [axes fraction].
ARROW_LENGTH, DISC_RADIUS = 0.09, 0.125
#: Gap between the disc and the image's edges [axes fraction].
EDGE_GAP = 0.015


def compass_centres() -> list[tuple[float, float]]:
    """Centres the compass may take [axes fraction]: the four corners, upper left first."""
    near, far = DISC_RADIUS + EDGE_GAP, 1.0 - DISC_RADIUS - EDGE_GAP
    return [(near, far), (far, far), (near, near), (far, near)]


def disc_pixels(centre: tuple[float, float], shape: tuple[int, int]) -> NDArray[np.bool_]:
    """Pixels of an image of ``shape`` (row 0 at the top) whose centres lie under the
    compass disc at ``centre`` [axes fraction]."""
    ny, nx = shape
    y = 1.0 - (np.arange(ny) + 0.5) / ny  # row 0 at the top (imshow's origin="upper")
    x = (np.arange(nx) + 0.5) / nx
    return (x[None, :] - centre[0]) ** 2 + (y[:, None] - centre[1]) ** 2 <= DISC_RADIUS**2


def compass_centre(on_target: NDArray[np.bool_] | None) -> tuple[float, float]:
    """The corner whose disc covers the fewest pixels of the target (the first on a tie)."""
    corners = compass_centres()
    if on_target is None or on_target.ndim != 2:
        return corners[0]
    covered = [int(np.count_nonzero(on_target & disc_pixels(c, on_target.shape))) for c in corners]
    return corners[int(np.argmin(covered))]


def draw_compass(
    ax: Any, ds: xr.Dataset, k: int, on_target: NDArray[np.bool_] | None = None
) -> list[str]:
    """Arrows of north, zenith and the Sun in a corner of image ``k``'s axes: the corner
    that covers the fewest of the ``on_target`` pixels (an image drawn to fill the axes,
    row 0 at the top), else the upper left.

    Returns the names drawn (for the caption).
    """
    dirs = image_plane_directions(ds, k)
    if not dirs:
        return []
    from matplotlib.patches import Circle

    centre = np.array(compass_centre(on_target))
    ax.add_patch(
        Circle(tuple(centre), DISC_RADIUS, transform=ax.transAxes, color="k", alpha=0.3, lw=0)
    )
    for name, (x, y) in dirs.items():
        tip = centre + ARROW_LENGTH * np.array([x, y])
        ax.annotate(
            "",
            xy=tuple(tip),
            xytext=tuple(centre),
            xycoords="axes fraction",
            arrowprops={"arrowstyle": "-|>", "color": _COLOURS[name], "lw": 1.6},
        )
        label = tip + 0.022 * np.array([x, y]) / np.hypot(x, y)
        ax.text(
            *label,
            name,
            transform=ax.transAxes,
            color=_COLOURS[name],
            ha="center",
            va="center",
            fontsize="small",
            fontweight="bold",
        )
    return list(dirs)
