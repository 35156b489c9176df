r"""Small helpers shared by the attitude modules: cross-product matrices, norms, scaling, messages.

:func:`skew` and :func:`unskew` are public (``eulerpoisson.attitude.skew``); the other
functions take arrays that are already validated and are used by :mod:`.quaternion`,
:mod:`.gibbs`, :mod:`.rotvec` and :mod:`.attitude`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..util.validate import as_float_array, scaled_norms

__all__ = ["skew", "unskew"]


def skew(v: ArrayLike) -> NDArray[np.float64]:
    r"""Cross-product matrix :math:`[\mathbf v]_\times`, with :math:`[\mathbf v]_\times \mathbf w = \mathbf v\times\mathbf w`.

    In the paper's index notation :math:`([\mathbf v]_\times)_{ij} = -\epsilon_{ijk} v_k`
    (the matrix :math:`-\hat v` of eq. 1.21).

    Parameters
    ----------
    v : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.attitude import skew
    >>> S = skew([1.0, 2.0, 3.0])
    >>> print(S)
    [[ 0. -3.  2.]
     [ 3.  0. -1.]
     [-2.  1.  0.]]
    >>> print(S @ [0.0, 0.0, 1.0], np.cross([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]))
    [ 2. -1.  0.] [ 2. -1.  0.]
    """
    v = as_float_array(v, "v", (3,))
    return skew_unchecked(v)


def skew_unchecked(v: np.ndarray) -> np.ndarray:
    """:func:`skew` of an already validated float array (..., 3), without the checks."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2)


def unskew(S: ArrayLike) -> NDArray[np.float64]:
    r"""Vector of the antisymmetric part of ``S``: the inverse of :func:`skew`.

    .. math:: v_k = -\tfrac12\epsilon_{kij}S_{ij}

    (the map :math:`R^T\dot R\mapsto\boldsymbol\Omega` of eq. 1.10).

    Parameters
    ----------
    S : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    Examples
    --------
    >>> from eulerpoisson.attitude import skew, unskew
    >>> print(unskew(skew([1.0, 2.0, 3.0])))
    [1. 2. 3.]
    """
    S = as_float_array(S, "S", (3, 3))
    return 0.5 * np.stack([S[..., 2, 1] - S[..., 1, 2], S[..., 0, 2] - S[..., 2, 0], S[..., 1, 0] - S[..., 0, 1]], -1)


def outer(a, b):
    """Batched outer products ``a b^T``, shape (..., 3, 3)."""
    return a[..., :, None] * b[..., None, :]


def norm(v):
    """Euclidean norms over the last axis (no overflow protection: scale first)."""
    return np.sqrt(np.sum(v * v, axis=-1))


def scaled_norm(v):
    """Euclidean norms over the last axis, also where the squares underflow or overflow.

    The plain :func:`norm` (its bits) where the sum of squares is safely inside float64; scaled by the
    largest component elsewhere (vectors below about 1e-146 or above 1e146), where the plain sum loses
    digits to subnormal squares or overflows.
    """
    v = np.asarray(v)
    with np.errstate(over="ignore", under="ignore"):
        s2 = np.sum(v * v, axis=-1)
    out = np.sqrt(s2)
    risky = ~((s2 > 2.0**-968) & (s2 < 2.0**968))
    if np.any(risky & np.any(v != 0, axis=-1)):
        out = np.where(risky, scaled_norms(v), out)
    return out


def pow2_below(m):
    """Largest power of two <= m (m > 0 finite); division by it is exact."""
    _, e = np.frexp(m)
    return np.ldexp(1.0, e - 1)


def first_index(mask) -> str:
    """' at batch index (i, j)' for the first True of a boolean batch mask, or ''."""
    mask = np.asarray(mask)
    if mask.ndim == 0:
        return ""
    idx = np.unravel_index(int(np.argmax(mask)), mask.shape)
    return f" at batch index {tuple(int(i) for i in idx)}"


def finite_result(x, what: str, **inputs) -> np.ndarray:
    """``x`` when it is finite; an :class:`~eulerpoisson.errors.InvalidInputError` naming ``what`` and its
    largest input when float64 overflowed (never a silent inf)."""
    if np.all(np.isfinite(x)):
        return x
    desc = ", ".join(f"max |{k}| = {float(np.max(np.abs(v))):.3g}" for k, v in inputs.items())
    raise InvalidInputError(f"{what} overflows float64 for these inputs ({desc}); rescale them")
