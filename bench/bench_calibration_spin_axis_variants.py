"""Covariance variants of the spin-axis calibration bench, from refits done once per draw.

Per draw (:func:`parts`), around the refined answer ``x0`` (the tangent parametrisation of
:class:`speclight.estimate.spin_axis.spin_axis_gradient.SpinMisfit`): the sandwich, the
jackknife refits on the search's map and on that map at half its ``nside`` (``xs``, ``xcs``),
the refit on the half map (``xc``; the shift ``s = xc - x0``), the refits on the map
displaced by draws of the map-error field (``warp``:
:func:`speclight.estimate.spin_axis.spin_axis_map_error.map_warp_deviations`) and, as a
diagnostic a user
cannot have, the refit on the truth's own finer map (``xt``: ``x0 - xt`` is what the search
map's error does to the answer). Every variant of :data:`VARIANTS` is then a sum of these
(:func:`variant`), so all are compared on the same searches.

Richardson (1911; bilinear interpolation errs by ``k h^2``): the answer on a map of pixel
``h`` is ``a_h = a + c h^2``, so ``a_h - a = (a_2h - a_h) / 3 = s / 3`` and the corrected
answer is ``a_h - s / 3``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from speclight.estimate.spin_axis.spin_axis_confidence import (
    EAST_NORTH,
    confidence_from_covariance,
    sandwich_covariance,
)
from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_jackknife import (
    half_resolution,
    jackknife_refits,
    jackknife_spread,
    refit,
    shrunk_jackknife_spread,
    shrunk_second_moment,
)
from speclight.estimate.spin_axis.spin_axis_map_error import (
    covering_covariance,
    map_warp_deviations,
)

VARIANTS = {
    "default": "jackknife + sandwich (method jackknife)",
    "sandwich": "sandwich (HAC) alone",
    "shrunk": "sandwich + jackknife, its axis block shrunk to isotropic (jackknife-shrunk)",
    "sandwich-warp": "sandwich + the map's displaced-direction field (sandwich-warp)",
    "jackknife-warp": "covering jackknife-shrunk and sandwich-warp (jackknife-warp)",
    "warp-sum": "jackknife-shrunk + the map's displaced-direction field (their sum)",
    "map-iso": "default + |s|^2 / 9 isotropic (jackknife-map)",
    "map-iso-half": "default + |s|^2 / 18 per component (isotropic: E|m|^2 = |s|^2 / 9)",
    "sandwich-iso-half": "sandwich + |s|^2 / 18 per component (no jackknife)",
    "map-rank1": "default + s s^T / 9 (rank 1, along the half-map shift)",
    "richardson": "answer - s / 3; sandwich + jackknife of the corrected answer",
    "richardson-rank1": "answer - s / 3; that + s s^T / 9 (the correction's size as its error)",
}
#: The variants built on the map-error field's refits.
WARP = ("sandwich-warp", "jackknife-warp", "warp-sum")


def parts(bmap, geo, y, res, free_period: bool, truth_map) -> dict:
    """The per-draw refits of the module doc (None where the answer is not finite)."""
    ra, dec, phase, _ = res.refined
    if not np.all(np.isfinite(res.refined[:3])):
        return {}
    model = SpinMisfit.around(bmap, geo, y, None, ra, dec, free_period)
    x0 = np.array([0.0, 0.0, np.radians(phase)] + ([0.0] if free_period else []))
    r, jac = model.residuals(x0)
    out = dict(x0=x0, y=y, error=res.error.T, dec=res.dec_deg, ra=res.ra_deg, refined=res.refined)
    if jac is None or not np.all(np.isfinite(r)) or not np.any(jac):
        return out
    out["r"], out["jac"] = r, jac  # for variants tried on the saved draws
    out["sandwich"], out["a_inv"], out["lag"] = sandwich_covariance(r, jac, y.shape[0])
    out["xs"] = jackknife_refits(model, x0, False)
    out["warp"] = map_warp_deviations(model, x0)
    coarse = half_resolution(model)
    if coarse is not None:
        out["xc"] = refit(coarse, x0)
        out["xcs"] = jackknife_refits(coarse, x0, False)
        out["corrected"] = model.to_spin_model(x0 - (out["xc"] - x0) / 3)
    out["xt"] = refit(dataclasses.replace(model, bmap=truth_map), x0)
    out["period_scale"] = float("nan")
    if free_period:
        step = np.array([0, 0, 0, 1e-6])
        out["period_scale"] = abs(model.period_s(x0 + step) - model.period_s(x0)) / 1e-6
    return out


def _en_deg(dx: np.ndarray) -> np.ndarray:
    """(east, north) [deg] of a change ``dx`` of the tangent parameters."""
    return np.degrees(EAST_NORTH @ dx[:2])


def shift_text(p: dict) -> str:
    """The half-map shift / 3 and the truth-map error (east, north) [deg], for the log."""
    if "xc" not in p:
        return "-"
    s3 = _en_deg(p["xc"] - p["x0"]) / 3
    te = _en_deg(p["x0"] - p["xt"])
    return f"({s3[0]:+.2f}, {s3[1]:+.2f}); map error ({te[0]:+.2f}, {te[1]:+.2f})"


def _rank1(s: np.ndarray) -> np.ndarray:
    out = np.zeros((s.size, s.size))
    out[:2, :2] = np.outer(s[:2], s[:2]) / 9.0
    return out


def _covariance(p: dict, key: str) -> np.ndarray | None:
    if "xs" not in p or (key not in ("default", "sandwich", "shrunk", *WARP) and "xc" not in p):
        return None
    if key in WARP and "warp" not in p:
        return None
    sand = p["sandwich"]
    if key == "sandwich":
        return sand
    if key in WARP:
        d = p["warp"]
        field = sand + (shrunk_second_moment(d)[0] if d.shape[0] else 0.0)
        shrunk = sand + shrunk_jackknife_spread(p["xs"])[0]
        if key == "sandwich-warp":
            return field
        return (
            covering_covariance(shrunk, field) if key == "jackknife-warp" else shrunk + field - sand
        )
    default = sand + jackknife_spread(p["xs"])
    if key == "default":
        return default
    if key == "shrunk":
        return sand + shrunk_jackknife_spread(p["xs"])[0]
    s = p["xc"] - p["x0"]
    iso = np.zeros_like(default)
    iso[0, 0] = iso[1, 1] = float(np.sum(s[:2] ** 2)) / 9.0
    if key == "map-iso":
        return default + iso
    if key == "map-iso-half":
        return default + iso / 2
    if key == "sandwich-iso-half":
        return sand + iso / 2
    if key == "map-rank1":
        return default + _rank1(s)
    corrected = sand + jackknife_spread(p["xs"] - (p["xcs"] - p["xs"]) / 3)
    if key == "richardson":
        return corrected
    return corrected + _rank1(s)


def _tangent_error(ra: float, dec: float, ra0: float, dec0: float) -> tuple[float, float]:
    """(east, north) [deg] of (ra, dec) about (ra0, dec0), azimuthal equidistant."""
    r, d, r0, d0 = np.radians([ra, dec, ra0, dec0])
    c = np.sin(d0) * np.sin(d) + np.cos(d0) * np.cos(d) * np.cos(r - r0)
    x = np.cos(d) * np.sin(r - r0)
    y = np.cos(d0) * np.sin(d) - np.sin(d0) * np.cos(d) * np.cos(r - r0)
    rho = np.arccos(np.clip(c, -1.0, 1.0))
    scale = rho / np.hypot(x, y) if np.hypot(x, y) > 0 else 1.0
    return float(np.degrees(x * scale)), float(np.degrees(y * scale))


def variant(row: dict, key: str) -> dict:
    """``row`` with the confidence ``c`` (and, for a corrected answer, the errors) of
    variant ``key``; the default's own confidence where the refits are missing."""
    p = row.get("parts") or {}
    cov = _covariance(p, key) if p else None
    if cov is None:
        return row
    c = confidence_from_covariance(
        cov, p["a_inv"], p["error"], p["dec"], p["ra"], p["refined"], p["y"], p["lag"],
        p["period_scale"],
    )  # fmt: skip
    c.constrained = c.constrained and not row["warned"]
    out = dict(row, c=c)
    if key.startswith("richardson"):
        ra, dec = p["corrected"][:2]
        out["east"], out["north"] = _tangent_error(ra, dec, *row["truth"])
        out["err"] = float(angular_distance_deg(ra, dec, *row["truth"]))
    return out


