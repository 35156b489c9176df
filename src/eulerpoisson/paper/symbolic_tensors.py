r"""SymPy on first use and the small symbolic helpers of the derivation (part of :mod:`.symbolic`).

:func:`sympy_module` imports SymPy (the ``symbolic`` extra) when first
needed; the Levi-Civita symbol, the hat map, cross and dot products, the
cyclic tensor of eq. 1.21, the canonical Poisson bracket and the rotation
matrices from an axis and angle or a quaternion are built on it. Every name
is re-exported by :mod:`eulerpoisson.paper.symbolic`.

Examples
--------
>>> levi_civita(0, 1, 2), levi_civita(1, 0, 2), levi_civita(0, 0, 1)
(1, -1, 0)
"""

from __future__ import annotations

from ..errors import InvalidInputError, require

__all__ = [
    "sympy_module",
    "levi_civita",
    "hat",
    "cross",
    "dot",
    "cyclic_tensor",
    "poisson_bracket",
    "rotation_from_axis_angle",
    "rotation_from_quaternion",
]

_SYMPY = None


def sympy_module():
    """The ``sympy`` module, imported on first use (:class:`~eulerpoisson.errors.MissingDependencyError` without the ``symbolic`` extra)."""
    global _SYMPY
    if _SYMPY is None:
        _SYMPY = require("sympy", "symbolic")
    return _SYMPY


# ---------------------------------------------------------------------------
# small tensor helpers
# ---------------------------------------------------------------------------


def levi_civita(i: int, j: int, k: int) -> int:
    r"""Levi-Civita symbol :math:`\epsilon_{ijk}` for indices in ``{0, 1, 2}``.

    Parameters
    ----------
    i, j, k : int
        Indices, 0-based.

    Returns
    -------
    int
        ``+1`` for an even permutation of ``(0, 1, 2)``, ``-1`` for an odd one,
        ``0`` otherwise.
    """
    return (i - j) * (j - k) * (k - i) // 2


def hat(v):
    r"""The paper's antisymmetric matrix :math:`\hat v_{ij} = \epsilon_{ijp} v_p`.

    Note :math:`\hat v = -[v]_\times`, i.e. :math:`\hat v w = w\times v`
    (after eq. 1.21 of the paper).

    Parameters
    ----------
    v : sympy.Matrix, shape (3, 1)

    Returns
    -------
    sympy.Matrix, shape (3, 3)
    """
    sp = sympy_module()
    return sp.Matrix(3, 3, lambda i, j: sum(levi_civita(i, j, p) * v[p] for p in range(3)))


def cross(u, v):
    r"""Cross product :math:`[u, v]` of two 3-vectors (the paper's bracket notation).

    Parameters
    ----------
    u, v : sympy.Matrix, shape (3, 1)

    Returns
    -------
    sympy.Matrix, shape (3, 1)
    """
    sp = sympy_module()
    return sp.Matrix(3, 1, lambda i, _: sum(levi_civita(i, j, k) * u[j] * v[k] for j in range(3) for k in range(3)))


def dot(u, v):
    r"""Scalar product :math:`(u, v)` of two 3-vectors."""
    return sum(u[i] * v[i] for i in range(3))


def cyclic_tensor(v):
    r"""The paper's :math:`T_{ijk} = \hat v_{ij} v_k + \text{cycle}(ijk)` (eq. 1.21).

    .. math:: T_{ijk} = \hat v_{ij} v_k + \hat v_{jk} v_i + \hat v_{ki} v_j,
              \qquad \hat v_{ij} = \epsilon_{ijp} v_p .

    It equals :math:`(v\cdot v)\,\epsilon_{ijk}` (a consequence of the
    vanishing of totally antisymmetric 4-index tensors in three dimensions),
    which :mod:`eulerpoisson.paper.audit` verifies.

    Parameters
    ----------
    v : sympy.Matrix, shape (3, 1)

    Returns
    -------
    list of list of list
        ``T[i][j][k]`` as SymPy expressions.
    """
    h = hat(v)
    return [[[h[i, j] * v[k] + h[j, k] * v[i] + h[k, i] * v[j] for k in range(3)] for j in range(3)] for i in range(3)]


