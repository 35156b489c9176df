"""Every public function and class has a numpydoc ``Examples`` section that shows real output.

Public: the functions and classes named in ``eulerpoisson.__all__``, in the
``__all__`` of every subpackage (``eulerpoisson.attitude``,
``eulerpoisson.solvers``, ...), and in the ``__all__`` of the public modules
that ``eulerpoisson.__all__`` names (``eulerpoisson.torques``). Each needs
its own docstring (not an inherited one) with an ``Examples`` section holding
at least one ``>>>`` example followed by the output it prints, so that a new
public name cannot arrive without one. That the examples run and print what
they say is checked by ``tests/test_docs.py`` (doctest, module by module).
"""

import doctest
import importlib
import inspect
import pkgutil
import re
import types

import pytest

import eulerpoisson

SECTION = re.compile(r"^([A-Z][A-Za-z ]*)\n-{3,}\s*$", re.M)


def _public_namespaces() -> dict[str, types.ModuleType]:
    spaces = {"eulerpoisson": eulerpoisson}
    for info in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson."):
        if info.ispkg:
            mod = importlib.import_module(info.name)
            if hasattr(mod, "__all__"):
                spaces[info.name] = mod
    for name in eulerpoisson.__all__:
        obj = getattr(eulerpoisson, name)
        if isinstance(obj, types.ModuleType) and hasattr(obj, "__all__"):
            spaces[obj.__name__] = obj
    return spaces


def _public_callables() -> dict[str, object]:
    """``{"package.name": object}`` of every public function and class (each object once, first name wins)."""
    out, seen = {}, set()
    for space, mod in _public_namespaces().items():
        for name in mod.__all__:
            obj = getattr(mod, name)
            if not (inspect.isclass(obj) or inspect.isroutine(obj)) or id(obj) in seen:
                continue
            seen.add(id(obj))
            out[f"{space}.{name}"] = obj
    return out


PUBLIC = _public_callables()


def examples_section(doc: str) -> str | None:
    """The text of the numpydoc ``Examples`` section of a (cleaned) docstring, or None."""
    heads = list(SECTION.finditer(doc))
    for i, m in enumerate(heads):
        if m.group(1).strip() == "Examples":
            end = heads[i + 1].start() if i + 1 < len(heads) else len(doc)
            return doc[m.end() : end]
    return None


def test_the_public_api_is_found():
    for name in (
        "eulerpoisson.RigidBody",
        "eulerpoisson.solve",
        "eulerpoisson.Trajectory",
        "eulerpoisson.attitude.gibbs_compose",
        "eulerpoisson.solvers.TaylorOptions",
        "eulerpoisson.torques.Gravity",
        "eulerpoisson.oracle.validate",
        "eulerpoisson.sweep.run_sweep",
    ):
        assert name in PUBLIC or any(obj is _resolve(name) for obj in PUBLIC.values()), name
    assert len(PUBLIC) > 80


def _resolve(dotted: str):
    mod, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(mod), name)


def test_examples_section_parser():
    doc = (
        "Summary.\n\nParameters\n----------\nx : int\n\nExamples\n--------\n>>> 1 + 1\n2\n\nReferences\n----------\nA."
    )
    assert examples_section(doc).strip() == ">>> 1 + 1\n2"
    assert examples_section("Summary.\n\nNotes\n-----\n>>> 1\n1") is None


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_public_callable_has_examples_with_output(name):
    obj = PUBLIC[name]
    own = obj.__doc__  # a class's own docstring (inspect.getdoc would inherit its base's)
    assert own, f"{name} has no docstring"
    section = examples_section(inspect.cleandoc(own))
    assert section is not None, f"{name}: no numpydoc 'Examples' section (a heading 'Examples' underlined by dashes)"
    examples = doctest.DocTestParser().get_examples(section, name)
    assert examples, f"{name}: the Examples section has no '>>>' example"
    shown = [
        ex
        for ex in examples
        if ex.want.strip()
        and "+SKIP" not in ex.source
        and not any(flag == doctest.SKIP and on for flag, on in ex.options.items())
    ]
    assert shown, f"{name}: no example shows its output (a '>>>' line followed by what it prints, not skipped)"
