"""Build helpers of the documentation (imported by ``conf.py``; not part of the package).

* the API pages: one page per public module listing every name of its ``__all__``
  (autosummary stubs), names exported twice documented once and aliased elsewhere;
* the gallery: the examples get an output folder as their argument and the images
  they write there are the gallery's figures;
* the audit report, generated from the code at build time.
"""

from __future__ import annotations

import importlib
import pkgutil
import shutil
import time
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1]

#: Public modules in the order of the API reference. Every subpackage with an ``__all__``,
#: every top-level module with one and every module reachable as ``ep.<name>`` is added
#: by :func:`api_modules` even when missing here, so that nothing public goes undocumented.
CURATED = [
    ("eulerpoisson", "The package: bodies, solve, trajectories, fit and the errors"),
    ("eulerpoisson.attitude", "Attitude sets centred on the Gibbs vector"),
    ("eulerpoisson.torques", "Torques"),
    ("eulerpoisson.solvers", "Problems, methods, their options and the registry"),
    ("eulerpoisson.solvers.exact", "The closed form"),
    ("eulerpoisson.solvers.taylor", "Taylor series (the paper's Lie series)"),
    ("eulerpoisson.solvers.symplectic", "Symplectic integrators"),
    ("eulerpoisson.solvers.rk", "Runge-Kutta (scipy)"),
    ("eulerpoisson.trajectory", "Trajectories"),
    ("eulerpoisson.io.read", "Reading trajectory files"),
    ("eulerpoisson.model.equations", "The model of the equations of motion"),
    ("eulerpoisson.analysis", "Analysis"),
    ("eulerpoisson.model.formulations", "The paper's formulations"),
    ("eulerpoisson.estimation", "Spin-state estimation"),
    ("eulerpoisson.io.observations", "Reading observations"),
    ("eulerpoisson.oracle", "The oracle"),
    ("eulerpoisson.testing", "Testing helpers"),
    ("eulerpoisson.sweep", "Sweeps"),
    ("eulerpoisson.io.stream", "Streaming long runs"),
    ("eulerpoisson.viz.plots", "Plots"),
    ("eulerpoisson.viz.animate", "Animations"),
    ("eulerpoisson.paper.audit", "The audit of the paper"),
    ("eulerpoisson.paper.symbolic", "The SymPy derivation"),
    ("eulerpoisson.paper.heavy_top", "The heavy top in the Gibbs vector"),
    ("eulerpoisson.errors", "Errors"),
    ("eulerpoisson.cli", "The command line"),
]


def _has_all(name: str) -> bool:
    return hasattr(importlib.import_module(name), "__all__")


def api_modules() -> list[tuple[str, str, list[str]]]:
    """``(module, title, names)`` for every documented module, in the reference's order."""
    import eulerpoisson

    names = [m for m, _ in CURATED]
    found = []
    for info in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson."):
        depth = info.name.count(".")
        if (info.ispkg or depth == 1) and not info.name.split(".")[-1].startswith("_"):
            found.append(info.name)
    found += ["eulerpoisson" + target for target in eulerpoisson._LAZY_MODULES.values()]
    for name in found:
        if name not in names and _has_all(name):
            names.append(name)
    titles = dict(CURATED)
    out = []
    for name in names:
        mod = importlib.import_module(name)
        if not hasattr(mod, "__all__"):
            raise RuntimeError(f"{name} has no __all__: it cannot be listed in the API reference")
        out.append((name, titles.get(name, name), list(mod.__all__)))
    return out


def aliases(modules) -> dict[str, str]:
    """Full name -> the full name where the same object is documented (names exported twice).

    An object is documented once, in its home: the first module of the reference that exports it, so
    ``ep.solve``, ``ep.Trajectory``... are documented as ``eulerpoisson.solve``, ``eulerpoisson.Trajectory``
    (the names users write) and the other pages say "alias of". References that the docstrings write
    relative to the defining module resolve through :func:`resolve_unqualified`.
    """
    import types

    module_pages = {m for m, _, _ in modules}
    exported: dict[tuple[int, str], list[str]] = {}
    out = {}
    for modname, _, names in modules:
        mod = importlib.import_module(modname)
        for name in names:
            obj = getattr(mod, name)
            if isinstance(obj, types.ModuleType):
                if obj.__name__ in module_pages:
                    out[f"{modname}.{name}"] = obj.__name__
                continue
            exported.setdefault((id(obj), name), []).append(modname)
    for (_, name), where in exported.items():
        if len(where) == 1:
            continue
        home = where[0]
        for m in where:
            if m != home:
                out[f"{m}.{name}"] = f"{home}.{name}"
    return out


