r"""The formulations' right-hand sides and Hamiltonians as plain kernels (part of :mod:`.formulations`).

Written with ``+ - * /`` only, on *component-first* inputs: a vector is
anything with ``v[0], v[1], v[2]`` (a tuple of floats, a 1-D array, an
array of shape ``(3, ...)``, sympy symbols, truncated Taylor series) and a
matrix anything with ``M[i][j]``; they return tuples. The formulation
objects (:mod:`eulerpoisson.model.formulations`, which re-exports every
name) call them with ``np.moveaxis(x, -1, 0)``; :func:`numba_kernels`
compiles them with numba.

Examples
--------
>>> euler_rhs((1.0, 0.0, 0.0), ((1.0, 0, 0), (0, 2.0, 0), (0, 0, 3.0)), ((1.0, 0, 0), (0, 0.5, 0), (0, 0, 1 / 3)))
(0.0, 0.0, 0.0)
"""

from __future__ import annotations

import types

__all__ = [
    "euler_rhs",
    "kinetic_energy",
    "euler_poisson_rhs",
    "canonical_hamiltonian",
    "canonical_rhs",
    "momentum_hamiltonian",
    "momentum_rhs",
    "velocity_rhs",
    "geodesic_energy",
    "geodesic_rhs",
    "numba_kernels",
    "a_transpose_v",
]


# ---------------------------------------------------------------------------
# component-first helpers (only + - * /; usable by numpy, numba, sympy, jets)
# ---------------------------------------------------------------------------
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _mv(M, v):
    return (
        M[0][0] * v[0] + M[0][1] * v[1] + M[0][2] * v[2],
        M[1][0] * v[0] + M[1][1] * v[1] + M[1][2] * v[2],
        M[2][0] * v[0] + M[2][1] * v[1] + M[2][2] * v[2],
    )


def _atilde_v(n, v):
    # Ã v = v + n (n.v) - n x v
    nv = _dot(n, v)
    c = _cross(n, v)
    return (v[0] + n[0] * nv - c[0], v[1] + n[1] * nv - c[1], v[2] + n[2] * nv - c[2])


def _atilde_t_v(n, v):
    # Ã^T v = v + n (n.v) + n x v
    nv = _dot(n, v)
    c = _cross(n, v)
    return (v[0] + n[0] * nv + c[0], v[1] + n[1] * nv + c[1], v[2] + n[2] * nv + c[2])


def _a_t_v(n, v):
    # A^T v = (v - n x v) / (1 + n^2)
    inv_s = 1.0 / (1.0 + _dot(n, n))
    c = _cross(n, v)
    return ((v[0] - c[0]) * inv_s, (v[1] - c[1]) * inv_s, (v[2] - c[2]) * inv_s)


# ---------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------
def euler_rhs(W, I, Iinv):
    r"""Euler's equations :math:`\dot{\boldsymbol\Omega} = I^{-1}[(I\boldsymbol\Omega)\times\boldsymbol\Omega]` (kernel).

    Parameters
    ----------
    W : vector (component-first)
        Body angular velocity :math:`\boldsymbol\Omega`.
    I, Iinv : matrix (component-first, ``M[i][j]``)
        Inertia tensor and its inverse.

    Returns
    -------
    tuple of 3 components

    References
    ----------
    Paper eq. 1.5 and 1.30.
    """
    M = _mv(I, W)
    return _mv(Iinv, _cross(M, W))


def kinetic_energy(W, I):
    r""":math:`E = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega` (kernel; paper eq. 1.25, 1.27)."""
    return 0.5 * _dot(W, _mv(I, W))


def euler_poisson_rhs(R, W, I, Iinv):
    r"""Euler-Poisson equations in :math:`(R, \boldsymbol\Omega)` (kernel).

    .. math:: \dot R = R[\boldsymbol\Omega]_\times, \qquad
              I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega

    Row :math:`i` of :math:`\dot R` is :math:`\mathbf r_i\times\boldsymbol\Omega`
    with :math:`\mathbf r_i` row :math:`i` of :math:`R`.

    Parameters
    ----------
    R : matrix (component-first, ``R[i][j]``)
    W : vector
    I, Iinv : matrix

    Returns
    -------
    (Rdot, Wdot) : tuple of 3 row tuples, tuple of 3 components

    References
    ----------
    Paper eq. 1.4 (:math:`\dot R_{ij} = -\epsilon_{jkm}\Omega_k R_{im}`) and 1.5.
    """
    Rdot = (_cross(R[0], W), _cross(R[1], W), _cross(R[2], W))
    return Rdot, euler_rhs(W, I, Iinv)


