"""Layout rules of the package (docs/design.md), checked on the source itself.

* no import cycles between speclight's modules, counting imports inside functions too
  (a lazy import hides a cycle from Python, not from the reader), and none between its
  packages (a package: a folder with ``__init__.py``, each module counted in the innermost
  one; the modules directly in ``speclight/`` each count as one; a subpackage may use its
  parents);
* no package folder holds more than :data:`MAX_MODULES_PER_PACKAGE` modules directly;
* no name a package exports is also one of its modules (``speclight.estimate.compare``
  is one thing, not a function or a module depending on what was imported first);
* Mitsuba and Dr.Jit are imported only inside ``speclight.render``;
* the render variant is chosen in one place (``render/session.py`` calls ``choose_variant``);
* no two modules share a file name (a newcomer can tell them apart), ``__init__`` and
  ``__main__`` aside;
* physical constants are defined once (``speclight.constants``);
* the estimators and the maps do not speak the command line: their errors name the Python
  parameter (``grid_deg``), and ``speclight.cli`` says the flag (``--grid-deg``).
"""

import ast
import re
from collections import Counter
from pathlib import Path

import speclight

ROOT = Path(speclight.__file__).parent


def _modules() -> dict[str, Path]:
    out = {}
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(path: Path, modules: dict[str, Path]) -> set[str]:
    """speclight modules imported anywhere in the file (a package import counts as its
    ``__init__``; ``from pkg import name`` counts the submodule when ``name`` is one)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        for name in names:
            if name in modules:
                found.add(name)
    return found


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The cycles a depth-first search meets in ``graph`` (node -> the nodes it imports)."""
    state: dict[str, int] = {}
    cycles = []

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for d in sorted(graph.get(m, ())):
            if state.get(d) == 1:
                cycles.append([*stack[stack.index(d) :], d] if d in stack else [m, d])
            elif d not in state:
                visit(d, [*stack, d])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    return cycles


def test_no_import_cycles():
    modules = _modules()
    graph = {m: _imports(p, modules) - {m} for m, p in modules.items()}
    # a package's __init__ re-exports its modules: importing a module of a package runs the
    # package's __init__ first, which is not a dependency of the module on its siblings
    for m in graph:
        graph[m] = {d for d in graph[m] if not (m.startswith(d + ".") and d != "speclight")}
    cycles = _cycles(graph)
    # package __init__ files re-exporting submodules that import the package are not cycles
    # of code; keep only cycles between plain modules
    real = [c for c in cycles if not any(modules[x].name == "__init__.py" for x in c)]
    assert not real, "import cycles:\n" + "\n".join(" -> ".join(c) for c in real)


def _package(module: str, modules: dict[str, Path]) -> str:
    """The innermost package of a module (a package's ``__init__`` is the package itself);
    a module directly in ``speclight/`` is its own unit (the shared facts, the thin layers)."""
    if modules[module].name == "__init__.py":
        return module
    parent = module.rpartition(".")[0]
    return module if parent == "speclight" else parent


def test_no_import_cycles_between_packages():
    """Packages import each other one way only, so each can be read (and replaced) knowing
    only the packages below it. A subpackage is part of its parents and may use them
    (``render/bsdfs/`` the shading of ``render/``, ``maps/writer/`` the format of ``maps/``):
    that is inside one package, where the module rule above applies."""
    modules = _modules()
    graph: dict[str, set[str]] = {}
    for m, path in modules.items():
        a = _package(m, modules)
        for d in _imports(path, modules):
            b = _package(d, modules)
            if a != b and not a.startswith(b + "."):
                graph.setdefault(a, set()).add(b)
    cycles = _cycles(graph)
    assert not cycles, "import cycles between packages:\n" + "\n".join(
        " -> ".join(c) for c in cycles
    )


#: Most modules directly in one package folder: past this, a folder is a list to scan, not a
#: layout to read (docs/design.md lists packages, not files).
MAX_MODULES_PER_PACKAGE = 25


def test_no_package_folder_is_a_long_list():
    crowded = {
        str(init.parent.relative_to(ROOT)): n
        for init in ROOT.rglob("__init__.py")
        if (n := len(list(init.parent.glob("*.py")))) > MAX_MODULES_PER_PACKAGE
    }
    assert not crowded, crowded


def test_no_exported_name_is_also_a_module():
    modules = _modules()
    clashes = []
    for name, path in modules.items():
        if path.name != "__init__.py":
            continue
        exported = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                exported |= {a.asname or a.name for a in node.names}
            elif isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
            ):
                exported |= {e.value for e in ast.walk(node.value) if isinstance(e, ast.Constant)}
        clashes += [f"{name}.{e}" for e in sorted(exported) if f"{name}.{e}" in modules]
    # ``from speclight.x import y`` in x's own __init__ naming its module y is a re-export of
    # the module itself, not a clash: keep only names bound to something else
    real = [c for c in clashes if not _reexports_module(modules, c)]
    assert not real, real


def _reexports_module(modules: dict[str, Path], dotted: str) -> bool:
    package, _, name = dotted.rpartition(".")
    tree = ast.parse(modules[package].read_text())
    return any(
        isinstance(node, ast.ImportFrom)
        and node.module == package
        and name in {a.name for a in node.names}
        for node in ast.walk(tree)
    )


def test_mitsuba_only_inside_render():
    pattern = re.compile(r"^\s*(import|from)\s+(mitsuba|drjit)\b", re.M)
    outside = [
        str(p.relative_to(ROOT))
        for p in ROOT.rglob("*.py")
        if pattern.search(p.read_text()) and p.relative_to(ROOT).parts[0] != "render"
    ]
    assert not outside


def test_the_variant_is_chosen_in_one_place():
    callers = [
        str(p.relative_to(ROOT))
        for p in ROOT.rglob("*.py")
        if re.search(r"\bchoose_variant\(", p.read_text())
    ]
    # variant.py defines it, session.py chooses the run's variant (info.py asks session.py)
    assert sorted(callers) == ["render/session.py", "render/variant.py"]


def test_module_file_names_are_unique():
    names = Counter(
        p.name for p in ROOT.rglob("*.py") if p.name not in ("__init__.py", "__main__.py")
    )
    assert [n for n, c in names.items() if c > 1] == []


def test_physical_constants_are_defined_once():
    pattern = re.compile(r"(299[_ ]?792[_ ]?458|6\.62607015|149[_ ]?597[_ ]?870)")
    places = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*.py") if pattern.search(p.read_text())]
    assert places == ["constants.py"]


def test_cores_name_parameters_not_flags():
    pattern = re.compile(r"""(field=|FIELD = )f?["']-""")
    speaking = [
        str(p.relative_to(ROOT))
        for folder in ("estimate", "maps")
        for p in (ROOT / folder).rglob("*.py")
        if pattern.search(p.read_text())
    ]
    assert speaking == []