def _write_if_changed(path: Path, text: str) -> None:
    """Rewrite only what changed, so that Sphinx's incremental builds stay incremental."""
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def write_api_pages(modules, srcdir: Path = DOCS) -> None:
    """One page per module (``api/<module>.rst``) and the toctree of the API index."""
    api = srcdir / "api"
    toc = [".. toctree::", "   :maxdepth: 1", ""]
    for modname, title, names in modules:
        heading = f"``{modname}``: {title}"
        lines = [
            ".. This page is generated by docs/_ext/ep_docs.py from the module's __all__.",
            "",
            heading,
            "=" * len(heading),
            "",
            f".. automodule:: {modname}",
            "   :no-members:",
            "",
            f".. currentmodule:: {modname}",
            "",
            ".. autosummary::",
            "   :toctree: generated/",
            "",
            *(f"   {n}" for n in names),
            "",
        ]
        _write_if_changed(api / f"{modname}.rst", "\n".join(lines))
        toc.append(f"   {modname}")
    _write_if_changed(api / "modules.rst.inc", "\n".join(toc) + "\n")


# ---------------------------------------------------------------------------
# the gallery
# ---------------------------------------------------------------------------

#: examples that need an optional peer: shown, run only where the peer imports
OPTIONAL_PEERS = {"validate_mujoco.py": "mujoco", "jax_fit.py": "jax"}


def executable_pattern() -> str:
    """sphinx-gallery's ``filename_pattern``: every example whose optional peer is installed."""
    import importlib.util
    import re

    missing = [f for f, mod in OPTIONAL_PEERS.items() if importlib.util.find_spec(mod) is None]
    if not missing:
        return r"/[^/]+\.py$"
    return r"/(?!(" + "|".join(re.escape(f) for f in missing) + r")$)[^/]+\.py$"


def output_dir(gallery_conf, src_file) -> Path:
    """The folder an example writes into during the build (``docs/_build/gallery_outputs/<name>``)."""
    return Path(gallery_conf["src_dir"]) / "_build" / "gallery_outputs" / Path(src_file).stem


_SEEN: dict[str, set] = {}


def reset_argv(gallery_conf, script_vars) -> list[str]:
    """Each example runs as ``python example.py OUTDIR`` with a fresh OUTDIR."""
    out = output_dir(gallery_conf, script_vars["src_file"])
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    _SEEN[str(out)] = set()
    return [str(out)]


def file_scraper(block, block_vars, gallery_conf) -> str:
    """The images an example wrote into its OUTDIR since the last code block, in the order written."""
    from sphinx_gallery.scrapers import figure_rst

    out = output_dir(gallery_conf, block_vars["src_file"])
    seen = _SEEN.setdefault(str(out), set())
    new = [p for p in out.rglob("*") if p.suffix.lower() in (".png", ".svg", ".jpg") and p not in seen]
    new.sort(key=lambda p: (p.stat().st_mtime_ns, str(p)))
    seen.update(new)
    images = []
    for src, dest in zip(new, block_vars["image_path_iterator"]):
        dest = Path(dest).with_suffix(src.suffix)
        shutil.copyfile(src, dest)
        images.append(dest)
    return figure_rst(images, gallery_conf["src_dir"])


def close_figures(gallery_conf, fname) -> None:
    """Between examples: no pyplot figure left open by the previous one."""
    import sys

    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close("all")


# ---------------------------------------------------------------------------
# the audit report
# ---------------------------------------------------------------------------

AUDIT_PAGE = "theory/audit_report.md"

_AUDIT_SKIPPED = """\
# The audit report

This build skipped the audit (``-D eulerpoisson_run_audit=0``). `make docs` runs it and puts
the full report here; it is also one command:

```sh
eulerpoisson audit --format md --out audit.md     # or json, tex
```

or, from Python, `eulerpoisson.paper.audit.run_audit().to_markdown()`.
"""


