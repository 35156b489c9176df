"""Input validation shared by the package (private)."""

from __future__ import annotations

import numbers

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError

#: the largest phase (rad) of a motion, |Omega| |t| or a heavy top's W |t|, that float64 still determines: the
#: frequencies are rounded numbers, and a few ulp of them shift the phase by more than 0.1 rad beyond it
MAX_PHASE = 2.0**48


def check_phase(
    t: np.ndarray, w: np.ndarray, speed=None, *, who: str = "exact", what: str = "|omega0| |t|", rate: str = "omega0"
) -> None:
    r"""Refuse times at which float64 no longer determines the phase of a motion: :math:`|\Omega_0||t| > 2^{48}`.

    The frequencies of the motion are rounded numbers: a relative error of a few ulp becomes a phase
    error of about :math:`4\varepsilon|\boldsymbol\Omega||t|`, more than a tenth of a radian beyond
    :data:`MAX_PHASE`: an error instead of a silent guess.

    Parameters
    ----------
    t : ndarray, shape (T,)
        The times (finite).
    w : ndarray, shape (*batch, 3)
        The initial rates :math:`\boldsymbol\Omega_0` (an overflowed one, inf, is refused too).
    speed : ndarray, shape (*batch), optional
        Replaces :math:`|\boldsymbol\Omega_0|` (a heavy top's rate includes :math:`\sqrt{\mu g\ell/A}`).
    who, what, rate : str
        The message's prefix, the phase's name and the rate's name.

    Raises
    ------
    InvalidInputError
        Naming the body (its index in the batch) and the phase, or the rate that overflowed.

    Examples
    --------
    >>> import numpy as np
    >>> check_phase(np.array([0.0, 1e3]), np.array([1.0, 0.0, 0.0]))
    >>> check_phase(np.array([1e15]), np.array([1.0, 0.0, 0.0]))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: exact: |omega0| |t| = 1e+15 exceeds 2^48 = 2.81e+14 rad: ...
    """
    if t.size == 0:
        return
    few = w.ndim == 1 and t.size <= 16  # one body at a few times: the maxima in plain floats
    tmax = max(map(abs, t.tolist())) if few else float(np.abs(t).max())
    if speed is None:
        # the common case without a temporary array: |Omega0|^2 <= 3 max|Omega0_i|^2 (4: room for rounding)
        wmax = max(map(abs, w.tolist())) if few else max(float(np.max(w, initial=0.0)), -float(np.min(w, initial=0.0)))
        if tmax == 0.0 or 4.0 * (wmax * wmax) * (tmax * tmax) <= 0.25 * MAX_PHASE * MAX_PHASE:
            return
        with np.errstate(over="ignore"):
            w2 = np.sum(w * w, axis=-1)
        # the common case in one pass: every |Omega0| t well inside the range (no square roots)
        if float(np.max(w2, initial=0.0)) * (tmax * tmax) <= 0.25 * MAX_PHASE * MAX_PHASE:
            return
        speed = np.sqrt(w2)
        if not np.all(np.isfinite(speed)):  # |Omega0| beyond 1e154: its square overflowed, not (always) the rate
            with np.errstate(invalid="ignore"):
                speed = scaled_norms(w)
    with np.errstate(over="ignore", invalid="ignore"):
        phase = np.asarray(speed * tmax)
    bad = ~(phase <= MAX_PHASE)  # (NaN: an infinite rate)
    if np.any(bad):
        flat = np.reshape(phase, -1)
        i = int(np.flatnonzero(np.reshape(bad, -1))[0])
        where = f" (body {tuple(int(k) for k in np.unravel_index(i, phase.shape))})" if phase.ndim else ""
        if not np.isfinite(np.reshape(speed, -1)[i]):
            raise InvalidInputError(
                f"{who}: {rate} overflows float64{where}: float64 cannot say where on its orbit the body is"
            )
        raise InvalidInputError(
            f"{who}: {what} = {flat[i]:.3g}{where} exceeds 2^48 = {MAX_PHASE:.3g} rad: at |t| = {tmax:.6g} "
            f"the rounding of the frequencies (a few ulp) already shifts the phase of the motion by more than "
            f"0.1 rad, so float64 cannot say where on its orbit the body is; use shorter times"
        )


def describe_value(x) -> str:
    a = np.asarray(x)
    if a.size <= 6:
        return repr(a.tolist()) if a.ndim else repr(a.item())
    return f"array of shape {a.shape}"


def as_float_array(x, name: str, tail: tuple[int, ...] = (), *, allow_nonfinite: bool = False) -> np.ndarray:
    """Return ``x`` as a float64 array whose trailing shape is ``tail``.

    Parameters
    ----------
    x : array_like
        The value to convert.
    name : str
        Argument name used in error messages.
    tail : tuple of int
        Required trailing dimensions, e.g. ``(3,)`` or ``(3, 3)``.
    allow_nonfinite : bool
        Accept NaN and inf (default: reject them).

    Raises
    ------
    TypeError
        If ``x`` is not numeric (strings, objects, complex numbers).
    InvalidInputError
        If the trailing shape is wrong or a value is NaN or infinite.
    """
    if type(x) is np.ndarray and x.dtype == _FLOAT64:
        a = x  # the common case (the checks below, without the conversions)
    else:
        a = _convert(x, name)
    nt = len(tail)
    if nt and (a.ndim < nt or a.shape[a.ndim - nt :] != tuple(tail)):
        want = "(..., " + ", ".join(str(t) for t in tail) + ")"
        raise InvalidInputError(f"{name} must have shape {want}, got shape {a.shape}")
    if not allow_nonfinite and not np.isfinite(a).all():
        raise InvalidInputError(f"{name} contains NaN or infinite values: {describe_value(a)}")
    return a


