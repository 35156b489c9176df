r"""The paper's formulations of the free rigid body as numeric objects.

Five coordinate systems describe the same motion. Each is a
:class:`Formulation`: the state layout, the right-hand side, the Hamiltonian,
the Poisson tensor and the integrals, side by side, all batched over leading
axes (states of shape ``(..., d)``) and valid for any symmetric
positive-definite inertia tensor :math:`I` (not only a diagonal one).

========================  =========================  ====  ==========================
registry name             variables                  d     paper equations
========================  =========================  ====  ==========================
``"euler-poisson"``       :math:`(R, \Omega)`        12    1.4, 1.5, 1.25
``"canonical"``           :math:`(n, \pi)`           6     1.13-1.19
``"momentum"``            :math:`(n, m)`             6     1.17, 1.20-1.23
``"velocity"``            :math:`(n, \Omega)`        6     1.26-1.30
``"geodesic"``            :math:`(n, \dot n)`        6     1.11, 1.13, 1.14
========================  =========================  ====  ==========================

Derivations (all checked numerically in ``tests/test_formulations.py``)
-----------------------------------------------------------------------
Write :math:`s = 1+\mathbf n^2`, :math:`N = [\mathbf n]_\times`,
:math:`A = (\mathbf 1+N)/s`, :math:`\tilde A = A^{-1} = \mathbf 1+\mathbf n\mathbf n^T-N`
(eq. 1.12 corrected). Then :math:`\tilde A^T\tilde A = s(\mathbf 1+\mathbf n\mathbf n^T)`,
:math:`R = A\tilde A^T`, :math:`R^T = \tilde A A^T`, :math:`\det A = s^{-2}`.

* Kinematics: :math:`\boldsymbol\Omega = 2A^T\dot{\mathbf n}`,
  :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega
  = \tfrac12(\boldsymbol\Omega + \mathbf n\times\boldsymbol\Omega + (\mathbf n\cdot\boldsymbol\Omega)\mathbf n)`.
* Momenta: :math:`\boldsymbol\pi = G\dot{\mathbf n} = 2AI\boldsymbol\Omega`,
  :math:`\mathbf M = I\boldsymbol\Omega = \tfrac12\tilde A\boldsymbol\pi`,
  :math:`\mathbf m = R\mathbf M = \tfrac12\tilde A^T\boldsymbol\pi` (because
  :math:`A\tilde A^T\tilde A = \tilde A^T`).
* Canonical equations: :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega` and
  :math:`\dot{\boldsymbol\pi} = -\tfrac12\left[(\mathbf n\cdot\boldsymbol\pi)\boldsymbol\Omega
  + (\mathbf n\cdot\boldsymbol\Omega)\boldsymbol\pi + \boldsymbol\Omega\times\boldsymbol\pi\right]`,
  i.e. :math:`\dot\pi_i = -\tfrac14[\delta_{ij}(\mathbf n\cdot\boldsymbol\pi) + \pi_i n_j
  + \epsilon_{ijk}\pi_k](I^{-1}\tilde A\boldsymbol\pi)_j`. The paper's eq. 1.16
  prints :math:`\epsilon_{ijk}n_k`; the correct last term has :math:`\pi_k`.
* Brackets. The flow of :math:`m_j` is the left rotation about
  :math:`\mathbf e_j`, the flow of :math:`M_j` the right one, so
  :math:`\{n_i, m_j\} = \tfrac12\tilde A_{ij}`, :math:`\{m_i, m_j\} = \epsilon_{ijk}m_k`,
  :math:`\{n_i, M_j\} = \tfrac12\tilde A_{ji}`, :math:`\{M_i, M_j\} = -\epsilon_{ijk}M_k`,
  :math:`\{m_i, M_j\} = 0` (eq. 1.18). The cyclic term of eqs. 1.21 and 1.28 is
  :math:`\hat n_{ij}n_k + \mathrm{cycle} = \mathbf n^2\epsilon_{ijk}` (three-dimensional
  Schouten identity), so the printed brackets are right but simplify:
  :math:`\{m_i,m_j\}` is exactly the :math:`so(3)` bracket and does not depend on
  :math:`\mathbf n`.
* Geodesic equation: differentiating :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega`
  and using Euler's equation gives

  .. math::
      \ddot{\mathbf n} = \frac{2(\mathbf n\cdot\dot{\mathbf n})}{s}\dot{\mathbf n}
      + 2\tilde A^T I^{-1}\left[(I\mathbf w)\times\mathbf w\right],\qquad
      \mathbf w = A^T\dot{\mathbf n} = \frac{\dot{\mathbf n}-\mathbf n\times\dot{\mathbf n}}{s},

  whose symmetric part is the Christoffel symbol of :math:`G = 4AIA^T`
  (see :func:`christoffel`). For :math:`I\propto\mathbf 1` only the first term
  survives: the geodesics are reparametrized straight lines (gnomonic chart of
  :math:`S^3`).

With a potential (the heavy top, the gravity gradient)
------------------------------------------------------
``formulation(name, body, torque=...)`` adds a conservative torque
(:class:`~eulerpoisson.torques.Gravity`,
:class:`~eulerpoisson.torques.GravityGradient`, any
:class:`~eulerpoisson.torques.Torque` with ``conservative = True`` and a
:meth:`~eulerpoisson.torques.Torque.potential`): :math:`H = H_0 + U(t, R)`
with the *same* Poisson tensor. Its body-frame torque is minus the body-frame
gradient of :math:`U`: along :math:`\delta R = R[\delta\boldsymbol\theta]_\times`,
:math:`\delta U = -\boldsymbol\tau\cdot\delta\boldsymbol\theta`. In the Gibbs
chart :math:`\delta\boldsymbol\theta = 2A^T\delta\mathbf n` (eq. 1.11), so

.. math::
    \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau,\qquad
    \dot{\boldsymbol\pi} = -\frac{\partial H_0}{\partial\mathbf n} + 2A\boldsymbol\tau,

(:func:`gibbs_potential_gradient`), consistent with Euler's equations since
:math:`\mathbf M = \tfrac12\tilde A\boldsymbol\pi` gains
:math:`\tfrac12\tilde A(2A\boldsymbol\tau) = \boldsymbol\tau`. Pushed to the
other charts with the brackets above: :math:`I\dot{\boldsymbol\Omega}` gains
:math:`\boldsymbol\tau` in :math:`(R, \boldsymbol\Omega)` and
:math:`(\mathbf n, \boldsymbol\Omega)`; :math:`\dot{\mathbf m}` gains
:math:`-\tfrac12\tilde A^T\partial_{\mathbf n}U = \tilde A^TA\boldsymbol\tau = R\boldsymbol\tau`
in :math:`(\mathbf n, \mathbf m)` (:math:`\tilde A^TA = A\tilde A^T` since
:math:`[\mathbf n]_\times` and :math:`\mathbf n\mathbf n^T` commute); and
:math:`\ddot{\mathbf n}` gains :math:`-G^{-1}\partial_{\mathbf n}U = \tfrac12\tilde A^TI^{-1}\boldsymbol\tau`
in :math:`(\mathbf n, \dot{\mathbf n})` (Euler-Lagrange equations of
:math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U`). A
time-dependent potential (the gravity gradient) makes the vector field depend
on the time: ``vector_field(state, t)``, ``rhs(t, y)``. The symbolic
derivation from the Lagrangian is :func:`eulerpoisson.paper.heavy_top.derive_heavy_top`.

Where the printed paper differs (each checked numerically in the tests)
-----------------------------------------------------------------------
* Eq. 1.12: :math:`\tilde A_{ij}` has :math:`n_in_j`, not :math:`n_jn_j`.
* Eq. 1.16: the last term of :math:`\dot\pi_i` is :math:`\epsilon_{ijk}\pi_k`, not
  :math:`\epsilon_{ijk}n_k` (the printed one is not :math:`-\partial H/\partial n_i`).
* Text after eq. 1.13: :math:`G(\mathbf 0) = 4I`, not :math:`\delta`.
* Footnote to eq. 1.17: at :math:`\mathbf n = 0`,
  :math:`E = \tfrac12 I^{-1}_{ij}m_im_j` (the factor :math:`\tfrac12` is missing).
* Eqs. 1.21, 1.28 are correct; with eq. 1.22 they reduce to
  :math:`\{m_i,m_j\} = \epsilon_{ijk}m_k` and :math:`\{\Omega_i,\Omega_j\} = -I^{-1}_{ia}I^{-1}_{jb}\epsilon_{abc}M_c`.

Kernels
-------
The right-hand sides and Hamiltonians are also plain *kernels*
(:func:`canonical_rhs`, :func:`geodesic_rhs`, ...) written with ``+ - * /``
only, on *component-first* inputs: a vector is anything with ``v[0], v[1],
v[2]`` (a tuple of floats, a 1-D array, an array of shape ``(3, ...)``, sympy
symbols, truncated Taylor series) and a matrix anything with ``M[i][j]``.
They return tuples. The objects call them with ``np.moveaxis(x, -1, 0)``;
:func:`numba_kernels` compiles them with numba.

Poisson bracket convention: :math:`\{f, g\} = \partial_{\mathbf n}f\cdot\partial_{\boldsymbol\pi}g
- \partial_{\boldsymbol\pi}f\cdot\partial_{\mathbf n}g`, :math:`\{n_i,\pi_j\} = \delta_{ij}`,
:math:`P_{ab} = \{z_a, z_b\}` and :math:`\dot z = P(z)\nabla H(z)`.

References
----------
A. A. Deriglazov, *Geodesic motion on the symplectic leaf of SO(3) with
distorted e(3) algebra and Liouville integrability of a free rigid body*
(the paper), eqs. 1.4-1.30.
J. E. Marsden and T. S. Ratiu, *Introduction to Mechanics and Symmetry*,
2nd ed., Springer (1999), ch. 13-15 (momentum maps of left and right actions).
"""