def write_audit_page(run: bool, srcdir: Path = DOCS) -> float:
    """Write the audit report page (the full report when ``run``); returns the seconds it took."""
    path = srcdir / AUDIT_PAGE
    start = time.perf_counter()
    if not run:
        text = _AUDIT_SKIPPED
    else:
        from eulerpoisson.paper.audit import run_audit

        report = run_audit().to_markdown()
        head, _, rest = report.partition("\n")
        note = (
            "This page is generated at build time by `eulerpoisson.paper.audit.run_audit()` (the same report as "
            "`eulerpoisson audit --format md`).\n"
        )
        text = head + "\n\n" + note + rest
    _write_if_changed(path, text)
    return time.perf_counter() - start


# ---------------------------------------------------------------------------
# cross-references
# ---------------------------------------------------------------------------

#: full names that are alias declarations (set by conf.py from :func:`aliases`)
ALIASES: dict[str, str] = {}
#: id of a documented object -> its documented full name (set by conf.py from :func:`homes`)
HOMES: dict[int, str] = {}


def homes(modules, alias_map) -> dict[int, str]:
    """id(object) -> the full name under which the object is documented."""
    out = {}
    for modname, _, names in modules:
        mod = importlib.import_module(modname)
        for name in names:
            full = f"{modname}.{name}"
            if full not in alias_map:
                out.setdefault(id(getattr(mod, name)), full)
    return out


def _documented_name(target: str) -> str | None:
    """A full name that imports (``eulerpoisson.io.read.LazyTrajectory``, ``eulerpoisson.paper.entries.ENTRIES``,
    ``eulerpoisson.trajectory.Trajectory.open``) -> the name under which that object is documented."""
    parts = target.split(".")
    if parts[0] != "eulerpoisson":
        return None
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for j in range(i, len(parts)):
            obj = getattr(obj, parts[j], None)
            if obj is None:
                return None
            home = HOMES.get(id(obj))
            if home is not None:
                return ".".join([home, *parts[j + 1 :]])
        return None
    return None


def internal_modules() -> set[str]:
    """Every module of the package, by full and by relative name (``core``, ``.core``, ``solvers.driver``).

    Docstrings name implementation modules with ``:mod:``; those are not in the API reference (only the
    public modules are), so such a reference is plain text, not an error. A misspelled one still is.
    """
    import eulerpoisson

    names = set()
    for info in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson."):
        parts = info.name.split(".")
        for i in range(len(parts)):
            tail = ".".join(parts[i:])
            names.update({tail, "." + tail})
    return names


def _lookup(obj, path: str) -> bool:
    """Whether ``obj.<path>`` names something: an attribute, a dataclass field, an annotation or an
    instance attribute that the class's code sets (``self.name = ...``)."""
    import inspect
    import re

    for part in path.split("."):
        if hasattr(obj, part):
            obj = getattr(obj, part)
            continue
        if part in getattr(obj, "__dataclass_fields__", {}) or part in getattr(obj, "__annotations__", {}):
            return True
        if inspect.isclass(obj):
            try:
                return re.search(rf"\bself\.{re.escape(part)}\s*[:=]", inspect.getsource(obj)) is not None
            except (OSError, TypeError):
                return False
        return False
    return True


