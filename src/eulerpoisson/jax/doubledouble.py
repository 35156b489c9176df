r"""Double-double arithmetic in JAX (Dekker 1971), elementwise and differentiable.

The same error-free transformations as :mod:`eulerpoisson.numerics.doubledouble` (the NumPy
reference), written with ``jax.numpy`` so that they trace, compile, vectorize and differentiate.
In float32 (``dtype=jnp.float32``) they are float-float arithmetic (Dekker's splitter
:math:`2^{12}+1`).

A double-double is an unevaluated sum :math:`a = a_h + a_l`, :math:`|a_l| \le \tfrac12\,
\mathrm{ulp}(a_h)`. Derivatives: the tangent of the high part is the tangent of the whole number
(the error terms have tangents of the order of the rounding of the tangent), which is what the
closed form needs (it differentiates through the high parts).

XLA keeps the order of floating-point operations (no reassociation), so the transformations stay
error-free under ``jax.jit``: ``two_sum(1.0, 1e-20)`` returns ``(1.0, 1e-20)``.

References
----------
T. J. Dekker, "A floating-point technique for extending the available precision", Numer. Math. 18
(1971) 224-242. Y. Hida, X. S. Li and D. H. Bailey, "Library for double-double and quad-double
arithmetic" (2007).

Examples
--------
>>> import jax
>>> import jax.numpy as jnp
>>> from eulerpoisson.jax.doubledouble import two_sum
>>> with jax.enable_x64(True):
...     s, e = jax.jit(two_sum)(jnp.float64(1.0), jnp.float64(1e-20))
>>> float(s), float(e)
(1.0, 1e-20)
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

__all__ = [
    "two_sum",
    "quick_two_sum",
    "split",
    "two_prod",
    "dd_add",
    "dd_mul",
    "dd_mul_d",
    "dd_div",
    "dd_sqrt",
    "safe_sqrt",
    "straight",
    "exp2i",
]


def two_sum(a, b):
    """Error-free ``a + b = s + e`` (Knuth)."""
    s = a + b
    bb = s - a
    e = (a - (s - bb)) + (b - bb)
    return s, e


def quick_two_sum(a, b):
    """Error-free ``a + b = s + e`` assuming ``|a| >= |b|``."""
    s = a + b
    e = b - (s - a)
    return s, e


def split(a):
    """``a = hi + lo`` with halves of half the mantissa (Dekker's splitting; float64 or float32)."""
    factor = 134217729.0 if jnp.result_type(a) == jnp.float64 else 4097.0
    t = factor * a
    hi = t - (t - a)
    return hi, a - hi


def two_prod(a, b):
    """Error-free ``a * b = p + e`` (no overflow assumed)."""
    p = a * b
    ah, al = split(a)
    bh, bl = split(b)
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


def dd_add(ah, al, bh, bl):
    """Sum of two double-doubles."""
    s, e = two_sum(ah, bh)
    t, f = two_sum(al, bl)
    e = e + t
    s, e = quick_two_sum(s, e)
    e = e + f
    return quick_two_sum(s, e)


def dd_mul(ah, al, bh, bl):
    """Product of two double-doubles."""
    p, e = two_prod(ah, bh)
    e = e + (ah * bl + al * bh)
    return quick_two_sum(p, e)


def dd_mul_d(ah, al, b):
    """Product of a double-double and a float."""
    p, e = two_prod(ah, b)
    e = e + al * b
    return quick_two_sum(p, e)


def dd_div(ah, al, bh, bl):
    """Quotient of two double-doubles (three correction steps)."""
    q1 = ah / bh
    ph, pl = dd_mul_d(bh, bl, q1)
    rh, rl = dd_add(ah, al, -ph, -pl)
    q2 = rh / bh
    ph, pl = dd_mul_d(bh, bl, q2)
    rh, rl = dd_add(rh, rl, -ph, -pl)
    q3 = rh / bh
    q1, q2 = quick_two_sum(q1, q2)
    return dd_add(q1, q2, q3, 0.0 * q3)


@jax.custom_jvp
def safe_sqrt(x):
    """``sqrt(x)`` whose derivative is 0 (not infinite) at ``x = 0``.

    For square roots of quantities that are exactly zero only where their own tangent is zero (the
    arguments of Carlson's duplication, ``sqrt(m1)`` on the separatrix): the product ``inf * 0`` of
    the plain derivative would be NaN.
    """
    return jnp.sqrt(x)


@safe_sqrt.defjvp
def _safe_sqrt_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    y = jnp.sqrt(x)
    pos = y > 0.0
    return y, jnp.where(pos, 0.5 * dx / jnp.where(pos, y, 1.0), 0.0)


def dd_sqrt(ah, al):
    """Square root of a non-negative double-double (0 -> 0)."""
    x = safe_sqrt(ah)
    pos = x > 0.0
    safe = jnp.where(pos, x, 1.0)
    p, e = two_prod(x, x)
    corr = ((ah - p) - e + al) / (2.0 * safe)
    corr = jnp.where(pos, corr, 0.0)
    return quick_two_sum(x, corr)


def straight(value, new):
    """``value`` with the tangent of ``new`` ("straight-through"; ``new`` must be finite).

    Where an iteration has converged (or a Landen level is not needed) the value stays the one of
    the NumPy reference, bit for bit, while the derivative keeps following the iteration: the
    derivative of a truncated iteration would otherwise miss the steps that were not taken (the
    AGM at ``m = 0`` gives ``dK/dm = 0`` instead of ``pi/8``).
    """
    return jax.lax.stop_gradient(value) + (new - jax.lax.stop_gradient(new))


def exp2i(e, dtype):
    """``2**e`` exactly, for integer ``e`` (an array) in ``dtype`` (float64 or float32), without ``pow``.

    Built from the bits of two powers of two, ``2**(e//2) * 2**(e - e//2)`` (each a normal number
    for ``|e|`` up to twice the largest exponent): the product is exact, ``inf`` above the largest
    power and 0 below the smallest subnormal one, as ``2.0**e``. (``jnp.ldexp`` is a ``pow``, costly
    on a GPU; this is two integer shifts and a product.)

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.doubledouble import exp2i
    >>> [float(v) for v in exp2i(jnp.array([-3, 0, 10]), jnp.float32)]
    [0.125, 1.0, 1024.0]
    """
    f64 = jnp.dtype(dtype) == jnp.float64
    itype, bias, mant = (jnp.int64, 1023, 52) if f64 else (jnp.int32, 127, 23)
    e = jnp.asarray(e).astype(itype)
    lo = jnp.clip(e, -2 * bias + 2, 2 * bias) // 2
    hi = jnp.clip(e, -2 * bias + 2, 2 * bias) - lo

    def bits(k):
        return jax.lax.bitcast_convert_type(jnp.left_shift(k + bias, mant).astype(itype), dtype)

    return bits(lo) * bits(hi)