def canonical_hamiltonian(n, p, Iinv):
    r""":math:`H = \tfrac18(\tilde A\boldsymbol\pi)^T I^{-1}(\tilde A\boldsymbol\pi)` (kernel; paper eq. 1.15)."""
    u = _atilde_v(n, p)
    return 0.125 * _dot(u, _mv(Iinv, u))


def canonical_rhs(n, p, Iinv):
    r"""Canonical equations in :math:`(\mathbf n, \boldsymbol\pi)` (kernel, polynomial).

    .. math::
        \dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega, \qquad
        \dot{\boldsymbol\pi} = -\tfrac12\left[(\mathbf n\cdot\boldsymbol\pi)\boldsymbol\Omega
        + (\mathbf n\cdot\boldsymbol\Omega)\boldsymbol\pi + \boldsymbol\Omega\times\boldsymbol\pi\right],
        \qquad \boldsymbol\Omega = \tfrac12 I^{-1}\tilde A\boldsymbol\pi .

    :math:`\dot{\mathbf n}` is of degree 4 in :math:`\mathbf n` and linear in
    :math:`\boldsymbol\pi`; :math:`\dot{\boldsymbol\pi}` of degree 3 in
    :math:`\mathbf n` and quadratic in :math:`\boldsymbol\pi`.
    The paper's eq. 1.16 prints :math:`\epsilon_{ijk}n_k` in the bracket of
    :math:`\dot\pi_i`; :math:`-\partial H/\partial n_i` has :math:`\epsilon_{ijk}\pi_k`.

    Parameters
    ----------
    n, p : vector (component-first)
        Gibbs vector and canonical momentum :math:`\boldsymbol\pi`.
    Iinv : matrix

    Returns
    -------
    (ndot, pidot) : two tuples of 3 components

    References
    ----------
    Paper eq. 1.14, 1.16 (corrected).
    """
    u = _atilde_v(n, p)
    Wh = _mv(Iinv, u)
    W = (0.5 * Wh[0], 0.5 * Wh[1], 0.5 * Wh[2])
    nd = _atilde_t_v(n, W)
    ndot = (0.5 * nd[0], 0.5 * nd[1], 0.5 * nd[2])
    npi = _dot(n, p)
    nw = _dot(n, W)
    c = _cross(W, p)
    pidot = (
        -0.5 * (npi * W[0] + nw * p[0] + c[0]),
        -0.5 * (npi * W[1] + nw * p[1] + c[1]),
        -0.5 * (npi * W[2] + nw * p[2] + c[2]),
    )
    return ndot, pidot


def momentum_hamiltonian(n, m, Iinv):
    r""":math:`H = \tfrac12\mathbf m^T R I^{-1}R^T\mathbf m` (kernel; footnote to eq. 1.20, eq. 1.25).

    Uses :math:`R^T\mathbf m = \tilde A A^T\mathbf m = \tilde A(\mathbf m - \mathbf n\times\mathbf m)/(1+\mathbf n^2)`.
    """
    Mb = _atilde_v(n, _a_t_v(n, m))
    return 0.5 * _dot(Mb, _mv(Iinv, Mb))


def momentum_rhs(n, m, Iinv):
    r"""Equations in :math:`(\mathbf n, \mathbf m)` (kernel, rational).

    .. math:: \dot{\mathbf n} = \tfrac12\tilde A^T I^{-1}R^T\mathbf m, \qquad \dot{\mathbf m} = 0

    Returns
    -------
    (ndot, mdot) : two tuples of 3 components

    References
    ----------
    Paper eq. 1.20.
    """
    Mb = _atilde_v(n, _a_t_v(n, m))
    W = _mv(Iinv, Mb)
    nd = _atilde_t_v(n, W)
    return (0.5 * nd[0], 0.5 * nd[1], 0.5 * nd[2]), (0.0 * m[0], 0.0 * m[1], 0.0 * m[2])