from __future__ import annotations

import types

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..attitude.core import (
    conversion_matrix,
    gibbs_from_quaternion,
    inverse_conversion_matrix,
    inverse_metric,
    matrix_from_gibbs,
    matrix_from_quaternion,
    metric,
    quaternion_from_gibbs,
    quaternion_from_matrix,
    skew,
)
from ..errors import InvalidInputError, SingularChartError, UnsupportedModelError
from ..util.validate import as_float_array
from .body import RigidBody
from .torques import Gravity, GravityGradient, Torque, TorqueLike, as_torques

__all__ = [
    "Formulation",
    "EulerPoisson",
    "Canonical",
    "Momentum",
    "Velocity",
    "Geodesic",
    "FORMULATIONS",
    "formulation",
    "gibbs_potential_gradient",
    # Lagrangian side
    "metric_derivative",
    "christoffel",
    "christoffel_from_metric",
    "lagrangian",
    "canonical_momentum",
    "geodesic_acceleration",
    # kernels
    "euler_rhs",
    "kinetic_energy",
    "euler_poisson_rhs",
    "canonical_rhs",
    "canonical_hamiltonian",
    "momentum_rhs",
    "momentum_hamiltonian",
    "velocity_rhs",
    "geodesic_rhs",
    "geodesic_energy",
    "numba_kernels",
]

# Levi-Civita symbol and the generators E_k = [e_k]x, E[k, a, b] = -eps_{kab}
_EPS3 = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _EPS3[_i, _j, _k] = 1.0
    _EPS3[_i, _k, _j] = -1.0
_GEN = -_EPS3


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


# ---------------------------------------------------------------------------
# array helpers
# ---------------------------------------------------------------------------
def _cf(x):
    """(..., 3) -> (3, ...) component-first view."""
    return np.moveaxis(x, -1, 0)


def _cf2(M):
    """(..., 3, 3) -> (3, 3, ...) component-first view."""
    return np.moveaxis(M, (-2, -1), (0, 1))


def _stack(comps):
    return np.stack(np.broadcast_arrays(*comps), axis=-1)


def _T(M):
    return np.swapaxes(M, -1, -2)


def _antisym(M):
    # exact antisymmetry (the products are antisymmetric up to rounding)
    return 0.5 * (M - _T(M))


def _mvec(M, v):
    return np.einsum("...ij,...j->...i", M, v)


def _as_body(body) -> RigidBody:
    if isinstance(body, RigidBody):
        return body
    if isinstance(body, Formulation):
        return body.body
    from .equations import Model

    if isinstance(body, Model):
        return body.body
    return RigidBody(body)


#: what ``torque=`` of the formulations accepts (for the error messages)
_ACCEPTED = (
    "None (the free body), or conservative torques: eulerpoisson.torques.Gravity, "
    "eulerpoisson.torques.GravityGradient (or any Torque with conservative = True and a "
    "potential), or a list of them"
)


def _potential_torques(body, torque, where: str) -> tuple:
    """The conservative torques of ``torque=`` (and of a Model given as ``body``) as a tuple."""
    from .equations import Model

    if isinstance(body, Model):
        if torque is not None:
            raise TypeError(f"{where}: give the torque either in the Model or as torque=, not both")
        torque = list(body.torques) or None
    elif isinstance(body, Formulation) and torque is None:
        torque = list(body.torques) or None
    try:
        torques = as_torques(torque)
    except TypeError as exc:
        raise TypeError(f"{where}: torque must be {_ACCEPTED}; got {torque!r}") from exc
    for tq in torques:
        if not (isinstance(tq, Torque) and tq.conservative and not tq.depends_on_omega):
            raise UnsupportedModelError(
                f"{where}: torque {tq!r} derives from no potential U(t, R), and the formulations are "
                f"Hamiltonian (H = H0 + U); torque must be {_ACCEPTED}. For non-conservative torques use "
                f"eulerpoisson.solve(..., torque=..., method='rk' or 'taylor')"
            )
    return torques


def gibbs_potential_gradient(n: ArrayLike, tau: ArrayLike) -> NDArray[np.float64]:
    r"""Gradient :math:`\partial U/\partial\mathbf n` of a potential from its body-frame torque.

    A potential :math:`U(R)` whose torque is :math:`\boldsymbol\tau`
    (:math:`\delta U = -\boldsymbol\tau\cdot\delta\boldsymbol\theta` for
    :math:`\delta R = R[\delta\boldsymbol\theta]_\times`) has, in the Gibbs
    chart where :math:`\delta\boldsymbol\theta = 2A^T(\mathbf n)\delta\mathbf n`
    (eq. 1.11),

    .. math::
        \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau
        = -\frac{2}{1+\mathbf n^2}\left(\boldsymbol\tau + \mathbf n\times\boldsymbol\tau\right).

    Parameters
    ----------
    n : array_like, shape (..., 3)
        Gibbs vectors.
    tau : array_like, shape (..., 3)
        Body-frame torques :math:`\boldsymbol\tau(R(\mathbf n))` (broadcast against ``n``).

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    References
    ----------
    Paper eq. 1.9, 1.11, 1.12 (:math:`A`), 1.15-1.16 (the canonical equations
    it enters: :math:`\dot{\boldsymbol\pi} = -\partial H_0/\partial\mathbf n - \partial U/\partial\mathbf n`).
    """
    n = as_float_array(n, "n", (3,))
    tau = as_float_array(tau, "tau", (3,))
    return -2.0 * _mvec(conversion_matrix(n), tau)


def _add_block(out, sl, extra):
    """``out`` (..., d) with ``extra`` (..., k) added to ``out[..., sl]``, broadcasting both."""
    shape = np.broadcast_shapes(out.shape, extra.shape[:-1] + out.shape[-1:])
    out = np.broadcast_to(out, shape).copy()
    out[..., sl] += extra
    return out