def _import_path(path: str):
    """The object a dotted path names (a module, then attributes), or None."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for part in parts[i:]:
            obj = getattr(obj, part, None)
        return obj
    return None


def _of_package(obj) -> bool:
    return (getattr(obj, "__module__", None) or getattr(obj, "__name__", "")).startswith("eulerpoisson")


def _internal(node, target: str) -> bool:
    """The target names something of the package that exists but is not public (an implementation detail).

    Looked up where the docstring is shown (``py:module``, ``py:class``), where it was written (the
    object named in the node's source, ``...: docstring of eulerpoisson.model.body.RigidBody``) and as a
    full name.
    """
    import inspect
    import re

    places = []
    modname, clsname = node.get("py:module"), node.get("py:class")
    if modname and clsname:
        places.append(_import_path(f"{modname}.{clsname}"))
    if modname:
        places.append(_import_path(modname))
    written = re.search(r"docstring of ([\w.]+)", node.source or "")
    if written:
        obj = _import_path(written.group(1))
        if obj is not None:
            places.append(obj)
            owner = obj if inspect.isclass(obj) else None
            qual = getattr(obj, "__qualname__", "")
            mod = inspect.getmodule(obj)
            if owner is None and mod is not None and "." in qual:
                owner = _import_path(f"{mod.__name__}.{qual.rsplit('.', 1)[0]}")
            places += [owner, mod]
    if "." in target:
        places.append(_import_path(target.rsplit(".", 1)[0]))
    places = [p for p in places if p is not None and _of_package(p)]
    return any(_lookup(p, target) or _lookup(p, target.rsplit(".", 1)[-1]) for p in places)


def resolve_unqualified(app, env, node, contnode):
    """``missing-reference``: resolve what the docstrings name, else leave it to nitpicky.

    * a full name that imports (``eulerpoisson.io.read.LazyTrajectory``) links to where that object is
      documented;
    * a short name (``Taylor``, ``Trajectory.to_netcdf``) that names exactly one documented object of the
      package links to it, wherever the docstring that wrote it is shown;
    * a name that exists in the docstring's module or class but is not public (``MIN_MOMENT``,
      ``Method.run`` without a docstring) is plain text: an implementation detail, not a broken reference.

    Anything else (a misspelling, a removed function) stays a warning, an error under ``-W``.
    """
    if node.get("refdomain") != "py":
        return None
    target = node.get("reftarget", "").lstrip(".~")
    if not target:
        return None
    from sphinx.util.nodes import make_refnode

    domain = env.get_domain("py")
    types_ok = set(domain.objtypes_for_role(node.get("reftype", "obj")) or ())
    home = _documented_name(target)
    if home is not None and home in domain.objects and domain.objects[home].objtype in types_ok:
        obj = domain.objects[home]
        return make_refnode(app.builder, node["refdoc"], obj.docname, obj.node_id, contnode, home)
    suffix = "." + target
    private = target.split(".")[-1].startswith("_")
    found = [
        (name, obj)
        for name, obj in domain.objects.items()
        if (name == target or name.endswith(suffix)) and not obj.aliased and obj.objtype in types_ok and not private
    ]
    real = [(n, o) for n, o in found if n not in ALIASES]
    found = real or found
    if len({(o.docname, o.node_id) for _, o in found}) == 1:
        name, obj = found[0]
        return make_refnode(app.builder, node["refdoc"], obj.docname, obj.node_id, contnode, name)
    if not found and _internal(node, target):
        return contnode  # a name of the implementation, not in the API reference: plain text, no link
    return None


# ---------------------------------------------------------------------------
# module-level data
# ---------------------------------------------------------------------------

#: data without a ``#:`` comment anywhere in the package
EXTRA_DATA_DOCS = {
    "eulerpoisson.__version__": "The installed version of eulerpoisson (from the package metadata).",
}

_DATA_DOCS: dict | None = None


def _data_docs() -> dict:
    """(id(value), name) -> the ``#:`` comment where a module of the package defines it."""
    global _DATA_DOCS
    if _DATA_DOCS is None:
        from sphinx.pycode import ModuleAnalyzer

        import eulerpoisson

        _DATA_DOCS = {}
        names = ["eulerpoisson"] + [m.name for m in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson.")]
        for modname in names:
            try:
                found = ModuleAnalyzer.for_module(modname).find_attr_docs()
                mod = importlib.import_module(modname)
            except Exception:  # noqa: BLE001 - a module without source: nothing to read
                continue
            for (cls, name), lines in found.items():
                if cls == "" and hasattr(mod, name):
                    _DATA_DOCS.setdefault((id(getattr(mod, name)), name), list(lines))
    return _DATA_DOCS


def data_docstring(app, what, name, obj, options, lines) -> None:
    """``autodoc-process-docstring`` for module-level data documented where it is re-exported.

    autodoc reads a ``#:`` comment only in the module the page documents; a constant that
    ``eulerpoisson.oracle`` re-exports from ``eulerpoisson.oracle.runs`` would get the docstring of its
    type (``tuple``, ``float``...). Use the comment where the package defines it instead (or nothing).
    """
    import inspect

    if what != "data":
        return
    if name in EXTRA_DATA_DOCS:
        lines[:] = [EXTRA_DATA_DOCS[name], ""]
        return
    typedoc = inspect.cleandoc(type(obj).__doc__ or "")
    if typedoc and "\n".join(lines).strip() == typedoc.strip():
        lines[:] = _data_docs().get((id(obj), name.rsplit(".", 1)[-1]), [])
