r"""Symplectic integrators (``method="symplectic"``).

Two families, chosen by the option ``scheme``:

``"gauss2"``, ``"gauss4"``, ``"gauss6"``
    Gauss-Legendre collocation with 1, 2, 3 stages (orders 2, 4, 6): implicit,
    symplectic and symmetric; the stage equations are solved by fixed-point
    iteration to round-off (starting from the previous step's collocation
    polynomial). Two sets of canonical variables (option ``variables``):

    ``"gibbs"`` (default)
        The paper's canonical variables :math:`(\mathbf n, \boldsymbol\pi)`
        with :math:`H = \tfrac18(\tilde A\boldsymbol\pi)^TI^{-1}\tilde A\boldsymbol\pi`
        (eqs. 1.15-1.16, the misprint of eq. 1.16 corrected, see
        :func:`~eulerpoisson.solvers.charts.canonical_field`). The
        attitude is carried in charts :math:`R = R_cR(\mathbf n)`, re-centred
        at :math:`\mathbf n = 0` when :math:`|\mathbf n|` exceeds
        ``chart_threshold`` (1 by default), the momentum carried over by the
        cotangent lift (:mod:`~eulerpoisson.solvers.charts`).
    ``"quaternion"``
        The homogeneous coordinates of the same variables: :math:`q` with
        :math:`\mathbf n = \mathbf q/q_0` (footnote to eq. 1.9) and its
        momentum :math:`p\in\mathbb R^4`, :math:`H = \tfrac12\sum_kM_k^2/I_k`,
        :math:`M_k = \tfrac12p\cdot(q\otimes\mathbf e_k)`
        (:func:`~eulerpoisson.solvers.charts.quaternion_field`). No chart
        is needed: left translations act linearly.

``"splitting"``, ``"splitting4"``
    The classical geometric reference in :math:`(R, \mathbf M)`: the explicit
    Lie-Poisson splitting :math:`H = \sum_i M_i^2/(2I_i)` of McLachlan (1993),
    Reich (1994) and Touma & Wisdom (1994). Each piece is integrated exactly
    (a rotation of :math:`\mathbf M` and of the attitude about a principal
    axis) and the pieces are composed symmetrically,
    :math:`\varphi_{h/2}^{[1]}\varphi_{h/2}^{[2]}\varphi_{h}^{[3]}\varphi_{h/2}^{[2]}\varphi_{h/2}^{[1]}`
    (Strang, order 2), or that map composed by Yoshida's triple jump
    (order 4). No iteration, no chart. It was chosen over the discrete
    Moser-Veselov algorithm because it is explicit, needs no matrix
    factorization, and has the same geometric properties.

What is conserved (measured in the tests)
    * ``splitting``: the spatial angular momentum :math:`\mathbf m = R\mathbf M`
      and :math:`|\mathbf M|` to round-off (every piece is the exact flow of
      a left-invariant Hamiltonian); the energy error is :math:`O(h^p)` and
      bounded, without drift.
    * Gauss, ``variables="quaternion"``: :math:`\mathbf m =
      \tfrac12\mathrm{vec}(p\otimes\bar q)`, :math:`|q|` and :math:`q\cdot p`
      to round-off (Gauss methods conserve quadratic invariants); the energy
      (quartic) error is :math:`O(h^p)` and bounded, without drift.
    * Gauss, ``variables="gibbs"``: in each chart the map is symplectic and
      symmetric, but none of the integrals is quadratic in
      :math:`(\mathbf n,\boldsymbol\pi)` (:math:`H` is quartic, :math:`\mathbf m
      = \tfrac12\tilde A^T\boldsymbol\pi` (eq. 1.17) cubic), so :math:`H` and
      :math:`\mathbf m` carry :math:`O(h^p)` errors. Moreover, the
      modified Hamiltonian that a symplectic method conserves depends on the
      coordinates, so it is a different function in each chart, and every
      chart is traversed the same way (entered at :math:`\mathbf n = 0`,
      left at :math:`|\mathbf n| = 1`): the energy error changes by a
      systematic :math:`O(h^p)` amount per chart change and **drifts
      linearly in time** (e.g. about :math:`5\cdot10^{-7}` relative per chart
      change for ``gauss4`` at :math:`h|\boldsymbol\Omega| = 0.1`, 16 times
      less at half the step). Also, since the new chart centre depends on
      the state, the map across a chart change is not exactly symplectic.
      Use ``variables="quaternion"`` or a splitting for long runs.

The driver splits each interval between sorted output times into equal
steps :math:`\le` ``dt``, so outputs land on the output times; negative
times integrate backwards from :math:`t = 0` with negative steps.

Speed
    The splittings and the Gauss methods in quaternion variables run in
    compiled kernels when numba is installed
    (:mod:`~eulerpoisson.solvers.symplectic.kernels`: bodies advanced
    in SIMD lanes of 8 or 16, about 1e7 to 1e8 body-steps per second per
    core); ``EULERPOISSON_NO_NUMBA=1`` selects the NumPy code below, which
    performs the same floating-point operations in the same order and gives
    the same results bit for bit. ``stats["compiled"]`` says which ran. The
    Gauss methods in Gibbs variables (charts) always use NumPy. Large
    batches are split over threads by ``solve(..., workers=)``; the default
    step, taken from the fastest body, is fixed once for the whole batch
    (:meth:`Symplectic.for_batch`), so the results do not depend on the
    number of threads.

References
----------
E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd
ed. (2006): II.1.3 (Gauss collocation), IV.2 (quadratic invariants), VI.4
(symplecticity), VII.5 (the rigid body), VIII.6 (implementation of implicit
methods), IX (backward error analysis).
R. I. McLachlan, "Explicit Lie-Poisson integration and the Euler equations",
Phys. Rev. Lett. 71 (1993) 3043. S. Reich, "Momentum conserving symplectic
integrators", Physica D 76 (1994) 375. J. Touma and J. Wisdom, "Lie-Poisson
integrators for rigid body dynamics in the solar system", Astron. J. 107
(1994) 1189. H. Yoshida, "Construction of higher order symplectic
integrators", Phys. Lett. A 150 (1990) 262.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...attitude.core import quaternion_from_rotation_matrix
from ...errors import EulerPoissonError, InvalidInputError, UnsupportedModelError
from ...numerics.quaternion import qmul
from ...util.jit import USE_NUMBA
from .. import charts as ch
from ..problem import Problem
from ..registry import Method, MethodOptions, MethodResult, hybridmethod, register_method

__all__ = ["Symplectic", "GaussTableau", "gauss_tableau", "gauss_step", "splitting_sequence", "splitting_advance"]

_EPS = np.finfo(float).eps

#: schemes and their orders
SCHEMES = {
    "gauss2": 2,
    "gauss4": 4,
    "gauss6": 6,
    "splitting": 2,
    "splitting4": 4,
    "exact_splitting": 2,
    "exact_splitting4": 4,
}

#: the schemes that run bodies under torque
TORQUE_SCHEMES = ("exact_splitting", "exact_splitting4")

#: canonical variables of the Gauss schemes
VARIABLES = ("gibbs", "quaternion")

#: default rotation per step, |Omega| * dt, when dt is not given
DEFAULT_ROTATION_PER_STEP = 0.05


# ---------------------------------------------------------------------------
# Gauss-Legendre collocation
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class GaussTableau:
    """Butcher tableau of the s-stage Gauss-Legendre method (order 2s)."""

    A: np.ndarray
    b: np.ndarray
    c: np.ndarray

    @property
    def stages(self) -> int:
        return self.b.shape[0]

    @property
    def order(self) -> int:
        return 2 * self.stages

    @property
    def extrapolation(self) -> np.ndarray:
        r"""Matrix :math:`E` of the starting guess :math:`Z^{(0)}_{\rm next} = EZ` (same step size).

        The collocation polynomial of a step, :math:`u(\theta) = y_0 + \sum_j
        \ell_j(\theta)Z_j` with the Lagrange basis :math:`\ell_j` on the nodes
        :math:`\{0, c_1, \dots, c_s\}`, passes through :math:`y_1 = u(1)`;
        the next step's stages are guessed as :math:`u(1+c_i) - u(1)`, so
        :math:`E_{ij} = \ell_j(1+c_i) - \ell_j(1)` (Hairer-Lubich-Wanner VIII.6.1).
        """
        nodes = np.concatenate([[0.0], self.c])

        def ell(j, x):  # Lagrange basis polynomial of node j (1-based: c_j) at x
            out = 1.0
            for m, xm in enumerate(nodes):
                if m != j:
                    out *= (x - xm) / (nodes[j] - xm)
            return out

        s = self.stages
        return np.array([[ell(j + 1, 1.0 + self.c[i]) - ell(j + 1, 1.0) for j in range(s)] for i in range(s)])


def gauss_tableau(stages: int) -> GaussTableau:
    r"""The Gauss-Legendre tableau with 1, 2 or 3 stages, in closed form.

    Nodes :math:`c_i` are the zeros of the shifted Legendre polynomial
    :math:`P_s(2c-1)`; :math:`a_{ij} = \int_0^{c_i}\ell_j`, :math:`b_j =
    \int_0^1\ell_j` with the Lagrange polynomials :math:`\ell_j` on the nodes.

    Parameters
    ----------
    stages : int
        1, 2 or 3.

    Returns
    -------
    GaussTableau

    Raises
    ------
    InvalidInputError
        Another number of stages.

    References
    ----------
    Hairer, Lubich, Wanner, *Geometric Numerical Integration*, Table II.1.1-1.2.
    """
    if stages == 1:
        A = [[0.5]]
        b = [1.0]
        c = [0.5]
    elif stages == 2:
        r = math.sqrt(3.0) / 6.0
        A = [[0.25, 0.25 - r], [0.25 + r, 0.25]]
        b = [0.5, 0.5]
        c = [0.5 - r, 0.5 + r]
    elif stages == 3:
        r = math.sqrt(15.0)
        A = [
            [5 / 36, 2 / 9 - r / 15, 5 / 36 - r / 30],
            [5 / 36 + r / 24, 2 / 9, 5 / 36 - r / 24],
            [5 / 36 + r / 30, 2 / 9 + r / 15, 5 / 36],
        ]
        b = [5 / 18, 4 / 9, 5 / 18]
        c = [0.5 - r / 10, 0.5, 0.5 + r / 10]
    else:
        raise InvalidInputError(f"Gauss tableaux are available for 1, 2 or 3 stages, got {stages!r}")
    return GaussTableau(np.array(A), np.array(b), np.array(c))


def _combine(C, Z):
    r"""Stage combinations :math:`W_{:,i} = \sum_j C_{ij}Z_{:,j}`, Z of shape (D, s, B) -> (D, r, B).

    Summed in the order :math:`j = 1, \dots, s` (what the compiled kernels do),
    not by ``matmul``, whose summation order (and use of fused multiply-adds)
    depends on the BLAS.
    """
    rows = []
    for i in range(C.shape[0]):
        acc = C[i, 0] * Z[:, 0]
        for j in range(1, C.shape[1]):
            acc = acc + C[i, j] * Z[:, j]
        rows.append(acc)
    return np.stack(rows, axis=1)


def _weights(b, F):
    r""":math:`\sum_j b_jF_{:,j}`, F of shape (D, s, B) -> (D, B), summed in the order j = 1, ..., s."""
    acc = b[0] * F[:, 0]
    for j in range(1, b.shape[0]):
        acc = acc + b[j] * F[:, j]
    return acc


def _error_nonfinite(h):
    return EulerPoissonError(f"symplectic: non-finite stage values at step h = {h:.6g}; reduce dt")


def _error_diverged(h):
    return EulerPoissonError(
        f"symplectic: the fixed-point iteration of the Gauss stages diverged at step h = {h:.6g}; "
        "the step is too large for this angular velocity: reduce dt"
    )


def _error_max_iter(max_iter, bad, h):
    return EulerPoissonError(
        f"symplectic: the Gauss stage equations did not converge in max_iter={max_iter} fixed-point "
        f"iterations (relative increment {bad:.3g} at step h = {h:.6g}); reduce dt or raise max_iter"
    )


def gauss_step(
    y0,
    h,
    inv_moments,
    tableau: GaussTableau,
    *,
    max_iter: int = 100,
    iterations: int | None = None,
    field=ch.canonical_field,
    Z0=None,
    counts=None,
):
    r"""One step of Gauss-Legendre collocation for :math:`(\mathbf n, \boldsymbol\pi)`, batched.

    Solves the stage equations :math:`Z_i = h\sum_j a_{ij}f(y_0+Z_j)` by
    fixed-point iteration, per body until the increment stops decreasing at
    round-off (or vanishes), then
    :math:`y_1 = y_0 + h\sum_j b_jf(y_0+Z_j)`.

    Parameters
    ----------
    y0 : ndarray, shape (D, B)
        The state, component first: :math:`(\mathbf n, \boldsymbol\pi)`
        (D = 6) or :math:`(q, p)` (D = 8, with ``field=quaternion_field``);
        real or complex.
    h : float
        Step (negative runs backwards).
    inv_moments : ndarray, shape (3, B)
        Inverse principal moments.
    tableau : GaussTableau
    max_iter : int
        Iteration cap.
    iterations : int, optional
        Run exactly this many iterations without a convergence test (used for
        complex-step derivatives, where the test would only see the real part).
    field : callable
        The vector field ``field(y, inv_moments)`` (default: the canonical
        equations of the free body).
    Z0 : ndarray, shape (D, s, B), optional
        Starting guess for the stage increments (default zero); see
        :attr:`GaussTableau.extrapolation`. It changes only the number of
        iterations, not the converged result (beyond round-off).
    counts : ndarray of int, shape (B,), optional
        If given, filled with the number of iterations each body needed.

    Returns
    -------
    y1 : ndarray, shape (D, B)
    iters : int
        Iterations used (the largest over the batch).
    Z : ndarray, shape (D, s, B)
        The converged stage increments.

    Raises
    ------
    EulerPoissonError
        If the iteration diverges or does not reach round-off in ``max_iter``
        iterations (the step is too large: reduce ``dt``).
    """
    A, b = tableau.A, tableau.b
    s = b.shape[0]
    B = y0.shape[1]
    y0s = y0[:, None, :]
    d = inv_moments[:, None, :]
    Z = np.zeros((y0.shape[0], s, B), dtype=y0.dtype) if Z0 is None else Z0
    F = field(y0s + Z, d)
    if iterations is not None:
        for _ in range(iterations):
            Z = h * _combine(A, F)
            F = field(y0s + Z, d)
        if counts is not None:
            counts[...] = iterations
        return y0 + h * _weights(b, F), iterations, Z
    D = y0.shape[0]
    active = np.ones(B, dtype=bool)
    all_active = True
    dprev = np.full(B, np.inf)
    scale = None
    k = 0
    for k in range(1, max_iter + 1):
        Znew = h * _combine(A, F)
        delta = np.abs(Znew - Z).reshape(D * s, B).max(axis=0)
        if scale is None:  # size of y0 + Z, fixed for the step
            scale = np.abs(y0).max(axis=0) + np.abs(Znew).reshape(D * s, B).max(axis=0)
            if not np.all(np.isfinite(scale)):
                raise _error_nonfinite(h)
        if not np.all(delta <= 1e3 * (scale + 1.0)):  # also catches NaN
            raise _error_diverged(h)
        done = (delta <= _EPS * scale) | ((delta >= dprev) & (delta <= 64 * _EPS * scale))
        if counts is not None:
            counts[active & done] = k
        if all_active:
            Z = Znew
        else:
            Z = np.where(active, Znew, Z)
        active &= ~done
        dprev = delta
        if not active.any():
            break
        Fnew = field(y0s + Z, d)
        all_active = bool(active.all())
        F = Fnew if all_active else np.where(active, Fnew, F)
    else:
        bad = np.max(np.where(active, delta / scale, 0.0))
        raise _error_max_iter(max_iter, bad, h)
    return y0 + h * _weights(b, F), k, Z


# ---------------------------------------------------------------------------
# Lie-Poisson splitting in (R, M)
# ---------------------------------------------------------------------------
_YOSHIDA_1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
_YOSHIDA_0 = 1.0 - 2.0 * _YOSHIDA_1


def splitting_sequence(order: int) -> list[tuple[int, float]]:
    r"""Sub-flows of one splitting step, as (principal axis, fraction of h), adjacent ones merged.

    Order 2: :math:`(1,\tfrac12), (2,\tfrac12), (3,1), (2,\tfrac12), (1,\tfrac12)`
    (axes 0-based in the result). Order 4: Yoshida's triple jump
    :math:`S_{\gamma_1h}S_{\gamma_0h}S_{\gamma_1h}` with
    :math:`\gamma_1 = 1/(2-2^{1/3})`, :math:`\gamma_0 = 1-2\gamma_1`.

    Raises
    ------
    InvalidInputError
        Order other than 2 or 4.
    """
    strang = [(0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)]
    if order == 2:
        seq = strang
    elif order == 4:
        seq = []
        for g in (_YOSHIDA_1, _YOSHIDA_0, _YOSHIDA_1):
            seq += [(a, g * f) for a, f in strang]
    else:
        raise InvalidInputError(f"splitting order must be 2 or 4, got {order!r}")
    merged: list[tuple[int, float]] = []
    for a, f in seq:
        if merged and merged[-1][0] == a:
            merged[-1] = (a, merged[-1][1] + f)
        else:
            merged.append((a, f))
    return merged


def _rotate_about_axis(q, M, inv_moments, axis, tau):
    r"""Exact flow of :math:`H_i = M_i^2/(2I_i)` for time ``tau``, in place.

    :math:`\boldsymbol\Omega = (M_i/I_i)\mathbf e_i` is constant;
    :math:`\dot{\mathbf M} = \mathbf M\times\boldsymbol\Omega` rotates
    :math:`\mathbf M` by :math:`-\varphi` about :math:`\mathbf e_i` and
    :math:`\dot R = R[\boldsymbol\Omega]_\times` gives
    :math:`q\leftarrow q\otimes(\cos\frac\varphi2, \sin\frac\varphi2\,\mathbf e_i)`,
    :math:`\varphi = \tau M_i/I_i`. Only :math:`\sin\frac\varphi2`,
    :math:`\cos\frac\varphi2` are evaluated (by the same polynomial as the
    compiled kernel), :math:`\sin\varphi = 2\sin\frac\varphi2\cos\frac\varphi2`,
    :math:`\cos\varphi = 1 - 2\sin^2\frac\varphi2`.
    """
    from . import kernels as _k

    i = axis
    j = (i + 1) % 3
    k = (i + 2) % 3
    sh, ch_ = _k.sincos_numpy(0.5 * (tau * (M[i] * inv_moments[i])))
    s = 2.0 * sh * ch_
    c = 1.0 - 2.0 * sh * sh
    Mj = M[j]
    Mk = M[k]
    M[j], M[k] = c * Mj + s * Mk, c * Mk - s * Mj
    w = q[0]
    vi = q[1 + i]
    vj = q[1 + j]
    vk = q[1 + k]
    q[0], q[1 + i], q[1 + j], q[1 + k] = w * ch_ - vi * sh, w * sh + vi * ch_, vj * ch_ + vk * sh, vk * ch_ - vj * sh


def splitting_advance(q, M, inv_moments, h, nsteps, sequence):
    r"""``nsteps`` splitting steps of size ``h`` (sub-flows merged across step boundaries).

    Parameters
    ----------
    q : ndarray, shape (4, B)
        Attitudes in the principal frame (not modified).
    M : ndarray, shape (3, B)
        Body angular momenta in the principal frame (not modified).
    inv_moments : ndarray, shape (3, B)
    h : float
    nsteps : int
    sequence : list of (axis, fraction)
        From :func:`splitting_sequence`; first and last on the same axis.

    Returns
    -------
    q, M : ndarrays, new arrays
    """
    q = q.copy()
    M = M.copy()
    first_axis, first_f = sequence[0]
    last_f = sequence[-1][1]
    middle = sequence[1:-1]
    for step in range(nsteps):
        f0 = first_f if step == 0 else first_f + last_f
        _rotate_about_axis(q, M, inv_moments, first_axis, f0 * h)
        for a, f in middle:
            _rotate_about_axis(q, M, inv_moments, a, f * h)
    _rotate_about_axis(q, M, inv_moments, sequence[-1][0], last_f * h)
    return q, M


# ---------------------------------------------------------------------------
# the registered method
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SymplecticOptions(MethodOptions):
    """Options of ``method="symplectic"``; see :class:`Symplectic` for their meaning.

    Examples
    --------
    >>> from eulerpoisson.solvers import SymplecticOptions
    >>> opts = SymplecticOptions(scheme="gauss4", dt=0.01)
    >>> opts.method, opts.scheme, opts.dt, opts.variables
    ('symplectic', 'gauss4', 0.01, 'quaternion')
    """

    method: ClassVar[str] = "symplectic"

    scheme: str | None = None
    variables: str = "quaternion"
    dt: float | None = None
    max_iter: int = 100
    chart_threshold: float = 1.0
    max_steps: int = 100_000_000

    def check(self) -> None:
        cfg = self.to_dict()
        scheme = cfg["scheme"]
        if scheme is not None and (not isinstance(scheme, str) or scheme not in SCHEMES):
            raise InvalidInputError(f"symplectic: unknown scheme {scheme!r}; choose one of {', '.join(SCHEMES)}")
        if cfg["variables"] not in VARIABLES:
            raise InvalidInputError(
                f"symplectic: unknown variables {cfg['variables']!r}; choose one of {', '.join(VARIABLES)}"
            )
        dt = cfg["dt"]
        if dt is not None:
            if isinstance(dt, bool) or not isinstance(dt, (int, float, np.integer, np.floating)):
                raise InvalidInputError(f"symplectic: dt must be a positive number or None, got {dt!r}")
            if not (math.isfinite(float(dt)) and float(dt) > 0):
                raise InvalidInputError(f"symplectic: dt must be a finite number > 0, got {dt!r}")
        cfg["max_iter"] = ch.check_count("symplectic", "max_iter", cfg["max_iter"])
        cfg["chart_threshold"] = ch.check_threshold(cfg["chart_threshold"])
        cfg["max_steps"] = ch.check_count("symplectic", "max_steps", cfg["max_steps"])

        self._update(cfg)


@register_method
class Symplectic(Method):
    r"""Symplectic integrators: Gauss collocation in :math:`(\mathbf n,\boldsymbol\pi)` or Lie-Poisson splitting.

    Parameters
    ----------
    scheme : str or None
        ``"gauss2"``, ``"gauss4"``, ``"gauss6"`` (Gauss-Legendre
        collocation of orders 2, 4, 6 in canonical variables),
        ``"splitting"`` (order 2) or ``"splitting4"`` (order 4), the explicit
        Lie-Poisson splitting in :math:`(R, \mathbf M)`, and, for bodies under
        torque, ``"exact_splitting"`` (order 2) or ``"exact_splitting4"``
        (order 4): the exact free-body flow composed with torque kicks
        (:mod:`.exact_splitting`; Celledoni, Fassò, Säfström and Zanna 2008).
        None (default): ``"gauss4"`` for the free body, ``"exact_splitting4"``
        under torque.
    variables : str
        Canonical variables of the Gauss schemes: ``"quaternion"`` (default:
        the homogeneous coordinates :math:`(q, p)\in T^*\mathbb R^4` of the
        paper's :math:`(\mathbf n, \boldsymbol\pi)`, :math:`\mathbf n = \mathbf q/q_0`;
        no charts are needed, :math:`\mathbf m`, :math:`|q|` and :math:`q\cdot p`
        are conserved exactly and the energy error stays bounded) or
        ``"gibbs"`` (the paper's :math:`(\mathbf n, \boldsymbol\pi)` themselves,
        eq. 1.15, with chart changes at :math:`|\mathbf n| = 1`: symplectic
        within each chart, but every chart is left outward, so the energy
        error of the modified Hamiltonian accumulates linearly, O(h^p) per
        chart change; kept as the paper's variables, not for long runs: it
        runs in NumPy, not in the compiled kernels, and is measured about
        500 times slower than the default at t = 1e4).
    dt : float or None
        Largest time step (> 0). ``None``: :math:`0.05/\max|\boldsymbol\Omega_0|`
        over the batch (a rotation of 0.05 rad per step).
    max_iter : int
        Cap on the fixed-point iterations per Gauss step (default 100).
    chart_threshold : float
        Re-centre the Gibbs chart where :math:`|\mathbf n|` exceeds it
        (default 1, a 90° rotation; 0 re-centres before every step, which
        makes the method a Cayley-chart Lie-group method that is no longer
        symplectic). Gauss with ``variables="gibbs"`` only.
    max_steps : int
        Most steps per body (default 10^8): the number of fixed steps the
        output times need is known before the run, and a larger one is
        refused with :class:`~eulerpoisson.errors.InvalidInputError`.

    The nominal order depends on the scheme: :meth:`nominal_order`.

    Statistics (``Trajectory.stats``): ``steps``, ``dt``, ``chart_changes``,
    ``compiled`` (the numba kernels ran) and, for Gauss, ``iterations`` (the
    fixed-point iterations summed over the steps, for the body that needed
    most) and ``max_iterations`` (the most in one step).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.solvers.symplectic import Symplectic
    >>> Symplectic.name
    'symplectic'
    >>> tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 1.0, 3), omega0=[1.0, 0.1, 0.5], method="symplectic",
    ...               scheme="splitting", dt=0.05)
    >>> bool(tr.drift()["m_norm"] < 1e-13)                         # m is conserved to round-off
    True
    """

    name = "symplectic"
    Options = SymplecticOptions
    order = 4
    refine = "dt"
    negative_times = True
    description = "Gauss-Legendre collocation in (n, pi) with chart changes, or Lie-Poisson splitting in (R, M)"
    additive_stats = ("chart_changes",)
    #: the default step of a whole batch, fixed by :meth:`for_batch` (None: from the bodies run)
    _batch_dt: float | None = None

    def _scheme(self, problem: Problem) -> str:
        return self.config["scheme"] or ("gauss4" if problem.model.is_free else "exact_splitting4")

    def for_batch(self, problem: Problem) -> Symplectic:
        """This method with the default step (from the fastest body of the batch) fixed for the whole batch."""
        import copy

        planned = copy.copy(self)
        if self.config["dt"] is None and problem.batch_shape and int(np.prod(problem.batch_shape)) > 0:
            if self._scheme(problem) in TORQUE_SCHEMES:
                planned._batch_dt = self._torque_default_dt(problem)
            elif problem.model.is_free:
                planned._batch_dt = self._free_default_dt(self._free_state(problem)[1])
        return planned

    def work_estimate(self, problem: Problem) -> float:
        """Rough seconds on one core: the number of fixed steps times a cost per body-step of the scheme."""
        cfg = self.config
        B = int(np.prod(problem.batch_shape, dtype=int))
        T = problem.t.shape[0]
        tmax = float(np.max(np.abs(problem.t))) if T else 0.0
        dt = cfg["dt"]
        if dt is None:
            with np.errstate(over="ignore"):
                wmax = float(np.max(np.sqrt(np.sum(problem.omega0 * problem.omega0, axis=-1)))) if B else 0.0
            dt = DEFAULT_ROTATION_PER_STEP / wmax if wmax > 0 else max(tmax, 1.0)
        scheme = self._scheme(problem)
        if scheme in TORQUE_SCHEMES:
            per_step = 1e-6
        elif scheme.startswith("gauss"):
            per_step = 0.3e-6 if cfg["variables"] == "quaternion" else 5e-6
        else:
            per_step = 0.1e-6
        with np.errstate(over="ignore"):
            steps = B * (1.0 + tmax / float(dt))
        return steps * per_step + 1e-7 * B * T

    @staticmethod
    def _free_state(problem: Problem):
        """``(q0, w0, moments, frame)`` of a free-body batch in the principal frame, (C, B) arrays (frame None:
        the body frame is principal)."""
        B = int(np.prod(problem.batch_shape, dtype=int))
        q0 = np.ascontiguousarray(problem.q0.reshape(B, 4).T)
        w0 = np.ascontiguousarray(problem.omega0.reshape(B, 3).T)
        if problem.body.is_diagonal:  # the body frame is principal: no transformation (and no cost)
            return q0, w0, np.ascontiguousarray(problem.principal_moments.reshape(B, 3).T), None
        frame = ch.principal_frame(problem)
        q0, w0 = frame.to_principal(q0, w0)
        return q0, w0, frame.moments, frame

    @staticmethod
    def _free_default_dt(w0) -> float:
        """0.05 rad per step for the fastest body (``w0``: (3, B) principal-frame angular velocities)."""
        with np.errstate(over="ignore"):
            wmax = float(np.max(np.sqrt(ch.dot(w0, w0)))) if w0.shape[1] else 0.0
        return DEFAULT_ROTATION_PER_STEP / wmax if wmax > 0 else math.inf

    @staticmethod
    def _torque_default_dt(problem: Problem) -> float:
        """0.05 rad per step for the fastest body, its rate including the torque's sqrt(|I^-1 tau|) at t = 0."""
        B = int(np.prod(problem.batch_shape, dtype=int))
        w0 = problem.omega0.reshape(B, 3)
        rate = np.sqrt(np.sum(w0 * w0, axis=-1))
        if B and not problem.model.is_free:
            tau = problem.model.torque(0.0, problem.q0, problem.omega0).reshape(B, 3)
            acc = np.einsum("bij,bj->bi", np.linalg.inv(problem.inertia.reshape(B, 3, 3)), tau)
            rate = np.maximum(rate, np.sqrt(np.sqrt(np.sum(acc * acc, axis=-1))))
        wmax = float(np.max(rate)) if B else 0.0
        return DEFAULT_ROTATION_PER_STEP / wmax if wmax > 0 else math.inf

    def nominal_order(self) -> int:
        """Order of convergence of the configured scheme (2, 4 or 6; 4 for the default)."""
        return SCHEMES[self.config["scheme"] or "gauss4"]

    @hybridmethod
    def supports(cls, model) -> str | None:
        """Whether the method (its configured scheme, when asked of an instance) runs ``model``."""
        if model.is_free:
            return None
        scheme = cls.config["scheme"] if isinstance(cls, Symplectic) else None
        if scheme is not None and scheme not in TORQUE_SCHEMES:
            return (
                f"scheme {scheme!r} solves the free body only (the model has {model.describe()}); under torque "
                "use scheme='exact_splitting' (order 2) or 'exact_splitting4' (order 4)"
            )
        if any(t.depends_on_omega for t in model.torques) or model.polynomial() is None:
            return (
                "its splitting kicks with torques that depend on the time and the attitude only (Gravity, "
                f"GravityGradient, BodyTorque, SpaceTorque), and the model has {model.describe()}"
            )
        return None
        if any(t.depends_on_omega for t in model.torques) or model.polynomial() is None:
            return (
                "its splitting kicks with torques that depend on the time and the attitude only (Gravity, "
                f"GravityGradient, BodyTorque, SpaceTorque), and the model has {model.describe()}"
            )
        return None

    # ------------------------------------------------------------------
    def run(self, problem: Problem) -> MethodResult:
        from . import kernels as _k

        cfg = self.config
        scheme = self._scheme(problem)
        if scheme in TORQUE_SCHEMES:
            return self._run_exact_splitting(problem, SCHEMES[scheme], scheme)
        if not problem.model.is_free:
            raise UnsupportedModelError(
                f"symplectic: scheme {scheme!r} solves the free body only; under torque use scheme="
                f"'exact_splitting' (order 2) or 'exact_splitting4' (order 4)"
            )
        bshape = problem.batch_shape
        B = int(np.prod(bshape, dtype=int))
        q0, w0, moments, frame = self._free_state(problem)
        inv_m = 1.0 / moments
        dt = cfg["dt"]
        if dt is None:
            dt = self._batch_dt if self._batch_dt is not None else self._free_default_dt(w0)
        dt = float(dt)
        if B:
            ch.check_step_budget(
                "symplectic",
                problem.t,
                1.0 / dt if dt > 0 else math.inf,
                cfg["max_steps"],
                "raise max_steps or dt, or shorten the times",
            )
        stats = {"scheme": scheme, "dt": dt}
        compiled = _k.USE_NUMBA and B > 0 and (not scheme.startswith("gauss") or cfg["variables"] == "quaternion")
        stats["compiled"] = bool(compiled)
        if scheme.startswith("gauss"):
            stats["variables"] = cfg["variables"]
            stages = SCHEMES[scheme] // 2
            if compiled:
                run = self._run_gauss_quaternion_compiled
            else:
                run = self._run_gauss if cfg["variables"] == "gibbs" else self._run_gauss_quaternion
            outs, nsteps = run(problem.t, dt, q0, w0, moments, inv_m, stages, stats)
        else:
            run = self._run_splitting_compiled if compiled else self._run_splitting
            outs, nsteps = run(problem.t, dt, q0, w0, moments, inv_m, SCHEMES[scheme], stats)
        T = problem.t.shape[0]
        if compiled:  # outputs (B, T, C) -> (C, B, T); copied for the frame (einsum rounds by memory layout)
            outs = tuple(
                np.moveaxis(o, -1, 0) if frame is None else np.ascontiguousarray(np.moveaxis(o, -1, 0)) for o in outs
            )
        q, w = outs if frame is None else frame.from_principal(*outs)  # (4, B, T), (3, B, T)
        q = np.moveaxis(q, 0, -1).reshape(bshape + (T, 4))
        w = np.moveaxis(w, 0, -1).reshape(bshape + (T, 3))
        stats["steps"] = nsteps
        return MethodResult(q=q, omega=w, stats=stats)

    @staticmethod
    def _iteration_stats(stats, total, most):
        """Fixed-point iteration counters: per body totals ``total`` and per-step maxima ``most``, shape (B,)."""
        stats["iterations"] = int(np.max(total)) if total.size else 0
        stats["max_iterations"] = int(np.max(most)) if most.size else 0

    def _run_gauss(self, t, dt, q0, w0, moments, inv_m, stages, stats):
        tab = gauss_tableau(stages)
        E = tab.extrapolation
        thr = self.config["chart_threshold"]
        max_iter = int(self.config["max_iter"])
        B = q0.shape[1]
        counters = {"chart_changes": 0}
        total = np.zeros(B, dtype=np.int64)
        most = np.zeros(B, dtype=np.int64)
        counts = np.zeros(B, dtype=np.int64)
        y0 = np.concatenate([np.zeros_like(w0), 2.0 * moments * w0])

        def advance(state, h, nsteps):
            qc, y = state
            Z = None
            for _ in range(nsteps):
                qc, n, p, changed = ch.change_chart(qc, y[:3], y[3:], thr)
                if changed.any():
                    counters["chart_changes"] += int(changed.sum())
                    y = np.concatenate([n, p])
                Z0 = None if Z is None else np.where(changed, 0.0, _combine(E, Z))
                y, _, Z = gauss_step(y, h, inv_m, tab, max_iter=max_iter, Z0=Z0, counts=counts)
                total[:] += counts
                np.maximum(most, counts, out=most)
            return qc, y

        def output(state):
            qc, y = state
            q = ch.qmul(qc, ch.quaternion_from_gibbs(y[:3]))
            return q, ch.omega_from_pi(y[:3], y[3:], inv_m)

        outs, nsteps = ch.run_fixed_step(t, dt, (q0, y0), advance, output)
        stats.update(counters)
        self._iteration_stats(stats, total, most)
        return outs, nsteps

    def _run_gauss_quaternion(self, t, dt, q0, w0, moments, inv_m, stages, stats):
        tab = gauss_tableau(stages)
        E = tab.extrapolation
        max_iter = int(self.config["max_iter"])
        B = q0.shape[1]
        total = np.zeros(B, dtype=np.int64)
        most = np.zeros(B, dtype=np.int64)
        counts = np.zeros(B, dtype=np.int64)
        y0 = np.concatenate([q0, ch.qp_from_body_momentum(q0, moments * w0)])

        def advance(y, h, nsteps):
            Z = None
            for _ in range(nsteps):
                y, _, Z = gauss_step(
                    y,
                    h,
                    inv_m,
                    tab,
                    max_iter=max_iter,
                    field=ch.quaternion_field,
                    Z0=None if Z is None else _combine(E, Z),
                    counts=counts,
                )
                total[:] += counts
                np.maximum(most, counts, out=most)
            return y

        def output(y):
            q = y[:4] / np.sqrt(ch.dot4(y[:4], y[:4]))
            return q, inv_m * ch.body_momentum_from_qp(y[:4], y[4:])

        outs, nsteps = ch.run_fixed_step(t, dt, y0, advance, output)
        stats["chart_changes"] = 0
        self._iteration_stats(stats, total, most)
        return outs, nsteps

    def _run_gauss_quaternion_compiled(self, t, dt, q0, w0, moments, inv_m, stages, stats):
        from . import kernels as _k

        max_iter = int(self.config["max_iter"])
        y0 = np.concatenate([q0, ch.qp_from_body_momentum(q0, moments * w0)])
        q, w, iters, nsteps, status = _k.run_gauss_quaternion(y0, inv_m, gauss_tableau(stages), t, dt, max_iter)
        code, h = int(status[0]), float(status[1])
        if code == _k.STATUS_NONFINITE:
            raise _error_nonfinite(h)
        if code == _k.STATUS_DIVERGED:
            raise _error_diverged(h)
        if code == _k.STATUS_MAX_ITER:
            raise _error_max_iter(max_iter, float(status[2]), h)
        stats["chart_changes"] = 0
        self._iteration_stats(stats, iters[:, 0], iters[:, 1])
        return (q, w), nsteps

    def _run_splitting(self, t, dt, q0, w0, moments, inv_m, order, stats):
        seq = splitting_sequence(order)

        def advance(state, h, nsteps):
            q, M = state
            return splitting_advance(q, M, inv_m, h, nsteps, seq)

        def output(state):
            q, M = state
            return q.copy(), M * inv_m

        outs, nsteps = ch.run_fixed_step(t, dt, (q0, moments * w0), advance, output)
        stats["chart_changes"] = 0
        return outs, nsteps

    def _run_splitting_compiled(self, t, dt, q0, w0, moments, inv_m, order, stats):
        from . import kernels as _k

        q, w, nsteps = _k.run_splitting(q0, moments * w0, inv_m, splitting_sequence(order), t, dt)
        stats["chart_changes"] = 0
        return (q, w), nsteps

    def _run_exact_splitting(self, problem: Problem, order: int, scheme: str) -> MethodResult:
        """The exact free flow composed with torque kicks, in the principal frame (:mod:`.exact_splitting`)."""
        from .exact_splitting import run_exact_splitting

        cfg = self.config
        bshape = problem.batch_shape
        B = int(np.prod(bshape, dtype=int))
        T = problem.t.shape[0]
        P = np.ascontiguousarray(problem.principal_axes.reshape(B, 3, 3))
        D = np.ascontiguousarray(problem.principal_moments.reshape(B, 3))
        qP = quaternion_from_rotation_matrix(P)
        q0 = problem.q0.reshape(B, 4)
        w0 = problem.omega0.reshape(B, 3)
        qp0 = qmul(q0, qP)
        Mp0 = D * np.einsum("bji,bj->bi", P, w0)
        poly = problem.model.polynomial()
        assert poly is not None  # supports() admits polynomial torques only
        data = poly.flatten(bshape).in_frame(P)
        dt = cfg["dt"]
        if dt is None:
            dt = self._batch_dt if self._batch_dt is not None else self._torque_default_dt(problem)
        dt = float(dt)
        if B:
            ch.check_step_budget(
                "symplectic",
                problem.t,
                1.0 / dt if dt > 0 else math.inf,
                cfg["max_steps"],
                "raise max_steps or dt, or shorten the times",
            )
        qp, Mp, nsteps = run_exact_splitting(D, qp0, Mp0, data, problem.t, dt, order)
        if not (np.all(np.isfinite(qp)) and np.all(np.isfinite(Mp))):
            raise EulerPoissonError("symplectic: the state became non-finite (the step dt is far too large)")
        q = qmul(qp, (qP * np.array([1.0, -1.0, -1.0, -1.0]))[:, None, :])
        w = np.einsum("bij,btj->bti", P, Mp / D[:, None, :])
        stats = {"scheme": scheme, "dt": dt, "steps": nsteps, "compiled": bool(USE_NUMBA), "chart_changes": 0}
        return MethodResult(q=q.reshape(bshape + (T, 4)), omega=w.reshape(bshape + (T, 3)), stats=stats)
