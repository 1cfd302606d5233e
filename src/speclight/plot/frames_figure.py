"""The figure of ``speclight frames``: the first frames with their truth drawn on them.

Each panel is one frame in ADU on an asinh stretch between its median (the sky) and a high
percentile, north and east arrows from its WCS, the target's streak from its start (circle)
to its end (cross) and its light centroid (plus), and the catalogue stars on the frame
(squares, labelled with their Hipparcos number and V magnitude).
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: Panels per figure.
MAX_PANELS = 4
#: Upper end of the stretch [percentile of the frame's pixels].
TOP_PERCENTILE = 99.9


def _stretch(adu: np.ndarray) -> tuple[np.ndarray, float, float]:
    low = float(np.median(adu))
    high = float(np.percentile(adu, TOP_PERCENTILE))
    high = max(high, low + 1.0)
    scaled = np.arcsinh(np.clip((adu - low) / (high - low), 0.0, None) * 10.0) / np.arcsinh(10.0)
    return scaled, low, high


def _on_frame(star: dict[str, Any], shape: tuple[int, ...]) -> tuple[float, float]:
    """Middle of the part of a star's streak (start to end) that lies on the frame."""
    f = np.linspace(0.0, 1.0, 201)
    x = star["start_x"] + f * (star["end_x"] - star["start_x"])
    y = star["start_y"] + f * (star["end_y"] - star["start_y"])
    inside = (x > -0.5) & (x < shape[1] - 0.5) & (y > -0.5) & (y < shape[0] - 0.5)
    if not inside.any():
        return float(star["x"]), float(star["y"])
    return float(x[inside].mean()), float(y[inside].mean())


def _compass(ax: Any, pointing: Any) -> None:
    """North and east arrows from the CD matrix, in the panel's lower right corner."""
    inv = np.linalg.inv(pointing.cd_deg)
    size = 0.1 * min(pointing.width_px, pointing.height_px)
    x0, y0 = pointing.width_px - 1.6 * size, 1.6 * size
    for label, world in (("N", (0.0, 1.0)), ("E", (1.0, 0.0))):
        d = inv @ np.array(world)
        d = d / np.hypot(*d) * size
        ax.annotate(
            "",
            xy=(x0 + d[0], y0 + d[1]),
            xytext=(x0, y0),
            arrowprops={"arrowstyle": "->", "color": "white", "lw": 1},
        )
        ax.text(x0 + 1.25 * d[0], y0 + 1.25 * d[1], label, color="white", ha="center", va="center")


def frames_figure(frames: list[Any], records: list[dict[str, Any]]) -> Any:
    """A figure of up to :data:`MAX_PANELS` frames and their truth.

    Parameters
    ----------
    frames
        :class:`~speclight.instrument.imaging.frame_set.Frame` objects.
    records
        Their truth records (``truth.json``), in the same order.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    from speclight.engine_packages import require_engine

    require_engine("matplotlib", "--plot", "the frames figure")
    shown = list(zip(frames, records, strict=False))[:MAX_PANELS]
    n = max(len(shown), 1)
    cols = min(n, 2)
    rows = int(np.ceil(n / cols))
    fig = Figure(figsize=(6.0 * cols, 5.2 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax in axes[len(shown) :]:
        ax.set_axis_off()
    for ax, (frame, record) in zip(axes, shown, strict=False):
        adu = np.asarray(frame.exposure.adu, dtype=np.float64)
        scaled, low, high = _stretch(adu)
        ax.imshow(scaled, origin="lower", cmap="gray", interpolation="nearest")
        t = record["target"]
        ax.plot(t["start_x"], t["start_y"], "o", mfc="none", color="tab:orange", ms=14, mew=0.8)
        if np.hypot(t["end_x"] - t["start_x"], t["end_y"] - t["start_y"]) > 1.0:
            ax.plot(t["end_x"], t["end_y"], "x", color="tab:orange", ms=10, mew=0.8)
            if np.isfinite(t["x"]):
                ax.plot(t["x"], t["y"], "+", color="tab:red", ms=12, mew=0.8)
        for star in record["stars"]:
            x, y = _on_frame(star, adu.shape)
            ax.plot(x, y, "s", mfc="none", color="tab:cyan", ms=14, mew=0.8)
            ax.annotate(
                f"HIP {star['hip']}  V={star['v_mag']:.1f}",
                (x, y),
                xytext=(9, 9),
                textcoords="offset points",
                color="tab:cyan",
                fontsize=7,
            )
        _compass(ax, frame.exposure.pointing)
        ax.set_xlim(-0.5, adu.shape[1] - 0.5)
        ax.set_ylim(-0.5, adu.shape[0] - 0.5)
        sky = record.get("sky_v_mag_arcsec2")
        sky_text = f", sky V {sky:.1f} mag/arcsec²" if sky is not None else ""
        ax.set_title(
            f"{record['file']}\n{record['start_utc']} UTC, {record['exposure_s']:g} s, "
            f"band {record['band']}{sky_text}",
            fontsize=9,
        )
        ax.set_xlabel(f"x [px]  (display {low:.0f}..{high:.0f} ADU, asinh)")
        ax.set_ylabel("y [px]")
    fig.suptitle(
        "speclight frames: target (o start, x end, + light centroid), Hipparcos stars (squares)",
        fontsize=10,
    )
    return fig
