r"""The transcription language of the paper audit (part of :mod:`.audit`).

A transcription (:mod:`eulerpoisson.paper.entries`) is Python source over
SymPy: a chain of sides joined by ``==`` (:func:`split_chain`), each
compiled once (:func:`compile_source`) and evaluated in the namespace of a
frame (:func:`eval_source`), or once per index for an indexed formula
(:func:`eval_indexed`, with :class:`T3` for three-index objects).

Examples
--------
>>> split_chain("f(a == b) == c == d")
['f(a == b)', 'c', 'd']
"""

from __future__ import annotations

import functools

import numpy as np

from ..errors import InvalidInputError
from .symbolic import sympy_module as _sp

__all__ = [
    "compile_source",
    "T3",
    "split_chain",
    "eval_indexed",
    "eval_source",
    "as_object",
    "flatten",
    "resolve",
]

# ---------------------------------------------------------------------------
# transcription language
# ---------------------------------------------------------------------------


@functools.cache
def compile_source(src: str):
    """Compile a transcription (numbers as SymPy rationals); cached per source."""
    from sympy.parsing.sympy_parser import auto_number, stringify_expr

    try:
        code = stringify_expr(src, {}, {}, (auto_number,))
        return compile(code, "<transcription>", "eval")
    except SyntaxError as exc:
        raise InvalidInputError(f"transcription is not valid Python: {src!r} ({exc})") from exc


class T3:
    """A 3-index tensor with ``T[i, j, k]`` access (private)."""

    def __init__(self, data):
        self.data = data

    def __getitem__(self, idx):
        i, j, k = idx
        return self.data[int(i)][int(j)][int(k)]


def split_chain(src: str) -> list[str]:
    """The sides of a chain ``a == b == c`` (an ``==`` inside brackets does not split)."""
    parts: list[str] = []
    cur: list[str] = []
    depth, i = 0, 0
    while i < len(src):
        c = src[i]
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        if depth == 0 and src.startswith("==", i):
            parts.append("".join(cur).strip())
            cur = []
            i += 2
            continue
        cur.append(c)
        i += 1
    parts.append("".join(cur).strip())
    return parts


def eval_indexed(src: str, index: str, ns: dict) -> list:
    """Evaluate ``src`` for all values of the free indices; flat list (row-major)."""
    code = compile_source(src)
    idx = list(index)
    out = []
    if not idx:
        return [eval_source(code, ns, src)]
    import itertools

    saved = {name: ns[name] for name in idx if name in ns}
    try:
        for vals in itertools.product(range(3), repeat=len(idx)):
            for name, v in zip(idx, vals):
                ns[name] = v
            out.append(eval_source(code, ns, src))
    finally:
        for name in idx:
            ns.pop(name, None)
        ns.update(saved)
    return out


def eval_source(code, ns, src):
    """Evaluate compiled ``code`` in the frame namespace ``ns`` (a 1x1 matrix becomes its entry)."""
    sp = _sp()
    try:
        v = eval(code, ns)  # noqa: S307 - transcriptions are package data
    except Exception as exc:
        raise InvalidInputError(f"cannot evaluate transcription {src!r}: {type(exc).__name__}: {exc}") from exc
    if isinstance(v, sp.MatrixBase) and v.shape == (1, 1):
        v = v[0, 0]
    return sp.sympify(v) if not isinstance(v, (bool, np.bool_)) else v


def as_object(flat: list, index: str):
    """A scalar, vector, matrix or :class:`T3` from a flat row-major list with free indices ``index``."""
    sp = _sp()
    if len(index) == 0:
        return flat[0]
    if len(index) == 1:
        return sp.Matrix(flat)
    if len(index) == 2:
        return sp.Matrix(3, 3, flat)
    return T3([[[flat[9 * i + 3 * j + k] for k in range(3)] for j in range(3)] for i in range(3)])


def flatten(v) -> list:
    """The components of a value (scalar, matrix, :class:`T3`, nested lists) as a flat list."""
    sp = _sp()
    if isinstance(v, T3):
        return [v.data[i][j][k] for i in range(3) for j in range(3) for k in range(3)]
    if isinstance(v, sp.MatrixBase):
        return list(v)
    if isinstance(v, (list, tuple)):
        out = []
        for x in v:
            out.extend(flatten(x))
        return out
    return [sp.sympify(v)]


def resolve(x):
    """The value to compare of ``x`` (the identity: values are evaluated eagerly)."""
    return x