# ---------------------------------------------------------------------------
# Lagrangian side (batched numpy)
# ---------------------------------------------------------------------------
def metric_derivative(n: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""Derivatives :math:`\partial_k G_{ij}` of the metric :math:`G = 4AIA^T`.

    With :math:`\partial_k A = [\mathbf e_k]_\times/s - 2n_kA/s` (:math:`s = 1+\mathbf n^2`),

    .. math::
        \partial_k G = \frac4s\left(X_k + X_k^T\right) - \frac{4n_k}{s}G,
        \qquad X_k = [\mathbf e_k]_\times I A^T .

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : RigidBody or array_like, shape (..., 3) or (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)
        ``dG[..., k, i, j]`` :math:`= \partial G_{ij}/\partial n_k`.

    Raises
    ------
    InvalidInputError
        Wrong shape or non-finite ``n``.
    InvalidInertiaError
        Not a physical inertia tensor.

    References
    ----------
    Paper eq. 1.12-1.13.
    """
    n = as_float_array(n, "n", (3,))
    body = _as_body(inertia)
    return _metric_derivative(n, body.inertia)


def _metric_derivative(n, I):
    s = 1.0 + np.sum(n * n, -1)
    A = conversion_matrix(n)
    IAt = I @ _T(A)
    X = np.einsum("kab,...bc->...kac", _GEN, IAt)
    G = 4.0 * A @ IAt
    s4 = (4.0 / s)[..., None, None, None]
    return s4 * (X + _T(X)) - s4 * n[..., :, None, None] * G[..., None, :, :]


def christoffel(n: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""Christoffel symbols :math:`\Gamma^i_{jk}(\mathbf n)` of :math:`G = 4AIA^T`, closed form.

    .. math::
        \Gamma^i_{jk} = -\frac{n_j\delta_{ik} + n_k\delta_{ij}}{1+\mathbf n^2}
        - \left[\tilde A^T I^{-1}\left((I\mathbf a_j)\times\mathbf a_k
        + (I\mathbf a_k)\times\mathbf a_j\right)\right]_i

    where :math:`\mathbf a_j = A^T\mathbf e_j` is column :math:`j` of :math:`A^T`
    (:math:`\boldsymbol\Omega = 2\sum_j\mathbf a_j\dot n_j`). Derivation: the
    Euler-Lagrange equations of :math:`L = \tfrac12 G_{ij}\dot n_i\dot n_j`
    are Euler's equations; differentiating
    :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega` gives
    :math:`\ddot{\mathbf n} = 2(\mathbf n\cdot\dot{\mathbf n})\dot{\mathbf n}/s
    + \tfrac12\tilde A^T\dot{\boldsymbol\Omega}` (the kinematic terms collapse
    because :math:`\mathbf n\cdot\boldsymbol\Omega = 2\mathbf n\cdot\dot{\mathbf n}/s`,
    :math:`\dot{\mathbf n}\cdot\boldsymbol\Omega = 2\dot{\mathbf n}^2/s`), and
    :math:`\Gamma` is the symmetrized coefficient of
    :math:`-\ddot{\mathbf n}`. Equals the Levi-Civita formula
    :func:`christoffel_from_metric`.

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : RigidBody or array_like, shape (..., 3) or (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)
        ``Gamma[..., i, j, k]`` :math:`= \Gamma^i_{jk}`, symmetric in ``j, k``.

    Raises
    ------
    InvalidInputError, InvalidInertiaError

    References
    ----------
    Paper eq. 1.11-1.14.
    """
    n = as_float_array(n, "n", (3,))
    body = _as_body(inertia)
    return _christoffel(n, body.inertia, body.inertia_inv)


def _christoffel(n, I, Iinv):
    s = 1.0 + np.sum(n * n, -1)
    A = conversion_matrix(n)  # rows of A are the columns a_j of A^T
    IA_cols = A @ I  # row j: (I a_j)^T  (I symmetric)
    X = np.cross(IA_cols[..., :, None, :], A[..., None, :, :])  # (..., j, k, 3)
    K = _T(inverse_conversion_matrix(n)) @ Iinv  # Ã^T I^-1
    B = np.einsum("...ia,...jka->...ijk", K, X)
    d = np.eye(3)
    kin = (n[..., None, :, None] * d[:, None, :] + n[..., None, None, :] * d[:, :, None]) / s[..., None, None, None]
    return -(B + np.swapaxes(B, -1, -2)) - kin


def christoffel_from_metric(n: ArrayLike, inertia: ArrayLike, dG: ArrayLike | None = None) -> NDArray[np.float64]:
    r"""Christoffel symbols by the Levi-Civita formula (reference for :func:`christoffel`).

    .. math:: \Gamma^i_{jk} = \tfrac12 G^{il}\left(\partial_j G_{lk} + \partial_k G_{lj} - \partial_l G_{jk}\right)

    Parameters
    ----------
    n : array_like, shape (..., 3)
    inertia : RigidBody or array_like
    dG : array_like, shape (..., 3, 3, 3), optional
        Metric derivatives ``dG[..., k, i, j]``; default :func:`metric_derivative`.
        Pass finite differences to check the closed form independently.

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    body = _as_body(inertia)
    dG = _metric_derivative(n, body.inertia) if dG is None else as_float_array(dG, "dG", (3, 3, 3))
    first = 0.5 * (np.einsum("...jlk->...ljk", dG) + np.einsum("...klj->...ljk", dG) - dG)  # Γ_{l jk}
    Ginv = inverse_metric(n, body.inertia)
    return np.einsum("...il,...ljk->...ijk", Ginv, first)


def lagrangian(n: ArrayLike, ndot: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""The paper's Lagrangian :math:`L = \tfrac12 G_{ij}\dot n_i\dot n_j` (eq. 1.13).

    .. math:: L = \frac{2}{(1+\mathbf n^2)^2}\,(\dot{\mathbf n}-\mathbf n\times\dot{\mathbf n})^T I
              (\dot{\mathbf n}-\mathbf n\times\dot{\mathbf n})
              = \tfrac12\boldsymbol\Omega^T I\boldsymbol\Omega

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
    inertia : RigidBody or array_like

    Returns
    -------
    ndarray, shape (...)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    v = as_float_array(ndot, "ndot", (3,))
    body = _as_body(inertia)
    return np.asarray(geodesic_energy(_cf(n), _cf(v), _cf2(body.inertia)))


def canonical_momentum(n: ArrayLike, ndot: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r"""Canonical momentum :math:`\boldsymbol\pi = G\dot{\mathbf n} = 2AI\boldsymbol\Omega` (eq. 1.14, 1.26).

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
    inertia : RigidBody or array_like

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    v = as_float_array(ndot, "ndot", (3,))
    body = _as_body(inertia)
    return _mvec(metric(n, body.inertia), v)


def geodesic_acceleration(n: ArrayLike, ndot: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    r""":math:`\ddot{\mathbf n} = -\Gamma(\dot{\mathbf n}, \dot{\mathbf n})` (see :func:`geodesic_rhs`).

    Parameters
    ----------
    n, ndot : array_like, shape (..., 3)
    inertia : RigidBody or array_like

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError, InvalidInertiaError
    """
    n = as_float_array(n, "n", (3,))
    v = as_float_array(ndot, "ndot", (3,))
    body = _as_body(inertia)
    _, a = geodesic_rhs(_cf(n), _cf(v), _cf2(body.inertia), _cf2(body.inertia_inv))
    return _stack(a)


# ---------------------------------------------------------------------------
# formulations
# ---------------------------------------------------------------------------
class Formulation:
    r"""One coordinate description of the free rigid body, with its invariants.

    Subclasses fix the class attributes below and implement the kernels'
    batched wrappers. States are arrays of shape ``(..., dimension)``; the
    body may itself be a batch (its batch shape broadcasts against the
    states').

    Parameters
    ----------
    body : RigidBody, Model or array_like
        The body, or its principal moments (3,) or inertia tensor (3, 3)
        (any symmetric positive-definite tensor obeying the triangle
        inequality), or a :class:`~eulerpoisson.Model` (its body and torques).
    torque : Torque or list of Torque, optional
        Conservative torques (:class:`~eulerpoisson.torques.Gravity`,
        :class:`~eulerpoisson.torques.GravityGradient`): the Hamiltonian
        becomes :math:`H_0 + U(t, R)` and the vector field gains the torque
        (see the module docstring); the Poisson tensor is unchanged. None:
        the free body. For a heavy top the inertia is about the fixed point.

    Raises
    ------
    UnsupportedModelError
        (a ``ValueError``) A torque that derives from no potential
        (``BodyTorque``, ``SpaceTorque``, a callable).
    TypeError
        A ``torque`` that is not a torque, or a Model together with ``torque``.
    InvalidInputError
        Torque parameters whose batch shape does not broadcast with the body's.

    Attributes
    ----------
    name : str
        Registry name.
    title : str
        Human-readable name.
    variables : tuple of str
        Name of each state component.
    layout : dict of str to slice
        Named blocks of the state (``unpack``/``pack``).
    block_shapes : dict of str to tuple
        Shape of each block (``(3,)`` or ``(3, 3)``).
    dimension : int
        ``d``, the length of the last state axis.
    rank : int
        Rank of the Poisson tensor (``d`` when nondegenerate).
    equations : dict of str to str
        Paper equation numbers of each ingredient.
    torques : tuple of Torque
        The conservative torques (empty for the free body).

    Notes
    -----
    The *common* representation used by the conversions is the pair
    ``(q, Omega)``: a unit quaternion (..., 4) (scalar first) and the body
    angular velocity (..., 3). Formulations in :math:`\mathbf n` raise
    :class:`~eulerpoisson.errors.SingularChartError` for rotations by
    :math:`\pi`, where :math:`\mathbf n` is infinite.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> f = ep.formulation("canonical", [1.0, 2.0, 2.5])              # (n, pi), paper eq. 1.14-1.16
    >>> type(f).__name__, f.name
    ('Canonical', 'canonical')
    >>> z = f.from_common([1.0, 0.0, 0.0, 0.0], [1.0, 0.1, 0.5])
    >>> print(np.round(z, 6))
    [0.  0.  0.  2.  0.4 2.5]
    >>> print(np.round(f.vector_field(z), 6))
    [ 0.5    0.05   0.25  -0.025  0.75  -0.1  ]
    """

    name: str = ""
    title: str = ""
    variables: tuple = ()
    layout: dict = {}
    block_shapes: dict = {}
    dimension: int = 0
    rank: int = 0
    equations: dict = {}

    def __init__(self, body: RigidBody | ArrayLike, torque: TorqueLike = None) -> None:
        self.torques = _potential_torques(body, torque, f"the {self.name!r} formulation")
        self.body = _as_body(body)
        self._I = self.body.inertia
        self._Iinv = self.body.inertia_inv
        self._Icf = _cf2(self._I)
        self._Iinvcf = _cf2(self._Iinv)
        shapes = [self.body.batch_shape] + [tq.batch_shape for tq in self.torques]
        try:
            self._bshape = np.broadcast_shapes(*shapes)
        except ValueError:
            desc = ", ".join(f"{type(tq).__name__} {tq.batch_shape}" for tq in self.torques)
            raise InvalidInputError(
                f"the {self.name!r} formulation: the torques' batch shapes ({desc}) do not broadcast with "
                f"the body's {self.body.batch_shape}"
            ) from None

    @property
    def is_free(self) -> bool:
        """True for the free body (no torque)."""
        return not self.torques

    @property
    def time_dependent(self) -> bool:
        """True when the potential depends explicitly on the time (the gravity gradient)."""
        return any(tq.time_dependent for tq in self.torques)

    # -- the potential ------------------------------------------------------
    @staticmethod
    def _time(t: ArrayLike) -> np.ndarray:
        return as_float_array(t, "t")

    def _torque_at(self, t, R):
        """Body-frame torque of the potential at the attitudes R (..., 3, 3), (..., 3)."""
        tau = np.zeros(R.shape[:-2] + (3,))
        w = np.zeros(R.shape[:-2] + (3,))
        for tq in self.torques:
            tau = tau + np.asarray(tq.evaluate(t, R, w, self._I), dtype=float)
        return tau

    def _potential_at(self, t, R):
        """Potential :math:`U(t, R)` summed over the torques, (...)."""
        U = np.zeros(R.shape[:-2])
        for tq in self.torques:
            U = U + np.asarray(tq.potential(t, R, self._I), dtype=float)
        return U

    def potential(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        r"""Potential energy :math:`U(t, R)` of the torques, shape (...) (zero for the free body).

        Parameters
        ----------
        state : array_like, shape (..., d)
        t : float or array_like, shape (...)
            Time (only the gravity gradient depends on it).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values of ``state`` or ``t``.
        """
        x = self._check(state)
        t = self._time(t)
        shape = np.broadcast_shapes(self._batch(x), t.shape)
        if not self.torques:
            return np.zeros(shape)
        return np.broadcast_to(self._potential_at(t, self.matrix(x)), shape).copy()

    def torque(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        r"""Body-frame torque :math:`\boldsymbol\tau(t, R)` of the potential, shape (..., 3).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values of ``state`` or ``t``.
        """
        x = self._check(state)
        t = self._time(t)
        shape = np.broadcast_shapes(self._batch(x), t.shape) + (3,)
        if not self.torques:
            return np.zeros(shape)
        return np.broadcast_to(self._torque_at(t, self.matrix(x)), shape).copy()

    def _with_potential(self, H0, x, t):
        if not self.torques:
            return H0
        t = self._time(t)
        U = self._potential_at(t, self.matrix(x))
        return np.asarray(H0 + U)

    def _gravity_direction(self):
        """Common unit direction of ``g`` when every torque is a Gravity with parallel ``g``; else None."""
        if not self.torques or not all(isinstance(tq, Gravity) for tq in self.torques):
            return None
        ghat = None
        for tq in self.torques:
            norm = np.sqrt(np.sum(tq.g * tq.g, -1))
            if np.any(norm == 0):
                return None
            d = tq.g / norm[..., None]
            if ghat is not None and not np.allclose(d, ghat, rtol=0.0, atol=1e-14):
                return None
            ghat = d
        return ghat

    # -- validation and layout ---------------------------------------------
    def _check(self, state, what="state"):
        return as_float_array(state, f"{what} of the {self.name!r} formulation", (self.dimension,))

    def _batch(self, x):
        return np.broadcast_shapes(x.shape[:-1], self._bshape)

    def unpack(self, state: ArrayLike) -> dict[str, NDArray[np.float64]]:
        """Named blocks of ``state`` (views), e.g. ``{'n': (..., 3), 'pi': (..., 3)}``.

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values.
        """
        x = self._check(state)
        return {k: x[..., sl].reshape(x.shape[:-1] + self.block_shapes[k]) for k, sl in self.layout.items()}

    def pack(self, **blocks: ArrayLike) -> NDArray[np.float64]:
        """Assemble a state (..., d) from named blocks (broadcast against each other).

        Raises
        ------
        InvalidInputError
            Missing or unknown block names, wrong block shapes, non-finite values.
        """
        names = set(self.layout)
        if set(blocks) != names:
            raise InvalidInputError(
                f"the {self.name!r} formulation needs the blocks {sorted(names)}, got {sorted(blocks)}"
            )
        arrs = [as_float_array(blocks[k], k, self.block_shapes[k]) for k in self.layout]
        flat = [a.reshape(a.shape[: a.ndim - len(self.block_shapes[k])] + (-1,)) for a, k in zip(arrs, self.layout)]
        shape = np.broadcast_shapes(*[f.shape[:-1] for f in flat])
        return np.concatenate([np.broadcast_to(f, shape + f.shape[-1:]) for f in flat], -1)

    # -- dynamics -------------------------------------------------------------
    def vector_field(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        """Right-hand side :math:`\\dot z = P(z)\\nabla H(z, t)`, shape (..., d).

        ``t`` (float or array broadcast against the batch) matters only for a
        time-dependent potential (the gravity gradient).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values.
        """
        raise NotImplementedError

    def rhs(self, t: float, y: ArrayLike) -> NDArray[np.float64]:
        """``vector_field(y, t)`` with scipy's ``fun(t, y)`` signature."""
        return self.vector_field(y, t)

    def hamiltonian(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        """Hamiltonian in these variables, :math:`H_0 + U(t, R)` (the kinetic energy plus the potential), shape (...)."""
        raise NotImplementedError

    def poisson_tensor(self, state: ArrayLike) -> NDArray[np.float64]:
        """Poisson tensor :math:`P_{ab} = \\{z_a, z_b\\}`, shape (..., d, d)."""
        raise NotImplementedError

    def poisson_determinant(self, state: ArrayLike) -> NDArray[np.float64]:
        """Closed-form :math:`\\det P(z)`, shape (...) (0 for a degenerate structure)."""
        raise NotImplementedError

    def casimirs(self, state: ArrayLike) -> NDArray[np.float64]:
        """Casimir functions (..., k); ``k = 0`` for a nondegenerate structure."""
        x = self._check(state)
        return np.zeros(self._batch(x) + (0,))

    def integrals(self, state: ArrayLike, t: ArrayLike = 0.0) -> dict[str, NDArray[np.float64]]:
        r"""First integrals.

        Free body: ``H`` (...), ``m`` (..., 3), ``m2`` (...), ``m3`` (...).
        ``m`` is the spatial angular momentum :math:`R I\boldsymbol\Omega`,
        ``m2`` :math:`= \mathbf m^2`, ``m3`` its third component; ``H``,
        ``m2``, ``m3`` are in involution (paper eq. 1.19, 1.23).

        With a potential: ``H`` :math:`= H_0 + U(t, R)` (conserved when no
        torque depends on the time); for gravity along one direction
        :math:`\hat{\mathbf g}` also ``m_vertical`` :math:`= \mathbf m\cdot\hat{\mathbf g}`
        (the space torque :math:`(R\mathbf c)\times\mu\mathbf g` is
        horizontal); for one gravity gradient the Jacobi integral ``jacobi``
        :math:`= H - \nu m_3` (:math:`U` depends on :math:`t` only through a
        rotation by :math:`\nu t` about :math:`\mathbf e_3`, generated by :math:`m_3`).

        Parameters
        ----------
        state : array_like, shape (..., d)
        t : float or array_like, shape (...)
            Time (for a time-dependent potential).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values.
        """
        x = self._check(state)
        m = self.spatial_momentum(x)
        H = self.hamiltonian(x, t)
        if not self.torques:
            return {"H": H, "m": m, "m2": np.sum(m * m, -1), "m3": m[..., 2]}
        out = {"H": H}
        ghat = self._gravity_direction()
        if ghat is not None:
            out["m_vertical"] = np.sum(m * ghat, -1)
        if len(self.torques) == 1 and isinstance(self.torques[0], GravityGradient):
            out["jacobi"] = H - self.torques[0].mean_motion * m[..., 2]
        return out

    # -- conversions --------------------------------------------------------
    def to_common(self, state: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(q, Omega)``: unit quaternions (..., 4) and body angular velocity (..., 3)."""
        raise NotImplementedError

    def from_common(self, q: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
        """State (..., d) from unit quaternions (..., 4) and body angular velocities (..., 3)."""
        raise NotImplementedError

    def convert(self, state: ArrayLike, target: str | Formulation) -> NDArray[np.float64]:
        """The same physical states in another formulation (a name or a :class:`Formulation`).

        The target uses this formulation's body unless a Formulation is given.

        Raises
        ------
        InvalidInputError
            Unknown target name, bad state.
        SingularChartError
            A rotation by pi converted to a formulation in ``n``.
        """
        if not isinstance(target, Formulation):
            target = formulation(target, self.body)
        return target.from_common(*self.to_common(state))

    def quaternion(self, state: ArrayLike) -> NDArray[np.float64]:
        """Unit quaternion (scalar first) of the attitude, (..., 4)."""
        return self.to_common(state)[0]

    def matrix(self, state: ArrayLike) -> NDArray[np.float64]:
        """Rotation matrix R (x_space = R x_body), (..., 3, 3)."""
        return matrix_from_quaternion(self.quaternion(state))

    def gibbs(self, state: ArrayLike) -> NDArray[np.float64]:
        """The paper's Gibbs vector n, (..., 3). Raises SingularChartError at angle pi."""
        return gibbs_from_quaternion(self.quaternion(state))

    def omega(self, state: ArrayLike) -> NDArray[np.float64]:
        r"""Body angular velocity :math:`\boldsymbol\Omega`, (..., 3)."""
        return self.to_common(state)[1]

    def body_momentum(self, state: ArrayLike) -> NDArray[np.float64]:
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega`, (..., 3)."""
        return _mvec(self._I, self.omega(state))

    def spatial_momentum(self, state: ArrayLike) -> NDArray[np.float64]:
        r"""Spatial angular momentum :math:`\mathbf m = RI\boldsymbol\Omega`, (..., 3)."""
        return _mvec(self.matrix(state), self.body_momentum(state))

    def __repr__(self) -> str:
        tq = f", torque={list(self.torques)!r}" if self.torques else ""
        return f"{type(self).__name__}(name={self.name!r}, dimension={self.dimension}, body={self.body!r}{tq})"


#: largest |n| at which the Gibbs formulations evaluate their formulas (powers up to
#: n^6 appear: 1e50 keeps them, and their differences, far from overflow and underflow)
MAX_GIBBS_NORM = 1e50


def _check_gibbs_norm(n, name: str) -> None:
    """SingularChartError where |n| > MAX_GIBBS_NORM (a rotation within ~2e-50 rad of a half turn)."""
    big = np.max(np.abs(n), axis=-1) if n.size else np.zeros(0)
    if np.any(big > MAX_GIBBS_NORM / 2.0):
        nrm = np.sqrt(np.sum((n / MAX_GIBBS_NORM) ** 2, axis=-1)) * MAX_GIBBS_NORM
        worst = float(np.max(nrm))
        if worst > MAX_GIBBS_NORM:
            raise SingularChartError(
                f"{name}: |n| = {worst:.3g} exceeds {MAX_GIBBS_NORM:.0e}: the rotation is within "
                f"{2.0 / worst:.1e} rad of a half turn, the singularity of the Gibbs chart, where the "
                f"formulas overflow; re-centre the chart (eulerpoisson.attitude.gibbs_chart) or use the "
                f"'euler_poisson' formulation"
            )


class _GibbsFormulation(Formulation):
    r"""Common parts of the formulations whose first block is n.

    The formulas are evaluated for :math:`|\mathbf n|\le 10^{50}` only
    (:data:`MAX_GIBBS_NORM`); beyond, a
    :class:`~eulerpoisson.errors.SingularChartError`. The attitude
    conversions (:meth:`gibbs`, :meth:`quaternion`, :meth:`matrix`) take any
    finite n. Near the half turn the chart is ill-conditioned: a state
    :math:`\delta` rad from it has :math:`|\mathbf n|\approx 2/\delta`, and
    quantities computed from :math:`(\mathbf n, \boldsymbol\pi)` or
    :math:`(\mathbf n, \mathbf m)` carry relative errors up to about
    :math:`\varepsilon|\mathbf n|` (measured :math:`\varepsilon|\mathbf n|/10`
    for the energy; :math:`(\mathbf n, \boldsymbol\Omega)` keeps full
    accuracy); re-centre the chart where that matters.
    """

    def _check(self, state, what="state"):
        x = super()._check(state, what)
        _check_gibbs_norm(x[..., 0:3], f"{what} of the {self.name!r} formulation")
        return x

    def gibbs(self, state) -> np.ndarray:
        return Formulation._check(self, state)[..., 0:3].copy()

    def quaternion(self, state) -> np.ndarray:
        return quaternion_from_gibbs(Formulation._check(self, state)[..., 0:3])

    def matrix(self, state) -> np.ndarray:
        return matrix_from_gibbs(Formulation._check(self, state)[..., 0:3])

    def to_common(self, state):
        x = self._check(state)
        return quaternion_from_gibbs(x[..., 0:3]), self.omega(x)

    def _split(self, state):
        x = self._check(state)
        return x, _cf(x[..., 0:3]), _cf(x[..., 3:6])

    def _tau_n(self, x, t):
        """Body-frame torque at R(n) of the states x, (..., 3)."""
        return self._torque_at(self._time(t), matrix_from_gibbs(x[..., 0:3]))

    def potential_gradient(self, state, t=0.0) -> np.ndarray:
        r"""Closed-form :math:`\partial U/\partial\mathbf n = -2A(\mathbf n)\boldsymbol\tau`, shape (..., 3).

        See :func:`gibbs_potential_gradient`; zero for the free body.

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values of ``state`` or ``t``.
        """
        x = self._check(state)
        shape = np.broadcast_shapes(self._batch(x), self._time(t).shape) + (3,)
        if not self.torques:
            return np.zeros(shape)
        g = -2.0 * _mvec(conversion_matrix(x[..., 0:3]), self._tau_n(x, t))
        return np.broadcast_to(g, shape).copy()

    def _common_in(self, q, omega):
        n = gibbs_from_quaternion(q)
        _check_gibbs_norm(n, f"q for the {self.name!r} formulation")
        w = as_float_array(omega, "omega", (3,))
        n, w = np.broadcast_arrays(n, w)
        return n, w


class EulerPoisson(Formulation):
    r"""Euler-Poisson equations in :math:`(R, \boldsymbol\Omega)` (paper eq. 1.4-1.5).

    State (..., 12): the rotation matrix :math:`R` flattened row-major
    (``R11, R12, ..., R33``) then :math:`\boldsymbol\Omega`.

    .. math:: \dot R = R[\boldsymbol\Omega]_\times,\quad I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega,
              \quad H = \tfrac12\boldsymbol\Omega^T I\boldsymbol\Omega

    Poisson tensor: the natural 12x12 Lie-Poisson tensor (dual of the
    semidirect product :math:`so(3)\ltimes(\mathbb R^3)^3`, the rows of
    :math:`R` being vectors under body rotations), in :math:`(R, \boldsymbol\Omega)`:

    .. math::
        \{R_{ij}, R_{kl}\} = 0,\quad \{R_{ij}, \Omega_l\} = (R[\mathbf e_k]_\times)_{ij}I^{-1}_{kl},
        \quad \{\Omega_i, \Omega_j\} = (I^{-1}[\mathbf M]_\times I^{-1})_{ij}

    with :math:`\mathbf M = I\boldsymbol\Omega`. It satisfies the Jacobi
    identity on all of :math:`\mathbb R^{12}` and has rank 6: the six
    Casimirs :math:`(RR^T)_{ij}` (:meth:`casimirs`) cut out
    :math:`SO(3)\times\mathbb R^3`, the symplectic leaf on which it is the
    canonical structure pushed forward from :math:`(\mathbf n, \boldsymbol\pi)`.
    """

    name = "euler-poisson"
    title = "Euler-Poisson (R, Omega)"
    variables = tuple(f"R{i}{j}" for i in range(1, 4) for j in range(1, 4)) + ("Omega1", "Omega2", "Omega3")
    layout = {"R": slice(0, 9), "Omega": slice(9, 12)}
    block_shapes = {"R": (3, 3), "Omega": (3,)}
    dimension = 12
    rank = 6
    equations = {
        "vector_field": "1.4, 1.5",
        "hamiltonian": "1.25",
        "poisson_tensor": "1.4-1.5 (Lie-Poisson; not printed)",
        "integrals": "1.24-1.25",
    }

    def _split(self, state):
        x = self._check(state)
        R = x[..., :9].reshape(x.shape[:-1] + (3, 3))
        return x, R, x[..., 9:12]

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, R, W = self._split(state)
        Rd, Wd = euler_poisson_rhs(_cf2(R), _cf(W), self._Icf, self._Iinvcf)
        out = _stack(Rd[0] + Rd[1] + Rd[2] + Wd)
        if self.torques:
            tau = self._torque_at(self._time(t), R)
            out = _add_block(out, slice(9, 12), _mvec(self._Iinv, tau))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, R, W = self._split(state)
        H = self._with_potential(kinetic_energy(_cf(W), self._Icf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x, R, W = self._split(state)
        shape = self._batch(x)
        RE = np.einsum("...ia,kaj->...ijk", R, _GEN)  # (R E_k)_ij
        B = np.einsum("...ijk,...kl->...ijl", RE, self._Iinv)
        B = np.broadcast_to(B, shape + (3, 3, 3)).reshape(shape + (9, 3))
        M = _mvec(self._I, W)
        C = _antisym(self._Iinv @ skew(M) @ self._Iinv)
        P = np.zeros(shape + (12, 12))
        P[..., :9, 9:] = B
        P[..., 9:, :9] = -_T(B)
        P[..., 9:, 9:] = C
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        return np.zeros(self._batch(x))

    def casimirs(self, state) -> np.ndarray:
        """The six Casimirs :math:`(RR^T)_{ij}`, ``i <= j`` (order 11, 12, 13, 22, 23, 33), (..., 6)."""
        x, R, W = self._split(state)
        RRt = R @ _T(R)
        iu = np.triu_indices(3)
        return np.broadcast_to(RRt[..., iu[0], iu[1]], self._batch(x) + (6,)).copy()

    def to_common(self, state):
        """``(q, Omega)``; ``R`` must be a rotation matrix (within 1e-6)."""
        x, R, W = self._split(state)
        return quaternion_from_matrix(R), W.copy()

    def from_common(self, q, omega) -> np.ndarray:
        R = matrix_from_quaternion(q)
        w = as_float_array(omega, "omega", (3,))
        return self.pack(R=R, Omega=w)

    def matrix(self, state) -> np.ndarray:
        return self._split(state)[1].copy()

    def omega(self, state) -> np.ndarray:
        return self._split(state)[2].copy()


class Canonical(_GibbsFormulation):
    r"""Canonical variables :math:`(\mathbf n, \boldsymbol\pi)` (paper eq. 1.14-1.19).

    .. math::
        H = \tfrac18(\tilde A\boldsymbol\pi)^T I^{-1}(\tilde A\boldsymbol\pi), \qquad
        P = \begin{pmatrix}0 & \mathbf 1\\ -\mathbf 1 & 0\end{pmatrix}, \qquad
        \mathbf m = \tfrac12\tilde A^T\boldsymbol\pi, \quad
        \boldsymbol\Omega = \tfrac12 I^{-1}\tilde A\boldsymbol\pi

    The vector field is the polynomial of :func:`canonical_rhs`
    (paper eq. 1.16 with :math:`\epsilon_{ijk}\pi_k` in place of the printed
    :math:`\epsilon_{ijk}n_k`). With a potential :math:`U(t, R)` (``torque=``),
    :math:`H = H_0 + U(t, R(\mathbf n))` and

    .. math:: \dot{\boldsymbol\pi} = -\frac{\partial H_0}{\partial\mathbf n}
              - \frac{\partial U}{\partial\mathbf n}, \qquad
              \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau

    (:meth:`potential_gradient`), with the canonical Poisson tensor.
    """

    name = "canonical"
    title = "canonical (n, pi)"
    variables = ("n1", "n2", "n3", "pi1", "pi2", "pi3")
    layout = {"n": slice(0, 3), "pi": slice(3, 6)}
    block_shapes = {"n": (3,), "pi": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.16 (corrected: eps_ijk pi_k)",
        "hamiltonian": "1.15",
        "poisson_tensor": "1.15.1",
        "integrals": "1.15, 1.17, 1.19, 1.23",
        "momenta": "1.14",
        "potential_gradient": "1.11-1.12 (dU/dn = -2 A tau)",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, p = self._split(state)
        nd, pd = canonical_rhs(n, p, self._Iinvcf)
        out = _stack(nd + pd)
        if self.torques:
            # pi-dot gains -dU/dn = 2 A tau
            out = _add_block(out, slice(3, 6), 2.0 * _mvec(conversion_matrix(x[..., 0:3]), self._tau_n(x, t)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, p = self._split(state)
        H = self._with_potential(canonical_hamiltonian(n, p, self._Iinvcf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        P = np.zeros((6, 6))
        P[:3, 3:] = np.eye(3)
        P[3:, :3] = -np.eye(3)
        return np.broadcast_to(P, self._batch(x) + (6, 6)).copy()

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        return np.ones(self._batch(x))

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        u = _mvec(inverse_conversion_matrix(x[..., :3]), x[..., 3:6])
        return 0.5 * _mvec(self._Iinv, u)

    def spatial_momentum(self, state) -> np.ndarray:
        r""":math:`\mathbf m = \tfrac12\tilde A^T\boldsymbol\pi` (eq. 1.17), (..., 3)."""
        x = self._check(state)
        m = 0.5 * _mvec(_T(inverse_conversion_matrix(x[..., :3])), x[..., 3:6])
        return np.broadcast_to(m, self._batch(x) + (3,)).copy()

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        p = 2.0 * _mvec(conversion_matrix(n), _mvec(self._I, w))
        n = np.broadcast_to(n, p.shape)
        return np.concatenate([n, p], -1)


class Momentum(_GibbsFormulation):
    r"""Noncanonical variables :math:`(\mathbf n, \mathbf m)` (paper eq. 1.20-1.23).

    .. math::
        \dot{\mathbf n} = \tfrac12\tilde A^T I^{-1}R^T\mathbf m,\quad \dot{\mathbf m} = 0,\quad
        H = \tfrac12\mathbf m^T RI^{-1}R^T\mathbf m

    .. math::
        \{n_i, n_j\} = 0,\quad \{n_i, m_j\} = \tfrac12\tilde A_{ij},\quad
        \{m_i, m_j\} = \epsilon_{ijk}m_k, \qquad
        \det P = \frac{(1+\mathbf n^2)^4}{64}

    The paper's :math:`\{m_i,m_j\}` of eq. 1.21 equals :math:`\epsilon_{ijk}m_k`
    because :math:`\hat n_{ij}n_k + \mathrm{cycle} = \mathbf n^2\epsilon_{ijk}`.
    """

    name = "momentum"
    title = "noncanonical (n, m)"
    variables = ("n1", "n2", "n3", "m1", "m2", "m3")
    layout = {"n": slice(0, 3), "m": slice(3, 6)}
    block_shapes = {"n": (3,), "m": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.20",
        "hamiltonian": "footnote to 1.20, 1.25",
        "poisson_tensor": "1.21 (simplified with 1.22)",
        "integrals": "1.17, 1.19, 1.23",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, m = self._split(state)
        nd, md = momentum_rhs(n, m, self._Iinvcf)
        out = _stack(nd + md)
        if self.torques:
            # m-dot gains the space-frame torque R tau = -1/2 Atilde^T dU/dn
            R = matrix_from_gibbs(x[..., 0:3])
            out = _add_block(out, slice(3, 6), _mvec(R, self._torque_at(self._time(t), R)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, m = self._split(state)
        H = self._with_potential(momentum_hamiltonian(n, m, self._Iinvcf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        At = inverse_conversion_matrix(x[..., :3])
        P = np.zeros(self._batch(x) + (6, 6))
        P[..., :3, 3:] = 0.5 * At
        P[..., 3:, :3] = -0.5 * _T(At)
        P[..., 3:, 3:] = -skew(x[..., 3:6])
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        s = 1.0 + np.sum(x[..., :3] ** 2, -1)
        return np.broadcast_to(s**4 / 64.0, self._batch(x)).copy()

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        R = matrix_from_gibbs(x[..., :3])
        return _mvec(self._Iinv, _mvec(_T(R), x[..., 3:6]))

    def spatial_momentum(self, state) -> np.ndarray:
        x = self._check(state)
        return np.broadcast_to(x[..., 3:6], self._batch(x) + (3,)).copy()

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        m = _mvec(matrix_from_gibbs(n), _mvec(self._I, w))
        n = np.broadcast_to(n, m.shape)
        return np.concatenate([n, m], -1)


class Velocity(_GibbsFormulation):
    r"""Variables :math:`(\mathbf n, \boldsymbol\Omega)` (paper eq. 1.26-1.30).

    .. math::
        \dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega,\quad
        I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega,\quad
        H = \tfrac12\boldsymbol\Omega^T I\boldsymbol\Omega

    .. math::
        \{n_i, \Omega_j\} = \tfrac12(\tilde A^T I^{-1})_{ij},\quad
        \{\Omega_i, \Omega_j\} = -I^{-1}_{ia}I^{-1}_{jb}\epsilon_{abc}M_c
        = (I^{-1}[\mathbf M]_\times I^{-1})_{ij},\qquad
        \det P = \frac{(1+\mathbf n^2)^4}{64(\det I)^2}
    """

    name = "velocity"
    title = "(n, Omega)"
    variables = ("n1", "n2", "n3", "Omega1", "Omega2", "Omega3")
    layout = {"n": slice(0, 3), "Omega": slice(3, 6)}
    block_shapes = {"n": (3,), "Omega": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.30",
        "hamiltonian": "1.27",
        "poisson_tensor": "1.28 (simplified with 1.29)",
        "integrals": "1.24-1.25",
        "momenta": "1.26",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, W = self._split(state)
        nd, Wd = velocity_rhs(n, W, self._Icf, self._Iinvcf)
        out = _stack(nd + Wd)
        if self.torques:
            out = _add_block(out, slice(3, 6), _mvec(self._Iinv, self._tau_n(x, t)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, W = self._split(state)
        H = self._with_potential(kinetic_energy(W, self._Icf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        K = 0.5 * _T(inverse_conversion_matrix(x[..., :3])) @ self._Iinv
        M = _mvec(self._I, x[..., 3:6])
        P = np.zeros(self._batch(x) + (6, 6))
        P[..., :3, 3:] = K
        P[..., 3:, :3] = -_T(K)
        P[..., 3:, 3:] = _antisym(self._Iinv @ skew(M) @ self._Iinv)
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        s = 1.0 + np.sum(x[..., :3] ** 2, -1)
        return np.broadcast_to(s**4 / (64.0 * np.linalg.det(self._I) ** 2), self._batch(x)).copy()

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        return x[..., 3:6].copy()

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        return np.concatenate([n, w], -1)


class Geodesic(_GibbsFormulation):
    r"""Lagrangian (geodesic) variables :math:`(\mathbf n, \dot{\mathbf n})` (paper eq. 1.11-1.14).

    Geodesics of :math:`G = 4AIA^T`: :math:`\ddot n^i + \Gamma^i_{jk}(\mathbf n)\dot n^j\dot n^k = 0`
    (see :func:`christoffel`). Those through :math:`\mathbf n = 0` are the
    body's motions from the identity; by left invariance every geodesic is a
    body motion (from :math:`R(\mathbf n_0)`).

    The "Hamiltonian" is the energy :math:`E = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n}`
    (equal to :math:`L`), plus :math:`U` with a potential (then
    :math:`L = E - U` and the motion is no longer geodesic: :math:`\ddot{\mathbf n}`
    gains :math:`-G^{-1}\partial U/\partial\mathbf n`). The Poisson tensor is the canonical one pulled
    back by :math:`\boldsymbol\pi = G(\mathbf n)\dot{\mathbf n}`:

    .. math::
        P = \begin{pmatrix}0 & G^{-1}\\ -G^{-1} & G^{-1}(C^T - C)G^{-1}\end{pmatrix},\qquad
        C_{lk} = \partial_k G_{lm}\,\dot n_m,\qquad
        \det P = \left(\frac{(1+\mathbf n^2)^4}{64\det I}\right)^2
    """

    name = "geodesic"
    title = "geodesic (n, ndot)"
    variables = ("n1", "n2", "n3", "ndot1", "ndot2", "ndot3")
    layout = {"n": slice(0, 3), "ndot": slice(3, 6)}
    block_shapes = {"n": (3,), "ndot": (3,)}
    dimension = 6
    rank = 6
    equations = {
        "vector_field": "1.13 (Euler-Lagrange / geodesic equation)",
        "hamiltonian": "1.13",
        "poisson_tensor": "1.14, 1.15.1 (pulled back)",
        "metric": "1.13",
        "integrals": "1.11, 1.24",
    }

    def vector_field(self, state, t=0.0) -> np.ndarray:
        x, n, v = self._split(state)
        nd, a = geodesic_rhs(n, v, self._Icf, self._Iinvcf)
        out = _stack(nd + a)
        if self.torques:
            # Euler-Lagrange with L = E - U: nddot gains -G^{-1} dU/dn = 1/2 Atilde^T I^{-1} tau
            K = _T(inverse_conversion_matrix(x[..., 0:3])) @ self._Iinv
            out = _add_block(out, slice(3, 6), 0.5 * _mvec(K, self._tau_n(x, t)))
        return out

    def hamiltonian(self, state, t=0.0) -> np.ndarray:
        x, n, v = self._split(state)
        H = self._with_potential(geodesic_energy(n, v, self._Icf), x, t)
        return np.broadcast_to(H, np.broadcast_shapes(self._batch(x), np.shape(H))).copy()

    def lagrangian(self, state, t=0.0) -> np.ndarray:
        r"""Lagrangian :math:`L = \tfrac12\dot{\mathbf n}^TG\dot{\mathbf n} - U(t, R(\mathbf n))` (eq. 1.13 with a potential), shape (...)."""
        x, n, v = self._split(state)
        E = geodesic_energy(n, v, self._Icf)
        L = E - self._potential_at(self._time(t), self.matrix(x)) if self.torques else E
        return np.broadcast_to(L, np.broadcast_shapes(self._batch(x), np.shape(L))).copy()

    def metric(self, state) -> np.ndarray:
        """:math:`G(\\mathbf n) = 4AIA^T`, (..., 3, 3)."""
        x = self._check(state)
        return metric(x[..., :3], self._I)

    def christoffel(self, state) -> np.ndarray:
        """:math:`\\Gamma^i_{jk}(\\mathbf n)`, (..., 3, 3, 3) (see :func:`christoffel`)."""
        x = self._check(state)
        return _christoffel(x[..., :3], self._I, self._Iinv)

    def momenta(self, state) -> np.ndarray:
        """Canonical momenta :math:`\\boldsymbol\\pi = G\\dot{\\mathbf n}`, (..., 3)."""
        x = self._check(state)
        return _mvec(metric(x[..., :3], self._I), x[..., 3:6])

    def poisson_tensor(self, state) -> np.ndarray:
        x = self._check(state)
        n, v = x[..., :3], x[..., 3:6]
        Ginv = inverse_metric(n, self._I)
        dG = _metric_derivative(n, self._I)
        C = np.einsum("...klm,...m->...lk", dG, v)
        Ginv = np.broadcast_to(Ginv, self._batch(x) + (3, 3))
        P = np.zeros(self._batch(x) + (6, 6))
        P[..., :3, 3:] = Ginv
        P[..., 3:, :3] = -_T(Ginv)
        P[..., 3:, 3:] = _antisym(Ginv @ (_T(C) - C) @ Ginv)
        return P

    def poisson_determinant(self, state) -> np.ndarray:
        x = self._check(state)
        s = 1.0 + np.sum(x[..., :3] ** 2, -1)
        return np.broadcast_to((s**4 / (64.0 * np.linalg.det(self._I))) ** 2, self._batch(x)).copy()

    def omega(self, state) -> np.ndarray:
        x = self._check(state)
        v = _stack(_a_t_v(_cf(x[..., :3]), _cf(x[..., 3:6])))
        return 2.0 * v

    def from_common(self, q, omega) -> np.ndarray:
        n, w = self._common_in(q, omega)
        v = 0.5 * _mvec(_T(inverse_conversion_matrix(n)), w)
        return np.concatenate([n, v], -1)


#: Registry of the formulations by name.
FORMULATIONS = {
    "euler-poisson": EulerPoisson,
    "canonical": Canonical,
    "momentum": Momentum,
    "velocity": Velocity,
    "geodesic": Geodesic,
}

_ALIASES = {
    "r-omega": "euler-poisson",
    "ep": "euler-poisson",
    "n-pi": "canonical",
    "n-m": "momentum",
    "noncanonical": "momentum",
    "n-omega": "velocity",
    "lagrangian": "geodesic",
    "n-ndot": "geodesic",
}


def formulation(name: str, body: RigidBody | ArrayLike, torque: TorqueLike = None) -> Formulation:
    r"""Construct a formulation by registry name, for the free body or with a potential.

    Parameters
    ----------
    name : str
        One of ``FORMULATIONS`` (``'euler-poisson'``, ``'canonical'``,
        ``'momentum'``, ``'velocity'``, ``'geodesic'``) or an alias
        (``'R-Omega'``, ``'n-pi'``, ``'n-m'``, ``'n-Omega'``, ``'n-ndot'``,
        ``'lagrangian'``, ``'noncanonical'``); case and ``_`` / ``-`` are ignored.
    body : RigidBody, Model or array_like
        The body or its inertia (moments (3,) or tensor (3, 3)), or a
        :class:`~eulerpoisson.Model` (its body and torques).
    torque : Torque or list of Torque, optional
        Conservative torques (:class:`~eulerpoisson.torques.Gravity`,
        :class:`~eulerpoisson.torques.GravityGradient`):
        :math:`H = H_0 + U(t, R)`, the same Poisson tensor, and in the
        canonical chart :math:`\dot{\boldsymbol\pi} = -\partial H_0/\partial\mathbf n
        - \partial U/\partial\mathbf n` with :math:`\partial U/\partial\mathbf n
        = -2A(\mathbf n)\boldsymbol\tau` (see the module docstring). None: the free body.

    Returns
    -------
    Formulation

    Raises
    ------
    InvalidInputError
        Unknown name.
    UnsupportedModelError
        (a ``ValueError``) A non-conservative torque (``BodyTorque``,
        ``SpaceTorque``, a callable); the message names what is accepted.
    TypeError
        ``name`` is not a string; ``torque`` is not a torque.
    InvalidInertiaError
        Not a physical inertia tensor.

    References
    ----------
    Paper eq. 1.9-1.16 (the canonical formulation the potential is added to).

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])
    >>> f = ep.formulation("canonical", [1.0, 1.0, 0.5], torque=top)
    >>> z = f.from_common([1.0, 0.0, 0.0, 0.0], [0.0, 0.2, 20.0])
    >>> f.vector_field(z).shape
    (6,)
    """
    if not isinstance(name, str):
        raise TypeError(f"formulation name must be a string, got {type(name).__name__} {name!r}")
    key = name.strip().lower().replace("_", "-")
    key = _ALIASES.get(key, key)
    if key not in FORMULATIONS:
        raise InvalidInputError(
            f"unknown formulation {name!r}; expected one of {sorted(FORMULATIONS)} or an alias {sorted(_ALIASES)}"
        )
    return FORMULATIONS[key](body, torque)
