"""Whether the numba-compiled kernels are used, and their compilation on first use (private).

numba is the optional ``fast`` extra. Every compiled kernel has a pure
numpy/Python twin that gives the same results; setting the environment
variable ``EULERPOISSON_NO_NUMBA=1`` before importing eulerpoisson selects
the twins (tests use it to check that both paths agree).

Nothing here imports numba when eulerpoisson is imported (numba and its
first use of a cached kernel cost about half a second, more than a small
problem takes in NumPy). :data:`USE_NUMBA` is decided from whether numba
*can* be imported (:func:`importlib.util.find_spec`); the modules that
compile kernels wrap them with :func:`lazy_njit` (and :func:`lazy_intrinsic`)
instead of ``numba.njit``, which record the function and its options; the
first call of any of them (:func:`activate`) imports numba, registers the
:func:`jitable` helpers, creates every recorded dispatcher with exactly the
options given (``cache=True`` included: the same compiled code as an eager
``njit``, loaded from the same on-disk cache) and puts the dispatchers in
place of the lazy objects in the namespaces of the package's modules, so
that compiled callers see real dispatchers (numba's ``inline="always"``
needs them) and later calls cost nothing extra. Kernels of modules imported
after that are plain ``numba.njit`` dispatchers from the start.
"""

from __future__ import annotations

import contextlib
import contextvars
import dis
import functools
import importlib.util
import os
import sys
import threading
import types
from collections.abc import Iterator

import numpy as np

from .env import env_value

__all__ = [
    "USE_NUMBA",
    "NUMPY_BELOW",
    "ENV_NUMPY_BELOW",
    "numpy_below",
    "use_compiled",
    "whole_run",
    "run_shape",
    "numba_wanted",
    "numba_active",
    "python_twins",
    "activate",
    "lazy_njit",
    "lazy_intrinsic",
    "lazy_module",
    "jitable",
    "stack_buffer",
    "kernel_array",
]


def numba_wanted() -> bool:
    """True when numba is importable and ``EULERPOISSON_NO_NUMBA`` is not ``"1"`` (numba is not imported)."""
    if os.environ.get("EULERPOISSON_NO_NUMBA", "") == "1":
        return False
    if "numba" in sys.modules:
        return True
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):  # pragma: no cover - a broken installation
        return False


#: decided once, when eulerpoisson is imported (without importing numba)
USE_NUMBA = numba_wanted()

#: seconds of NumPy work (a method's estimate) below which a problem is solved without numba: importing
#: numba and loading a cached kernel take about 0.5 s, more than NumPy needs for a small problem
NUMPY_BELOW = 0.05
#: environment variable replacing :data:`NUMPY_BELOW` (seconds >= 0; 0: the compiled kernels always)
ENV_NUMPY_BELOW = "EULERPOISSON_NUMPY_BELOW"


def numpy_below() -> float:
    """The threshold in use: ``$EULERPOISSON_NUMPY_BELOW`` when set, else :data:`NUMPY_BELOW`.

    Raises
    ------
    InvalidInputError
        The environment variable is not a number >= 0.
    """
    env = (env_value(ENV_NUMPY_BELOW) or "").strip()
    if not env:
        return NUMPY_BELOW
    try:
        value = float(env)
    except ValueError:
        value = -1.0
    if not value >= 0.0:
        from ..errors import InvalidInputError

        raise InvalidInputError(
            f"the environment variable {ENV_NUMPY_BELOW} must be a number of seconds >= 0 "
            f"(0: always the compiled kernels), or unset; got {env!r}"
        )
    return value


#: the shape (bodies, output times) of the whole run that the problems being solved are parts of (0: unknown)
_RUN: contextvars.ContextVar[tuple[int, int]] = contextvars.ContextVar("eulerpoisson_whole_run", default=(0, 0))