# ---------------------------------------------------------------------------
# Poisson bracket
# ---------------------------------------------------------------------------


def poisson_bracket(f, g, n, pi):
    r"""Canonical Poisson bracket of phase-space functions.

    .. math:: \{f, g\} = \sum_i \left(\frac{\partial f}{\partial n_i}
              \frac{\partial g}{\partial\pi_i} - \frac{\partial f}{\partial\pi_i}
              \frac{\partial g}{\partial n_i}\right),

    so that :math:`\{n_i, \pi_j\} = \delta_{ij}` (paper eq. 1.15.1).

    Parameters
    ----------
    f, g : sympy.Expr or sympy.Matrix
        Scalars or column vectors (shape ``(k, 1)``).
    n, pi : sequence of sympy.Symbol
        The canonical coordinates and momenta (same length).

    Returns
    -------
    sympy.Expr or sympy.Matrix
        A scalar if both are scalars; a column if one is a vector; the matrix
        ``{f_a, g_b}`` (shape ``(len(f), len(g))``) if both are vectors.
        Entries are returned unsimplified (use :func:`rsimp`).

    Raises
    ------
    InvalidInputError
        If ``n`` and ``pi`` have different lengths or contain non-symbols.
    """
    sp = sympy_module()
    n = list(n)
    pi = list(pi)
    if len(n) != len(pi) or not n:
        raise InvalidInputError(
            f"poisson_bracket: n and pi must be non-empty and of equal length, got {len(n)} and {len(pi)}"
        )
    if not all(isinstance(x, sp.Symbol) for x in n + pi):
        raise InvalidInputError("poisson_bracket: n and pi must contain sympy Symbols only")

    def pb(a, b):
        return sum(sp.diff(a, q) * sp.diff(b, p) - sp.diff(a, p) * sp.diff(b, q) for q, p in zip(n, pi))

    fm = isinstance(f, sp.MatrixBase)
    gm = isinstance(g, sp.MatrixBase)
    if fm and gm:
        fl, gl = list(f), list(g)
        return sp.Matrix(len(fl), len(gl), lambda a, b: pb(fl[a], gl[b]))
    if fm:
        return sp.Matrix([pb(a, g) for a in f])
    if gm:
        return sp.Matrix([pb(f, b) for b in g])
    return pb(f, g)


# ---------------------------------------------------------------------------
# rotation matrices
# ---------------------------------------------------------------------------


def rotation_from_axis_angle(k, cos_a, sin_a):
    r"""Rotation matrix of the construction before eq. 1.7.

    The image of a point is :math:`x' = Px + Nx\cos\alpha + [k, x]\sin\alpha`
    with the projectors :math:`P = kk^T`, :math:`N = 1 - kk^T` (eq. 1.6);
    the matrix is the Jacobian :math:`R_{ij} = \partial x'_i/\partial x_j`.

    Parameters
    ----------
    k : sympy.Matrix, shape (3, 1)
        Unit rotation axis.
    cos_a, sin_a : sympy.Expr
        :math:`\cos\alpha` and :math:`\sin\alpha`.

    Returns
    -------
    sympy.Matrix, shape (3, 3)
    """
    sp = sympy_module()
    x = sp.Matrix(sp.symbols("x_1:4"))
    P = k * k.T
    N = sp.eye(3) - P
    xp = P * x + N * x * cos_a + cross(k, x) * sin_a
    return xp.jacobian(x).applyfunc(sp.expand)


def rotation_from_quaternion(q0, q):
    r"""Active rotation matrix of a (not necessarily unit) quaternion.

    .. math:: R = \frac{(q_0^2 - q\cdot q)\,1 + 2 q q^T + 2 q_0 [q]_\times}
              {q_0^2 + q\cdot q}, \qquad ([q]_\times)_{ij} = -\epsilon_{ijk} q_k .

    Parameters
    ----------
    q0 : sympy.Expr
        Scalar part.
    q : sympy.Matrix, shape (3, 1)
        Vector part.

    Returns
    -------
    sympy.Matrix, shape (3, 3)
    """
    sp = sympy_module()
    qq = dot(q, q)
    qx = -hat(q)
    return ((q0**2 - qq) * sp.eye(3) + 2 * q * q.T + 2 * q0 * qx) / (q0**2 + qq)