def velocity_rhs(n, W, I, Iinv):
    r"""Equations in :math:`(\mathbf n, \boldsymbol\Omega)` (kernel, polynomial).

    .. math:: \dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega, \qquad
              I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega

    Returns
    -------
    (ndot, Wdot) : two tuples of 3 components

    References
    ----------
    Paper eq. 1.30.
    """
    nd = _atilde_t_v(n, W)
    return (0.5 * nd[0], 0.5 * nd[1], 0.5 * nd[2]), euler_rhs(W, I, Iinv)


def geodesic_energy(n, v, I):
    r""":math:`L = \tfrac12\dot{\mathbf n}^T G\dot{\mathbf n} = 2\mathbf w^T I\mathbf w`, :math:`\mathbf w = A^T\dot{\mathbf n}` (kernel; eq. 1.13)."""
    w = _a_t_v(n, v)
    return 2.0 * _dot(w, _mv(I, w))


def geodesic_rhs(n, v, I, Iinv):
    r"""Geodesic equation :math:`\ddot n^i = -\Gamma^i_{jk}\dot n^j\dot n^k` of :math:`G = 4AIA^T` (kernel, rational).

    .. math::
        \ddot{\mathbf n} = \frac{2(\mathbf n\cdot\dot{\mathbf n})}{1+\mathbf n^2}\dot{\mathbf n}
        + 2\tilde A^T I^{-1}\left[(I\mathbf w)\times\mathbf w\right], \qquad
        \mathbf w = A^T\dot{\mathbf n}

    Parameters
    ----------
    n, v : vector (component-first)
        :math:`\mathbf n` and :math:`\dot{\mathbf n}`.
    I, Iinv : matrix

    Returns
    -------
    (ndot, nddot) : two tuples of 3 components (``ndot`` is ``v``)

    References
    ----------
    Paper eq. 1.11, 1.13 (the Lagrangian whose Euler-Lagrange equations these are).
    """
    inv_s = 1.0 / (1.0 + _dot(n, n))
    w = _a_t_v(n, v)
    d = _atilde_t_v(n, _mv(Iinv, _cross(_mv(I, w), w)))
    f = 2.0 * _dot(n, v) * inv_s
    return (v[0], v[1], v[2]), (f * v[0] + 2.0 * d[0], f * v[1] + 2.0 * d[1], f * v[2] + 2.0 * d[2])


_KERNELS = (
    "_dot",
    "_cross",
    "_mv",
    "_atilde_v",
    "_atilde_t_v",
    "_a_t_v",
    "euler_rhs",
    "kinetic_energy",
    "euler_poisson_rhs",
    "canonical_hamiltonian",
    "canonical_rhs",
    "momentum_hamiltonian",
    "momentum_rhs",
    "velocity_rhs",
    "geodesic_energy",
    "geodesic_rhs",
)


def numba_kernels(**jit_options):
    """Numba-compiled copies of the kernels.

    Every kernel and helper is re-created with a private globals dictionary
    in which the helpers are the compiled ones, then wrapped in
    ``numba.njit(**jit_options)``; compilation happens on first call. Call
    them with 1-D float arrays (vectors) and 2-D arrays (matrices).

    Parameters
    ----------
    **jit_options
        Passed to ``numba.njit`` (e.g. ``cache=True``, ``fastmath=False``).

    Returns
    -------
    types.SimpleNamespace
        Attributes named like the kernels (``canonical_rhs``, ...).

    Raises
    ------
    MissingDependencyError
        If numba is not installed (extra ``fast``).
    """
    from ..errors import require

    numba = require("numba", "fast")
    g = dict(globals())
    out = {}
    for name in _KERNELS:
        f = globals()[name]
        copy = types.FunctionType(f.__code__, g, name, f.__defaults__, f.__closure__)
        out[name] = numba.njit(**jit_options)(copy)
        g[name] = out[name]
    return types.SimpleNamespace(**{k: v for k, v in out.items() if not k.startswith("_")})


#: :math:`A^T\mathbf v = (\mathbf v - \mathbf n\times\mathbf v)/(1+\mathbf n^2)` (component-first), for the
#: conversions of the formulations
a_transpose_v = _a_t_v
