r"""Double-double arithmetic (Dekker 1971): the one copy every module uses.

A double-double is an unevaluated sum :math:`a = a_h + a_l` of two float64
with :math:`|a_l| \le \tfrac12\,\mathrm{ulp}(a_h)`, about 106 bits. The
primitives are written once, elementwise, so they work on floats and numpy
arrays, and are compiled inline into the numba kernels that call them
(:data:`~eulerpoisson.util.jit.jitable`): compiled and numpy paths perform the
same operations and agree bit for bit.

References
----------
T. J. Dekker, "A floating-point technique for extending the available
precision", Numer. Math. 18 (1971) 224-242. D. E. Knuth, *The Art of Computer
Programming*, vol. 2, 4.2.2 (two-sum). Y. Hida, X. S. Li and D. H. Bailey,
"Library for double-double and quad-double arithmetic" (2007).
"""

from __future__ import annotations

import numpy as np

from ..util.jit import jitable

__all__ = [
    "SPLITTER",
    "two_sum",
    "quick_two_sum",
    "split",
    "two_prod",
    "dd_add",
    "dd_mul",
    "dd_mul_d",
    "dd_div",
    "dd_sqrt",
    "sum_of_squares",
]

#: Dekker's splitter 2**27 + 1
SPLITTER = 134217729.0


@jitable
def two_sum(a, b):
    """Error-free ``a + b = s + e`` (Knuth)."""
    s = a + b
    bb = s - a
    e = (a - (s - bb)) + (b - bb)
    return s, e


@jitable
def quick_two_sum(a, b):
    """Error-free ``a + b = s + e`` assuming ``|a| >= |b|``."""
    s = a + b
    e = b - (s - a)
    return s, e


@jitable
def split(a):
    """``a = hi + lo`` with 26-bit halves (Dekker's splitting)."""
    t = 134217729.0 * a
    hi = t - (t - a)
    return hi, a - hi


@jitable
def two_prod(a, b):
    """Error-free ``a * b = p + e`` (no overflow assumed)."""
    p = a * b
    ah, al = split(a)
    bh, bl = split(b)
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


@jitable
def dd_add(ah, al, bh, bl):
    """Sum of two double-doubles."""
    s, e = two_sum(ah, bh)
    t, f = two_sum(al, bl)
    e = e + t
    s, e = quick_two_sum(s, e)
    e = e + f
    return quick_two_sum(s, e)


@jitable
def dd_mul(ah, al, bh, bl):
    """Product of two double-doubles."""
    p, e = two_prod(ah, bh)
    e = e + (ah * bl + al * bh)
    return quick_two_sum(p, e)


@jitable
def dd_mul_d(ah, al, b):
    """Product of a double-double and a float."""
    p, e = two_prod(ah, b)
    e = e + al * b
    return quick_two_sum(p, e)


@jitable
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


def dd_sqrt(ah, al):
    """Square root of a non-negative double-double (0 -> 0), elementwise on arrays."""
    x = np.sqrt(ah)
    safe = np.where(x > 0.0, x, 1.0)
    p, e = two_prod(x, x)
    corr = ((ah - p) - e + al) / (2.0 * safe)
    corr = np.where(x > 0.0, corr, 0.0)
    return quick_two_sum(x, corr)


def sum_of_squares(v):
    """``sum(v**2, -1)`` as a double-double ``(hi, lo)``; ``|v|`` must be below about 1e150."""
    hi, lo = two_prod(v[..., 0], v[..., 0])
    for i in range(1, v.shape[-1]):
        p, pe = two_prod(v[..., i], v[..., i])
        hi, se = two_sum(hi, p)
        lo = lo + pe + se
    return two_sum(hi, lo)