class whole_run:
    """Within it, every problem solved is a part of one run of ``n_bodies`` bodies at ``n_times`` output times.

    A context manager (``with whole_run(B, T): ...``). The methods choose
    between their compiled kernels and NumPy from the size of the whole run
    (:func:`run_shape`), not of the part: a run solved in chunks (the
    command line's and :func:`~eulerpoisson.io.stream.solve_to_file`'s
    chunks of output times, a sweep's chunks of points) takes one path in
    every chunk, which gives the numbers of one call and pays numba's start
    once for a large run. 0: the part's own size. (A class rather than a
    generator: it is entered on every call of ``solve``.)
    """

    __slots__ = ("_shape", "_token")

    def __init__(self, n_bodies: int = 0, n_times: int = 0) -> None:
        self._shape = (int(n_bodies), int(n_times))

    def __enter__(self) -> None:
        self._token = _RUN.set(self._shape)

    def __exit__(self, *exc: object) -> None:
        _RUN.reset(self._token)


def run_shape(n_bodies: int, n_times: int) -> tuple[int, int]:
    """``(bodies, output times)`` of the run that a problem of this size is part of (see :func:`whole_run`)."""
    b, t = _RUN.get()
    return max(int(n_bodies), b), max(int(n_times), t)


def use_compiled(numpy_seconds: float) -> bool:
    """Whether a problem that NumPy would solve in about ``numpy_seconds`` takes the compiled kernels.

    True when numba is in use (:data:`USE_NUMBA`) and the estimate is at
    least :func:`numpy_below` (0.05 s: about 2*10^4 evaluations of the
    closed form); below, the NumPy twin runs and numba is not even imported.
    A pure function of the problem: the same problem takes the same path in
    every process, whatever ran before. A program that solves many small
    problems in one long-lived process (where numba's start-up is paid once)
    is faster with ``EULERPOISSON_NUMPY_BELOW=0`` (the benchmarks set it):
    one evaluation of the closed form costs about 2 ms in NumPy, tens of
    microseconds compiled.
    """
    below = numpy_below()  # (a bad environment variable is an error with or without numba)
    return USE_NUMBA and not numpy_seconds < below


# activation: numba imported, the jitable helpers registered, the lazy dispatchers made
_LOCK = threading.RLock()
_ACTIVE = False
_PENDING_JITABLE: list = []  # (function, options) waiting for register_jitable
_LAZY: list = []  # every lazy object made before activation


#: within :func:`python_twins`: the lazy kernels run their plain-Python twins instead of activating numba
_TWINS: contextvars.ContextVar[bool] = contextvars.ContextVar("eulerpoisson_python_twins", default=False)


@contextlib.contextmanager
def python_twins() -> Iterator[bool]:
    """Within it, a kernel not compiled yet runs as plain Python, and numba is neither imported nor activated.

    For problems too small to pay numba's start (:func:`use_compiled`):
    each :class:`LazyDispatcher` called from Python runs its plain-Python
    twin (its own function, or the twin given to :func:`lazy_njit` where
    the compiled version is written differently), each
    :class:`LazyIntrinsic` its ``python`` twin. The twins perform the same
    floating-point operations with the same C-library functions, so the
    numbers are those of the compiled kernels, bit for bit (tested). Once
    numba is active in the process (a larger problem activated it) the
    compiled kernels run instead: the same numbers, faster.

    Yields
    ------
    bool
        Whether the twins run (False: numba is active, the compiled kernels run).
    """
    token = _TWINS.set(True)
    try:
        yield not _ACTIVE
    finally:
        _TWINS.reset(token)


def numba_active() -> bool:
    """Whether numba has been imported and the kernels made (:func:`activate` ran) in this process."""
    return _ACTIVE


