"""The computation of one chunk of sweep points: flip half-period, :math:`k^2`, attitude sensitivity
and status of each point (the quantities are defined in :mod:`eulerpoisson.sweep.runner`).
"""

from __future__ import annotations

import math
import time as _time
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError

__all__ = ["compute_points", "STATUS", "classify"]

#: meaning of the ``status`` codes
STATUS = {0: "regular", 1: "separatrix", 2: "symmetric body", 3: "not a physical body"}

_TOL = 1e-12  # same relative tolerance as RigidBody's degeneracy checks


# ---------------------------------------------------------------------------
# the computation of one chunk
# ---------------------------------------------------------------------------
def classify(I: np.ndarray) -> np.ndarray:
    """Status 0 (asymmetric, physical), 2 (symmetric) or 3 (not a physical body) per row of I (m, 3)."""
    s = np.sort(I, -1)
    tol = _TOL * np.sum(np.abs(s), -1)
    bad = (s[:, 0] <= 0) | (s[:, 0] + s[:, 1] - s[:, 2] < -tol)
    sym = (s[:, 1] - s[:, 0] <= tol) | (s[:, 2] - s[:, 1] <= tol)
    return np.where(bad, 3, np.where(sym, 2, 0)).astype(np.int8)


_classify = classify  # the former name


def _rotation_angle(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    w = np.sum(q1 * q2, -1)
    v = q1[..., :1] * q2[..., 1:] - q2[..., :1] * q1[..., 1:] - np.cross(q1[..., 1:], q2[..., 1:])
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))


def compute_points(
    inertia: ArrayLike,
    M0: ArrayLike,
    *,
    T: float,
    delta: float = 1e-6,
    method: str = "exact",
    workers: int | None = None,
) -> dict[str, Any]:
    r"""Flip half-period, :math:`k^2`, attitude sensitivity and status of a batch of points.

    Parameters
    ----------
    inertia : array_like, shape (P, 3)
        Principal moments (any order; rows that are not physical bodies get
        NaN results and status 3).
    M0 : array_like, shape (P, 3)
        Initial body angular momenta (principal frame), nonzero.
    T : float
        Time of the sensitivity, > 0.
    delta : float
        Perturbation angle of the momentum direction (radians).
    method : str
        Method used to compute the attitudes at ``T``.
    workers : int or None
        Threads of the solve, as for :func:`~eulerpoisson.solve` (the
        results do not depend on it).

    Returns
    -------
    dict of ndarray
        ``half_period`` (P,) (inf on the separatrix, NaN for symmetric or
        non-physical bodies), ``k2`` (P,), ``sensitivity`` (P,) (NaN for
        non-physical bodies), ``status`` (P,) int8 (see :data:`STATUS`).

    Raises
    ------
    InvalidInputError
        Bad shapes, non-finite values, a zero momentum, ``T <= 0`` or
        ``delta`` outside (0, 0.1).

    Notes
    -----
    Pure function of its inputs: the same chunk gives the same bits on any
    worker.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.sweep import compute_points
    >>> inertia = [[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [2.0, 2.0, 3.0]]
    >>> M0 = [[0.1, 0.0, 1.0], [0.0, 1.0, 0.1], [0.0, 1.0, 0.1]]    # near axis 3, near axis 2, a symmetric body
    >>> out = compute_points(inertia, M0, T=10.0)
    >>> print(np.round(out["half_period"], 6), out["status"])
    [ 9.496682 24.50238        nan] [0 0 2]
    """
    from scipy.special import ellipkm1

    from ..analysis import elliptic_parameters
    from ..model.body import RigidBody
    from ..solvers import solve
    from ..util.validate import as_float_array, as_scalar

    I = as_float_array(inertia, "inertia", (3,)).reshape(-1, 3)
    M = as_float_array(M0, "M0", (3,)).reshape(-1, 3)
    if I.shape != M.shape:
        raise InvalidInputError(f"inertia and M0 must have the same shape (P, 3), got {I.shape} and {M.shape}")
    T = as_scalar(T, "T", positive=True)
    delta = as_scalar(delta, "delta", positive=True)
    if not delta < 0.1:
        raise InvalidInputError(f"delta must be a small angle in radians, 0 < delta < 0.1, got {delta!r}")
    L = np.linalg.norm(M, axis=-1)
    if np.any(L == 0):
        raise InvalidInputError("M0 contains a zero angular momentum (a body at rest has no flips)")
    P = I.shape[0]
    status = classify(I)
    k2 = np.full(P, np.nan)
    k2c = np.full(P, np.nan)
    lam = np.full(P, np.nan)
    for i in np.nonzero(status == 0)[0]:
        try:
            par = elliptic_parameters(I[i], M[i])
        except InvalidInputError:  # exactly on the separatrix
            status[i], k2[i], k2c[i], lam[i] = 1, 1.0, 0.0, 1.0
            continue
        k2[i], k2c[i], lam[i] = par["k2"], par["k2c"], par["lam"]
    # tennis_racket_half_period = 2 K(k) / lambda, evaluated for the whole chunk at once (same bits)
    with np.errstate(divide="ignore"):
        half = 2.0 * ellipkm1(k2c) / lam
    status[(status == 0) & ~np.isfinite(half)] = 1

    sens = np.full(P, np.nan)
    ok = np.nonzero(status != 3)[0]
    if ok.size:
        Iv, Mv, Lv = I[ok], M[ok], L[ok]
        u = Mv / Lv[:, None]
        th = np.arccos(np.clip(u[:, 2], -1.0, 1.0))
        ph = np.arctan2(u[:, 1], u[:, 0])
        e_th = np.stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)], -1)
        e_ph = np.stack([-np.sin(ph), np.cos(ph), np.zeros_like(ph)], -1)
        c, s = math.cos(delta), math.sin(delta)
        Ms = np.concatenate([Mv, Lv[:, None] * (c * u + s * e_th), Lv[:, None] * (c * u + s * e_ph)])
        Is = np.concatenate([Iv, Iv, Iv])
        # full (diagonal) tensors: a (3, 3) array of moments would read as one tensor
        tr = solve(RigidBody(Is[:, :, None] * np.eye(3)), [T], omega0=Ms / Is, method=method, workers=workers)
        q = tr.quaternion[:, 0, :].reshape(3, ok.size, 4)
        ang = np.maximum(_rotation_angle(q[0], q[1]), _rotation_angle(q[0], q[2]))
        sens[ok] = ang / delta
    return {"half_period": half, "k2": k2, "sensitivity": sens, "status": status}


def compute_chunk(inertia, M0, T, delta, method, run_points=0, workers=None):
    """One task: ``compute_points`` plus its wall time (module-level, so Dask can ship it by reference).

    ``run_points``: the points of the whole sweep (each is solved three times), from which the compiled
    kernels or NumPy are chosen, the same for every chunk. ``workers``: threads of the solve; Dask tasks
    pass 1 (Dask's workers already use the cores).
    """
    from ..util.jit import whole_run

    start = _time.perf_counter()
    with whole_run(n_bodies=3 * int(run_points)):
        out = compute_points(inertia, M0, T=T, delta=delta, method=method, workers=workers)
    out["seconds"] = _time.perf_counter() - start
    return out