_FLOAT64 = np.dtype(np.float64)


def _convert(x, name: str) -> np.ndarray:
    """``x`` as a float64 array (:func:`as_float_array` without the shape and finiteness checks)."""
    if isinstance(x, (str, bytes)):
        raise TypeError(f"{name} must be numeric, got the string {x!r}")
    if isinstance(x, np.ma.MaskedArray):
        raise TypeError(f"{name} is a masked array; its mask would be ignored: fill or drop the masked values first")
    try:
        a = np.asarray(x)
    except Exception as exc:  # ragged lists etc.
        raise InvalidInputError(f"{name} could not be converted to an array: {exc}") from exc
    if a.dtype == object or not np.issubdtype(a.dtype, np.number):
        raise TypeError(f"{name} must be a real numeric array, got dtype {a.dtype}")
    if np.iscomplexobj(a):
        raise TypeError(f"{name} must be real, got complex dtype {a.dtype}")
    return a.astype(np.float64, copy=False)


def as_scalar(x, name: str, *, positive: bool = False, nonnegative: bool = False, integer: bool = False) -> float:
    """Return ``x`` as a finite Python float (or int), with range checks.

    Raises
    ------
    TypeError
        If ``x`` is not a real number.
    InvalidInputError
        If ``x`` is not finite or out of range.
    """
    if isinstance(x, bool) or not isinstance(x, (numbers.Real, np.floating, np.integer)):
        if isinstance(x, np.ndarray) and x.ndim == 0:
            x = x.item()
        else:
            kind = "an integer" if integer else "a real number"
            raise TypeError(f"{name} must be {kind}, got {type(x).__name__} {x!r}")
    v = float(x)
    if not np.isfinite(v):
        raise InvalidInputError(f"{name} must be finite, got {v!r}")
    if integer:
        if v != int(v):
            raise InvalidInputError(f"{name} must be an integer, got {x!r}")
        v = int(v)
    if positive and not v > 0:
        raise InvalidInputError(f"{name} must be > 0, got {x!r}")
    if nonnegative and not v >= 0:
        raise InvalidInputError(f"{name} must be >= 0, got {x!r}")
    return v


def as_bool(x, name: str) -> bool:
    """A flag: ``bool`` or ``numpy.bool_`` only (a string such as ``"no"`` is truthy, so it is refused).

    Raises
    ------
    TypeError
        If ``x`` is not a boolean.
    """
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    raise TypeError(f"{name} must be True or False, got {x!r} ({type(x).__name__})")


def check_broadcast(**arrays) -> tuple[int, ...]:
    """Broadcast batch shape of arrays whose last axis is a vector (quaternion, Gibbs vector...).

    ``check_broadcast(p=p, q=q)`` returns ``np.broadcast_shapes(p.shape[:-1], q.shape[:-1])``.

    Raises
    ------
    InvalidInputError
        Naming every argument with its shape when the batch shapes do not broadcast.
    """
    try:
        return np.broadcast_shapes(*(np.shape(a)[:-1] for a in arrays.values()))
    except ValueError:
        desc = ", ".join(f"{k} {np.shape(a)}" for k, a in arrays.items())
        raise InvalidInputError(
            f"batch shapes do not broadcast: {desc} (leading axes must broadcast as in numpy)"
        ) from None


def as_shape(shape, name: str = "shape") -> tuple[int, ...]:
    """A batch shape: a non-negative int or a sequence of them (not bools, not floats).

    Raises
    ------
    TypeError
        If ``shape`` is not an int or a sequence of ints.
    InvalidInputError
        If an entry is negative.
    """
    items = (shape,) if isinstance(shape, (int, np.integer)) and not isinstance(shape, (bool, np.bool_)) else shape
    try:
        items = tuple(items)
    except TypeError:
        raise TypeError(f"{name} must be an int or a tuple of ints, got {shape!r}") from None
    for k in items:
        if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)):
            raise TypeError(f"{name} must be an int or a tuple of ints, got {shape!r}")
        if k < 0:
            raise InvalidInputError(f"{name} entries must be >= 0, got {shape!r}")
    return tuple(int(k) for k in items)


def scaled_norms(a: ArrayLike, axes: int | tuple[int, int] = -1) -> np.ndarray:
    """Euclidean (Frobenius) norms over ``axes`` without overflow in the squares (inf only when the norm is).

    Examples
    --------
    >>> round(float(scaled_norms([3e200, 4e200, 0.0])) / 1e200, 12)
    5.0
    """
    a = np.abs(np.asarray(a, dtype=float))
    top = np.max(a, axis=axes, keepdims=True)
    safe = np.where(top > 0, top, 1.0)
    return (
        np.squeeze(safe, axis=axes) * np.sqrt(np.sum(np.square(a / safe), axis=axes)) * (np.squeeze(top, axis=axes) > 0)
    )