def oracle_report(rows: list[dict]) -> None:
    """How the half-map shift / 3 predicts the map's error (the truth-map refit) and the
    pulls of the default with that error removed (what a perfect map-error model gives)."""
    got = [r for r in rows if r.get("parts") and "xc" in r["parts"] and r["c"].constrained]
    if not got:
        return
    s3 = np.array([_en_deg(r["parts"]["xc"] - r["parts"]["x0"]) / 3 for r in got])
    te = np.array([_en_deg(r["parts"]["x0"] - r["parts"]["xt"]) for r in got])
    err = np.array([[r["east"], r["north"]] for r in got])
    sig = np.array([[r["c"].sigma_east_deg, r["c"].sigma_north_deg] for r in got])
    print(f"\n### the map's error (truth-map refit) over the {len(got)} said constrained")
    for j, name in enumerate(("east", "north")):
        cc = np.corrcoef(s3[:, j], te[:, j])[0, 1]
        slope = float(np.sum(s3[:, j] * te[:, j]) / np.sum(s3[:, j] ** 2))
        print(
            f"{name}: rms map error {np.sqrt(np.mean(te[:, j] ** 2)):.3f} deg, rms shift/3 "
            f"{np.sqrt(np.mean(s3[:, j] ** 2)):.3f}; correlation {cc:.2f}, map error = "
            f"{slope:.2f} x shift/3; error / sigma std {np.std(err[:, j] / sig[:, j]):.2f}, "
            f"with the map error removed {np.std((err[:, j] - te[:, j]) / sig[:, j]):.2f}"
        )
