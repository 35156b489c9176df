"""The architecture, checked from the source (issue 21).

- No import cycle between the package's modules, imports inside functions included, save the lazy accessors
  named in :data:`LAZY_ACCESSORS` (a method that reaches a higher layer on first use, as xarray's ``.plot``).
  Imports under ``if TYPE_CHECKING:`` are not imports at run time and are not counted.
- The lower layers (numerics, attitude, model, the trajectory) import nothing from solvers, io, viz,
  estimation, oracle or cli.
- No private name (a leading underscore) imported from another module of the package.
- No file over 1,200 lines, save the compiled kernel modules (under 1,500).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "src" / "eulerpoisson"
PACKAGE = "eulerpoisson"

#: (importing module, imported module): lazy accessors, imports inside one method that give a lower-layer
#: object a view of a higher layer on first use
LAZY_ACCESSORS = {
    ("eulerpoisson.trajectory", "eulerpoisson.viz.plots"),  # Trajectory.plot
    ("eulerpoisson.trajectory", "eulerpoisson.io.netcdf"),  # Trajectory.to_netcdf / from_netcdf / to_xarray
    ("eulerpoisson.trajectory", "eulerpoisson.io.read"),  # Trajectory.open
    ("eulerpoisson.trajectory", "eulerpoisson.solvers.engine"),  # Trajectory.__call__ (the dense output)
    ("eulerpoisson.io.read", "eulerpoisson.viz.plots"),  # LazyTrajectory.plot
}

LOWER = ("numerics", "attitude", "model", "trajectory")
UPPER = ("solvers", "io", "viz", "estimation", "oracle", "cli")

#: kernel modules (compiled loops, one per scheme family) may be longer
KERNELS = {"solvers/exact/kernels.py", "solvers/exact/lanes.py", "solvers/taylor/kernels.py"}


def _modules() -> dict[str, tuple[Path, bool]]:
    mods = {}
    for p in ROOT.rglob("*.py"):
        parts = list(p.relative_to(ROOT.parent).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        mods[".".join(parts)] = (p, is_pkg)
    return mods


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.id if isinstance(test, ast.Name) else (test.attr if isinstance(test, ast.Attribute) else "")
            if name == "TYPE_CHECKING":
                for sub in node.body:
                    skip.update(id(n) for n in ast.walk(sub))
    return skip


def _imports(mods):
    """``{module: {(imported module, imported name or None, line)}}`` for the package's own modules."""

    def owner(name: str) -> str:
        while name not in mods and "." in name:
            name = name.rsplit(".", 1)[0]
        return name

    out: dict[str, set[tuple[str, str | None, int]]] = {}
    for name, (path, is_pkg) in mods.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        skip = _type_checking_nodes(tree)
        found = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] == PACKAGE:
                        found.add((owner(a.name), None, node.lineno))
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".") if is_pkg else name.split(".")[:-1]
                    base = base[: len(base) - (node.level - 1)] if node.level > 1 else base
                    target = ".".join(base + ([node.module] if node.module else []))
                elif node.module and node.module.split(".")[0] == PACKAGE:
                    target = node.module
                else:
                    continue
                for a in node.names:
                    sub = f"{target}.{a.name}"
                    if sub in mods:
                        found.add((sub, None, node.lineno))
                    else:
                        found.add((owner(target), a.name, node.lineno))
        out[name] = {f for f in found if f[0] != name}
    return out


MODS = _modules()
IMPORTS = _imports(MODS)


def _graph(allow=LAZY_ACCESSORS):
    return {m: {t for t, _, _ in imp if (m, t) not in allow} for m, imp in IMPORTS.items()}


def _cycles(graph) -> list[list[str]]:
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    comps: list[list[str]] = []
    counter = [0]

    def visit(v):  # Tarjan's strongly connected components, iteratively deep enough for this package
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return comps


def test_the_graph_is_read():
    assert "eulerpoisson.solvers.engine" in MODS and len(MODS) > 80
    assert ("eulerpoisson.trajectory", "eulerpoisson.viz.plots") in {
        (m, t) for m, imp in IMPORTS.items() for t, _, _ in imp
    }


def test_no_import_cycle():
    cycles = _cycles(_graph())
    assert not cycles, "import cycles:\n" + "\n".join(" <-> ".join(c) for c in cycles)


def test_the_lazy_accessors_are_needed():
    """Every allowed edge exists (a stale allowlist would hide a new cycle under an old name)."""
    edges = {(m, t) for m, imp in IMPORTS.items() for t, _, _ in imp}
    assert LAZY_ACCESSORS <= edges, sorted(LAZY_ACCESSORS - edges)


def _layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_lower_layers_import_nothing_above_them():
    bad = []
    for m, imp in IMPORTS.items():
        if _layer(m) not in LOWER:
            continue
        for t, _, line in imp:
            if _layer(t) in UPPER and (m, t) not in LAZY_ACCESSORS:
                bad.append(f"{m}:{line} imports {t}")
    assert not bad, "\n".join(sorted(bad))


def test_no_private_name_imported_across_modules():
    bad = []
    for m, imp in IMPORTS.items():
        for t, name, line in imp:
            if name is not None and name.startswith("_") and not name.startswith("__"):
                bad.append(f"{m}:{line} imports {name} from {t}")
            if t.rsplit(".", 1)[-1].startswith("_") and not t.endswith("__init__"):
                bad.append(f"{m}:{line} imports the private module {t}")
    assert not bad, "\n".join(sorted(bad))


@pytest.mark.parametrize("path", sorted(p for p, _ in MODS.values()), ids=lambda p: str(p.relative_to(ROOT)))
def test_file_length(path):
    rel = str(path.relative_to(ROOT))
    limit = 1500 if rel in KERNELS else 1200
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= limit, f"{rel}: {n} lines (at most {limit})"


def test_a_cycle_is_found():
    """The checker itself: a cycle made by hand is reported."""
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
