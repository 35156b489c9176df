"""Whether the numba-compiled kernels are used (private).

numba is the optional ``fast`` extra. Every compiled kernel has a pure
numpy/Python twin that gives the same results; setting the environment
variable ``EULERPOISSON_NO_NUMBA=1`` before importing eulerpoisson selects
the twins (tests use it to check that both paths agree).
"""

from __future__ import annotations

import os


def numba_wanted() -> bool:
    """True when numba is importable and ``EULERPOISSON_NO_NUMBA`` is not ``"1"``."""
    if os.environ.get("EULERPOISSON_NO_NUMBA", "") == "1":
        return False
    try:
        import numba  # noqa: F401
    except ImportError:  # pragma: no cover - depends on environment
        return False
    return True


#: decided once, when eulerpoisson is imported
USE_NUMBA = numba_wanted()


def _python_stack_buffer(size):
    """Pure-Python stand-in of :func:`stack_buffer`: a zero-filled float64 array."""
    import numpy as np

    return np.zeros(size)


def _make_stack_buffer():
    """A numba intrinsic ``stack_buffer(size)``: a float64 array on the caller's stack.

    ``size`` must be a compile-time constant (a module-level int). The array
    lives in the entry block of the function that calls it (``alloca``), so
    LLVM knows that it aliases neither the arguments nor any heap array: the
    lane loops that write into it and read the kernel's arrays vectorize
    without run-time overlap checks. The memory is not initialized.
    """
    from numba import types
    from numba.core import cgutils
    from numba.extending import intrinsic
    from numba.np.arrayobj import make_array, populate_array

    @intrinsic
    def stack_buffer(typingctx, size):
        if not isinstance(size, types.IntegerLiteral):
            return None
        n = int(size.literal_value)
        aryty = types.Array(types.float64, 1, "C")

        def codegen(context, builder, signature, args):
            fty = context.get_value_type(types.float64)
            data = cgutils.alloca_once(builder, fty, size=n)
            ary = make_array(aryty)(context, builder)
            intp = context.get_value_type(types.intp)
            populate_array(
                ary,
                data=data,
                shape=[intp(n)],
                strides=[intp(8)],
                itemsize=intp(8),
                meminfo=None,
            )
            return ary._getvalue()

        return aryty(size), codegen

    return stack_buffer


#: ``stack_buffer(size)``: scratch float64 array of compile-time size, on the
#: stack in compiled kernels, on the heap (zero-filled) in their Python twins
stack_buffer = _make_stack_buffer() if USE_NUMBA else _python_stack_buffer


def _identity(f):
    return f


def _make_jitable():
    """``numba.extending.register_jitable`` when numba is used, else the identity."""
    from numba.extending import register_jitable

    return register_jitable


#: decorator for small helpers shared by numpy code and compiled kernels: the
#: function stays a plain Python function (it works on arrays), and compiled
#: kernels that call it compile it inline
jitable = _make_jitable() if USE_NUMBA else _identity