def activate() -> None:
    """Import numba and make every lazily wrapped kernel (once per process; thread-safe).

    Registers the :func:`jitable` helpers, creates the dispatchers and
    intrinsics recorded by :func:`lazy_njit` and :func:`lazy_intrinsic`, and
    replaces the lazy objects by them in the namespaces of the loaded
    ``eulerpoisson`` modules. Nothing is compiled here: a dispatcher
    compiles (or loads from its cache) on its first call, as with ``njit``.

    Raises
    ------
    RuntimeError
        numba is not in use (:data:`USE_NUMBA` false).
    ImportError
        numba is installed but cannot be imported (the message says how to go on without it).
    """
    global _ACTIVE
    if _ACTIVE:
        return
    if not USE_NUMBA:
        raise RuntimeError("numba is not in use (not installed, or EULERPOISSON_NO_NUMBA=1): no compiled kernel")
    with _LOCK:
        if _ACTIVE:
            return
        try:
            import numba  # noqa: F401
            from numba.extending import register_jitable
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise ImportError(
                f"numba is installed but cannot be imported ({exc}); reinstall it, or set "
                f"EULERPOISSON_NO_NUMBA=1 to use the NumPy implementations"
            ) from exc
        for f, options in _PENDING_JITABLE:
            if options:
                register_jitable(**options)(f)
            else:
                register_jitable(f)
        _PENDING_JITABLE.clear()
        for lazy in _LAZY:
            lazy._real = lazy._make()
        done = {id(lazy): lazy._real for lazy in _LAZY}
        for name, module in list(sys.modules.items()):
            if module is None or not (name == "eulerpoisson" or name.startswith("eulerpoisson.")):
                continue
            namespace = getattr(module, "__dict__", None)
            if not namespace:
                continue
            for key, val in list(namespace.items()):
                if isinstance(val, _Lazy) and id(val) in done:
                    namespace[key] = done[id(val)]
        _ACTIVE = True


class _Lazy:
    """A numba object (dispatcher or intrinsic) made on first use: see :func:`activate`."""

    _real = None

    def _make(self):  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def real(self):
        """The numba object (activates numba on first use)."""
        if not _ACTIVE:  # (not ``_real``: it is set before the namespaces are updated, which compiling needs)
            activate()
        return self._real

    @property
    def _numba_type_(self):
        # how numba types this object where a compiled caller still refers to it (activation replaces
        # the module-level references by the real object; this covers any other)
        real = self.real
        ty = getattr(real, "_numba_type_", None)
        if ty is not None:
            return ty
        from numba.core.registry import cpu_target

        ctx = cpu_target.typing_context
        ctx.refresh()  # (an intrinsic is found in the registries once they are loaded)
        return ctx.resolve_value_type(real)


class LazyDispatcher(_Lazy):
    """``numba.njit(**options)(py_func)``, made when first called (or when numba is first used).

    Calling it calls the dispatcher; other attributes (``signatures``,
    ``py_func``...) are the dispatcher's.
    """

    def __init__(self, py_func, options, python=None):
        self.py_func = py_func
        self.options = dict(options)
        #: the plain-Python twin run within :func:`python_twins` (default: ``py_func`` itself)
        self.python = py_func if python is None else python
        functools.update_wrapper(self, py_func)

    def _make(self):
        from numba import njit

        return njit(**self.options)(self.py_func)

    def __call__(self, *args, **kwargs):
        if not _ACTIVE and _TWINS.get():
            twin = self._twin
            if twin is None:
                twin = self._twin = _direct_twin(self.python)
            return twin(*args, **kwargs)
        return self.real(*args, **kwargs)

    #: :attr:`python` with its calls of other kernels made directly (:func:`_direct_twin`), made on first use
    _twin = None

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.real, name)

    def __repr__(self):
        state = "made" if self._real is not None else "not made yet"
        return f"<lazy numba dispatcher of {self.py_func.__qualname__} ({state})>"


class LazyIntrinsic(_Lazy):
    """``numba.extending.intrinsic(defn)``, made when numba is first used.

    Called from Python it runs ``python`` (its plain twin) if given, else
    raises as a numba intrinsic does.
    """

    def __init__(self, defn, python=None):
        self.defn = defn
        self.python = python
        functools.update_wrapper(self, defn)

    def _make(self):
        from numba.extending import intrinsic

        return intrinsic(self.defn)

    def __call__(self, *args, **kwargs):
        if self.python is not None:
            return self.python(*args, **kwargs)
        raise NotImplementedError(f"{self.defn.__name__} is an intrinsic of compiled code, not usable in Python")

    def __repr__(self):
        return f"<lazy numba intrinsic {self.defn.__qualname__}>"


