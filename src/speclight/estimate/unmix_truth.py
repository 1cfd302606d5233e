"""Unmixing against ground truth: the comparison that ``speclight unmix`` adds to ABUND.nc.

When the input carries ``reflectance_factor_material(time, material, band)`` (each
material's part of the band reflectance factor), the signal shares of :mod:`.accuracy` are
compared:

* endmembers named as the materials (a scenario endmember ``a,b`` stands for materials a and
  b; every material named once) are matched **by name**, and the classes are the
  endmembers;
* otherwise (extracted endmembers, foreign names) **each endmember goes to the material whose
  ground-truth signature** (its contribution summed over the epochs) **is nearest in spectral
  angle**; the classes are the materials, and the shares of endmembers matched to one
  material are summed.

Added: ``true_share`` and ``estimated_share(time, class)``, ``confusion_matrix(true_class,
estimated_class)``, ``material_signature(material, band)`` (divided by its band mean), for
angle matching ``endmember_material`` and ``endmember_angle(endmember)``, and the attributes
``matching`` and ``mean_absolute_share_error``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from speclight.estimate import accuracy
from speclight.estimate.unmix_inputs import Endmembers, ReflectanceFactors


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
    true_m = accuracy.material_shares(truth)
    est_k = accuracy.signal_shares(abundance, members.signatures)
    groups = [name.split(",") for name in members.names]
    listed = [m for group in groups for m in group]
    reference = np.nansum(truth, axis=0)  # (M, B): each material's summed signature
    if by_name and sorted(listed) == sorted(materials):
        classes = list(members.names)
        of_material = np.empty(len(materials), dtype=np.intp)
        for k, group in enumerate(groups):
            for m in group:
                of_material[materials.index(m)] = k
        true = accuracy.merge_columns(true_m, of_material, len(classes))
        est = est_k
        matching = "by name"
    else:
        to_material = accuracy.match_by_angle(members.signatures, reference)
        classes = list(materials)
        true = true_m
        est = accuracy.merge_columns(est_k, to_material, len(classes))
        angle = accuracy.spectral_angle_rad(members.signatures, reference)
        ds["endmember_material"] = (
            "endmember",
            np.array([materials[i] for i in to_material]),
            {
                "long_name": "ground-truth material matched to each "
                "endmember (smallest spectral angle)"
            },
        )
        ds["endmember_angle"] = (
            "endmember",
            np.degrees(angle[np.arange(len(to_material)), to_material]),
            {
                "units": "degree",
                "long_name": "spectral angle between "
                "the endmember and its matched material's signature",
            },
        )
        matching = "by spectral angle"
    norm = reference / np.where(
        reference.mean(axis=1, keepdims=True) > 0, reference.mean(axis=1, keepdims=True), 1.0
    )
    coords = {
        "material": ("material", np.array(materials, dtype=str), {"long_name": "true material"}),
        "class": ("class", np.array(classes, dtype=str), {"long_name": "material class compared"}),
    }
    ds = ds.assign_coords(coords)
    ds["material_signature"] = (
        ("material", "band"),
        norm,
        {
            "units": "1",
            "long_name": "ground-truth band signature of each material, summed over "
            "epochs, divided by its band mean",
        },
    )
    ds["true_share"] = (
        ("time", "class"),
        true,
        {"units": "1", "long_name": "true share of the band-summed reflectance factor"},
    )
    ds["estimated_share"] = (
        ("time", "class"),
        est,
        {"units": "1", "long_name": "estimated share: a_k sum_b S_kb, normalised"},
    )
    cm = accuracy.confusion_matrix(true, est)
    ds["confusion_matrix"] = (
        ("true_class", "estimated_class"),
        cm,
        {
            "units": "1",
            "long_name": "fraction of the epochs dominated by the true class that "
            "were estimated as dominated by each class (rows sum to 1)",
        },
    )
    ds = ds.assign_coords(
        true_class=("true_class", np.array(classes, dtype=str)),
        estimated_class=("estimated_class", np.array(classes, dtype=str)),
    )
    ds.attrs["matching"] = matching
    ds.attrs["mean_absolute_share_error"] = accuracy.mean_absolute_share_error(true, est)
    return ds
