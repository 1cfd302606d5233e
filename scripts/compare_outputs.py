"""Run the built-in examples (and a few variants that reach other code paths) and compare runs.

Used to check that a refactoring leaves every output bit-identical::

    python scripts/compare_outputs.py run before/     # on the old commit
    python scripts/compare_outputs.py run after/      # on the new one
    python scripts/compare_outputs.py compare before/ after/

``compare`` checks every variable, coordinate and attribute of every case for exact equality
(NaN equal to NaN); only the ``history`` attribute (a time stamp) is ignored. Exit 1 on any
difference.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
import yaml

#: (case name, example, overrides applied to the example's YAML mapping).
CASES: list[tuple[str, str, dict[str, Any]]] = [
    ("box-wing", "box-wing", {}),
    ("box-wing-laser", "box-wing-laser", {}),
    ("calsphere", "calsphere", {}),
    ("lcs1", "lcs1", {}),
    (
        "box-wing-images",
        "box-wing",
        {"time.stop": "2019-08-30T02:20:09Z", "render.save_images_at": [0, 5]},
    ),
    (
        "box-wing-laser-path",
        "box-wing-laser",
        {
            "time.stop": "2019-08-30T02:20:02Z",
            "render.mode": "path",
            "render.resolution_px": 48,
            "render.samples_per_pixel": 4,
            "render.save_images_at": [1],
        },
    ),
    (
        "calsphere-path-disk",
        "calsphere",
        {
            "render.mode": "path",
            "render.resolution_px": 32,
            "render.samples_per_pixel": 4,
            "illumination.solar_disk": True,
            "time.step_s": 60.0,
        },
    ),
]


def _set(tree: dict[str, Any], dotted: str, value: Any) -> None:
    *head, last = dotted.split(".")
    for key in head:
        tree = tree.setdefault(key, {})
    tree[last] = value


def run(out: Path) -> None:
    from speclight.scenario.builtin_examples import example_text
    from speclight.scenario.load import parse_scenario
    from speclight.simulation import simulate

    out.mkdir(parents=True, exist_ok=True)
    only = set(sys.argv[3:])
    for name, example, overrides in CASES:
        if only and name not in only:
            continue
        tree = yaml.safe_load(example_text(example))
        for key, value in overrides.items():
            _set(tree, key, value)
        loaded = parse_scenario(yaml.safe_dump(tree), source=name, base_dir=Path.cwd())
        result = simulate(loaded)
        path = out / f"{name}.nc"
        path.unlink(missing_ok=True)
        result.dataset.to_netcdf(path, engine="h5netcdf")
        (out / f"{name}.notes").write_text("\n".join(result.notes) + "\n")
        print(f"{name}: {len(result.dataset.data_vars)} variables")


def _same(a: Any, b: Any) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


def compare(a_dir: Path, b_dir: Path) -> int:
    bad = 0
    for name, _, _ in CASES:
        pa, pb = a_dir / f"{name}.nc", b_dir / f"{name}.nc"
        if not pa.exists() or not pb.exists():
            print(f"{name}: missing in one run")
            bad += 1
            continue
        a, b = xr.open_dataset(pa, engine="h5netcdf"), xr.open_dataset(pb, engine="h5netcdf")
        diffs = []
        names_a = set(a.variables)
        names_b = set(b.variables)
        for v in sorted(names_a ^ names_b):
            diffs.append(f"variable {v} in one run only")
        for v in sorted(names_a & names_b):
            if not _same(a[v].values, b[v].values):
                diffs.append(f"variable {v} differs")
            if a[v].dims != b[v].dims:
                diffs.append(f"variable {v}: dims {a[v].dims} vs {b[v].dims}")
            if {k: str(x) for k, x in a[v].attrs.items()} != {
                k: str(x) for k, x in b[v].attrs.items()
            }:
                diffs.append(f"variable {v}: attributes differ")
        ga = {k: str(x) for k, x in a.attrs.items() if k != "history"}
        gb = {k: str(x) for k, x in b.attrs.items() if k != "history"}
        for k in sorted(set(ga) | set(gb)):
            if ga.get(k) != gb.get(k):
                diffs.append(f"global attribute {k} differs")
        notes_a = (a_dir / f"{name}.notes").read_text()
        notes_b = (b_dir / f"{name}.notes").read_text()
        if notes_a != notes_b:
            diffs.append("notes differ")
        print(f"{name}: {'identical' if not diffs else 'DIFFERENT'} ({len(a.variables)} variables)")
        for d in diffs:
            print(f"    {d}")
        bad += bool(diffs)
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "run":
        run(Path(sys.argv[2]))
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3])))
    else:
        sys.exit(__doc__)