# the plain-Python twins, calling each other directly -------------------------------------------------------
#: by id of a module's namespace: (the namespace, its copy in which the lazy kernels are their direct twins)
_TWIN_NAMESPACES: dict[int, tuple[dict, dict]] = {}
#: by id of a function: (the function, its direct twin)
_TWIN_FUNCTIONS: dict[int, tuple[types.FunctionType, types.FunctionType]] = {}
_GLOBAL_WRITES = frozenset({"STORE_GLOBAL", "DELETE_GLOBAL"})


def _direct_twin(f):
    """``f`` (a kernel's plain-Python twin) as a function whose calls of other kernels are direct.

    Within :func:`python_twins` every call of a lazy kernel from a twin went
    through :meth:`LazyDispatcher.__call__` (a Python-level call and a context
    lookup, about a microsecond: some hundreds of them per evaluation of the
    closed form, most of its time). The direct twin is ``f``'s code with a
    copy of its module's namespace in which the lazy kernels are their direct
    twins and the lazy intrinsics their Python twins, and the package's plain
    functions (the jitable helpers) direct twins too: the same operations in
    the same order, so the same numbers, about 1.5 times faster. The copy is
    made once, when the twins first run (a kernel module's globals are its
    constants); a function of a module without kernels (it reads that
    module's live globals), one that writes a module global, or one that is
    not a plain function of the package, is left as it is.
    """
    if type(f) is not types.FunctionType or not f.__module__.startswith("eulerpoisson"):
        return f
    entry = _TWIN_FUNCTIONS.get(id(f))
    if entry is not None:
        return entry[1]
    if not any(isinstance(v, _Lazy) for v in f.__globals__.values()) or any(
        ins.opname in _GLOBAL_WRITES for ins in dis.get_instructions(f)
    ):
        twin = f  # a module without kernels (its functions read its live globals), or a global written
    else:
        twin = types.FunctionType(f.__code__, _twin_namespace(f.__globals__), f.__name__, f.__defaults__, f.__closure__)
        twin.__kwdefaults__ = f.__kwdefaults__
        twin.__qualname__ = f.__qualname__
    _TWIN_FUNCTIONS[id(f)] = (f, twin)
    return twin


def _twin_namespace(namespace: dict) -> dict:
    """The copy of a module's namespace that direct twins run in (see :func:`_direct_twin`)."""
    entry = _TWIN_NAMESPACES.get(id(namespace))
    if entry is not None:
        return entry[1]
    copy = dict(namespace)
    _TWIN_NAMESPACES[id(namespace)] = (namespace, copy)  # (before the values: kernels of one module call each other)
    for key, value in namespace.items():
        if isinstance(value, LazyDispatcher):
            copy[key] = _direct_twin(value.python)
        elif isinstance(value, LazyIntrinsic):
            if value.python is not None:
                copy[key] = value.python
        elif type(value) is types.FunctionType and value.__module__.startswith("eulerpoisson"):
            copy[key] = _direct_twin(value)
    return copy


def lazy_njit(func=None, /, *, python=None, **options):
    """``numba.njit`` made on first use: ``lazy_njit(**options)(f)`` or ``lazy_njit(f)``.

    Returns a :class:`LazyDispatcher` before numba is used in this process
    (see :func:`activate`), the ``numba.njit`` dispatcher itself after.
    The options are those of ``numba.njit`` (``cache=True``, ``nogil``,
    ``fastmath``, ``inline``...), passed unchanged. ``python``: the
    plain-Python twin that :func:`python_twins` runs, where ``f`` itself
    is written for the compiler only (intrinsics); default ``f``.
    """

    def wrap(f):
        with _LOCK:
            if _ACTIVE:
                from numba import njit

                return njit(**options)(f)
            lazy = LazyDispatcher(f, options, python)
            _LAZY.append(lazy)
            return lazy

    if func is not None:
        return wrap(func)
    return wrap


