"""Unmixing against ground truth: the comparison that ``speclight unmix`` adds to ABUND.nc.

When the input carries each material's part of the band reflectance factors
(``reflectance_factor_material(time, material, band)``, or ``laser_reflectance_factor_
material`` under lasers; ``render: {per_material: true}``), the true contributions are their
projections on the signatures (:func:`speclight.estimate.spectra.ground_truth.true_contributions`),
and the compared shares are the fractions ``g_k / sum(g)`` (what ``nnls-norm`` estimates):

* endmembers named as the materials, or as their reflectance labels (``material_reflectance``:
  the shipped table names, file stems), every material covered once (a scenario endmember
  ``a,b`` stands for materials a and b), are matched **by name**. The classes are the
  endmembers, the truth is projected on the endmembers' own (per-epoch) signatures, and the
  estimate is the abundance normalised to sum to one;
* otherwise (extracted endmembers, foreign names) the classes are the distinct materials
  (by reflectance label where the input has the labels). Each class's **true signature** is
  its ground truth summed over the epochs, divided by its band mean; **each endmember goes to
  the class whose true signature is nearest in spectral angle**. Truth and estimate are both
  expressed in units of the true signatures (:func:`.accuracy.in_reference_units`), and the
  estimates of endmembers matched to one class are summed.

Added: ``true_share`` and ``estimated_share(time, class)``, ``confusion_matrix(true_class,
estimated_class)`` (rows normalised) and ``confusion_count``, for angle matching
``true_signature(class, band)``, ``endmember_material`` and ``endmember_angle(endmember)``,
and the attributes ``matching`` and ``mean_absolute_share_error``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from speclight.estimate.inputs.reflectance_factors import ReflectanceFactors
from speclight.estimate.spectra import accuracy
from speclight.estimate.spectra.endmember_spectra import Endmembers
from speclight.estimate.spectra.ground_truth import fractions, true_contributions


def _by_name(members: Endmembers, keys: list[str]) -> list[str] | None:
    """Each material's endmember (by ``keys``: names or labels), or None if they do not
    cover every key exactly once."""
    groups = [name.split(",") for name in members.names]
    listed = [m for group in groups for m in group]
    if sorted(listed) != sorted(set(keys)):
        return None
    owner = {m: members.names[k] for k, group in enumerate(groups) for m in group}
    return [owner[m] for m in keys]


def compare_with_truth(
    ds: xr.Dataset,
    data: ReflectanceFactors,
    members: Endmembers,
    abundance: np.ndarray,
    by_name: bool,
) -> xr.Dataset:
    """Add the comparison with the input's ground truth to an ABUND.nc dataset (module doc).

    Parameters
    ----------
    ds
        The ABUND.nc dataset.
    data
        The reflectance factors, with ``material_contribution`` and ``material_names``.
    members
        The endmembers unmixed with.
    abundance
        (N, K) their contributions.
    by_name
        Match endmembers to materials by name where every material is named exactly once.
    """
    truth = data.material_contribution
    materials = data.material_names
    assert truth is not None and materials is not None
    labels = data.material_labels or materials
    owner = None
    if by_name:
        owner = _by_name(members, materials)
        matching = "by name"
        if owner is None and data.material_labels:
            owner = _by_name(members, labels)
            matching = "by reflectance label"
    if owner is not None:
        classes = list(members.names)
        sig = members.signatures if members.signatures_epoch is None else members.signatures_epoch
        true = fractions(true_contributions(truth, owner, classes, sig))
        est = fractions(abundance)
    else:
        classes = list(dict.fromkeys(labels))
        of_class = np.array([classes.index(m) for m in labels])
        summed = np.stack(
            [np.nansum(truth[:, of_class == c], axis=(0, 1)) for c in range(len(classes))]
        )
        mean = summed.mean(axis=1, keepdims=True)
        reference = summed / np.where(mean > 0, mean, 1.0)
        angle = accuracy.spectral_angle_rad(members.signatures, reference)
        to_class = np.argmin(angle, axis=1)
        true = fractions(true_contributions(truth, labels, classes, reference))
        own = accuracy.in_reference_units(abundance, members.signatures, reference[to_class])
        est = fractions(accuracy.merge_columns(own, to_class, len(classes)))
        ds["endmember_material"] = (
            "endmember",
            np.array([classes[i] for i in to_class]),
            {"long_name": "true material matched to each endmember (smallest spectral angle)"},
        )
        ds["endmember_angle"] = (
            "endmember",
            np.degrees(angle[np.arange(len(to_class)), to_class]),
            {
                "units": "degree",
                "long_name": "spectral angle between the endmember and its material's "
                "true signature",
            },
        )
        ds["true_signature"] = (
            ("class", "band"),
            reference,
            {
                "units": "1",
                "long_name": "band signature of each true material (its ground truth summed "
                "over the epochs), divided by its band mean",
            },
        )
        matching = "by spectral angle"
    ds = ds.assign_coords(
        {
            "class": ("class", np.array(classes, dtype=str), {"long_name": "material compared"}),
            "true_class": ("true_class", np.array(classes, dtype=str)),
            "estimated_class": ("estimated_class", np.array(classes, dtype=str)),
        }
    )
    what = "fraction g_k / sum(g) of the contributions"
    ds["true_share"] = (("time", "class"), true, {"units": "1", "long_name": f"true {what}"})
    ds["estimated_share"] = (
        ("time", "class"),
        est,
        {"units": "1", "long_name": f"estimated {what}"},
    )
    dims = ("true_class", "estimated_class")
    ds["confusion_matrix"] = (
        dims,
        accuracy.confusion_matrix(true, est),
        {
            "units": "1",
            "long_name": "fraction of the epochs dominated by the true class that were "
            "estimated as dominated by each class (rows sum to 1)",
        },
    )
    ds["confusion_count"] = (
        dims,
        accuracy.confusion_matrix(true, est, normalise=False).astype(np.int64),
        {"units": "1", "long_name": "epochs by true and estimated dominant class"},
    )
    ds.attrs["matching"] = matching
    ds.attrs["mean_absolute_share_error"] = accuracy.mean_absolute_share_error(true, est)
    return ds