def lazy_intrinsic(defn=None, /, *, python=None):
    """``numba.extending.intrinsic`` made on first use (see :func:`lazy_njit`); decorator.

    ``python``: the plain-Python twin run when the object is called from
    Python before numba is used.
    """

    def wrap(d):
        with _LOCK:
            if _ACTIVE:
                from numba.extending import intrinsic

                return intrinsic(d)
            lazy = LazyIntrinsic(d, python)
            _LAZY.append(lazy)
            return lazy

    if defn is not None:
        return wrap(defn)
    return wrap


class lazy_module:
    """A module imported on first attribute access (``lazy_module("numba.core.types").float64``)."""

    def __init__(self, name: str):
        self._name = name
        self._module: object | None = None

    def __getattr__(self, attr):
        if attr.startswith("__"):
            raise AttributeError(attr)
        module = self._module
        if module is None:
            import importlib

            module = self._module = importlib.import_module(self._name)
        return getattr(module, attr)

    def __repr__(self):
        return f"<lazy module {self._name}>"


def _python_stack_buffer(size):
    """Pure-Python stand-in of :func:`stack_buffer`: a zero-filled float64 array."""
    import numpy as np

    return np.zeros(size)


def _stack_buffer_intrinsic(typingctx, size):
    """A numba intrinsic ``stack_buffer(size)``: a float64 array on the caller's stack.

    ``size`` must be a compile-time constant (a module-level int). The array
    lives in the entry block of the function that calls it (``alloca``), so
    LLVM knows that it aliases neither the arguments nor any heap array: the
    lane loops that write into it and read the kernel's arrays vectorize
    without run-time overlap checks. The memory is not initialized.
    (The typing function of the intrinsic, which :func:`lazy_intrinsic` makes
    when numba is first used.)
    """
    from numba import types
    from numba.core import cgutils
    from numba.np.arrayobj import make_array, populate_array

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


#: ``stack_buffer(size)``: scratch float64 array of compile-time size, on the
#: stack in compiled kernels, on the heap (zero-filled) in their Python twins
stack_buffer = (
    lazy_intrinsic(_stack_buffer_intrinsic, python=_python_stack_buffer) if USE_NUMBA else _python_stack_buffer
)


def jitable(f):
    """Decorator for small helpers shared by numpy code and compiled kernels.

    The function stays a plain Python function (it works on arrays), and
    compiled kernels that call it compile it inline: it is registered with
    ``numba.extending.register_jitable`` when numba is first used
    (:func:`activate`; at once if it already is), not at import.
    """
    if USE_NUMBA:
        with _LOCK:
            if _ACTIVE:
                from numba.extending import register_jitable

                register_jitable(f)
            else:
                _PENDING_JITABLE.append((f, {}))
    return f


def kernel_array(x):
    """``x`` as a C-contiguous, aligned, writeable float64 ndarray (a copy only where it is not one already).

    numba compiles one specialization per array type, and a read-only array
    (``np.broadcast_to``, ``flags.writeable = False``, a NetCDF read) or a
    strided one is a type of its own: every array passed to a compiled
    kernel goes through here, so that each kernel has one signature (the one
    ``eulerpoisson warmup`` compiles). The common case (already such an
    array) costs two attribute reads.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.zeros(3)
    >>> kernel_array(a) is a, kernel_array(np.broadcast_to(a, (2, 3))).flags.writeable
    (True, True)
    """
    if type(x) is np.ndarray and x.dtype == np.float64:
        f = x.flags
        if f.c_contiguous and f.aligned:
            return x if f.writeable else x.copy()
    return np.require(x, dtype=np.float64, requirements=("C", "A", "W", "E"))
