"""Shared pieces of the benchmarks: the reference problem, timing, errors, machine info and the peers.

Everything here is benchmark plumbing; nothing is imported by the package. The peers (scipy's
``solve_ivp`` written out as a user would, heyoka, MuJoCo) are set up on the same ODE as the
package: Euler's equations ``I dOmega/dt = (I Omega) x Omega`` and the quaternion kinematics
``dq/dt = q (x) (0, Omega) / 2`` (paper eqs. 1.4-1.5), body frame, principal axes.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

#: the reference problem of the issue
INERTIA = (1.0, 2.0, 3.0)
OMEGA0 = (1.0, 0.1, 0.5)
Q0 = (1.0, 0.0, 0.0, 0.0)
T_REF = 100.0
EPS = float(np.finfo(float).eps)

SCHEMA_VERSION = 1

#: optional peers that may be measured when they import; ``run.py --peers scipy`` empties it
ALL_OPTIONAL_PEERS = ("heyoka", "mujoco")
OPTIONAL_PEERS = set(ALL_OPTIONAL_PEERS)


# ---------------------------------------------------------------------------
# measurement helpers
# ---------------------------------------------------------------------------
def best_time(fn, *, repeats: int = 5, budget: float = 2.0, warmup: bool = True):
    """Best wall time of ``fn()`` over several calls (``time.perf_counter``).

    One untimed warm-up call (compilation, caches) unless ``warmup`` is False, then up to
    ``repeats`` timed calls, fewer when they would exceed ``budget`` seconds in total (the
    number is set from the first timed call, so a compiling warm-up does not cut it down;
    always at least one). Returns ``(best_seconds, result_of_last_call, number_of_timed_calls)``.
    """
    if warmup:
        fn()
    t0 = time.perf_counter()
    out = fn()
    times = [time.perf_counter() - t0]
    more = repeats - 1
    if times[0] > 0:
        more = max(0, min(repeats - 1, int(budget / times[0]) - 1))
    for _ in range(more):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out, len(times)


def attitude_error(q, q_ref) -> float:
    """Angle (rad) of the rotation between two attitudes given as quaternions; sign-insensitive.

    ``2 atan2(|vec(q_ref^* q)|, |scal(q_ref^* q)|)``, accurate for tiny angles (no arccos).
    Inputs may be float64 or long double; the result is a float.
    """
    a = np.asarray(q_ref, dtype=np.longdouble).reshape(4)
    b = np.asarray(q, dtype=np.longdouble).reshape(4)
    w = np.sum(a * b)
    v = a[0] * b[1:] - b[0] * a[1:] - np.cross(a[1:], b[1:])
    return float(2 * np.arctan2(np.sqrt(np.sum(v * v)), abs(w)))


def energy(omega, inertia=INERTIA):
    """Kinetic energy 1/2 sum I_i Omega_i^2 (principal frame), (..., 3) -> (...)."""
    om = np.asarray(omega, dtype=float)
    return 0.5 * np.sum(np.asarray(inertia) * om * om, axis=-1)


def relative_energy_error(omega, omega0=OMEGA0, inertia=INERTIA) -> float:
    e0 = energy(omega0, inertia)
    return float(abs(energy(omega, inertia) - e0) / e0)


# ---------------------------------------------------------------------------
# machine
# ---------------------------------------------------------------------------
def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _version(dist: str):
    """Installed version of a distribution (without importing it), or None."""
    from importlib import metadata

    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


def machine_info() -> dict:
    """CPU model, core counts and the versions of Python and of the measured libraries."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        usable = os.cpu_count()
    return {
        "cpu": _cpu_model(),
        "logical_cpus": os.cpu_count(),
        "usable_cpus": usable,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": _version("numpy"),
        "scipy": _version("scipy"),
        "numba": _version("numba"),
        "eulerpoisson": _version("eulerpoisson"),
        "heyoka": _version("heyoka"),
        "mujoco": _version("mujoco"),
        "threads": "one thread per measurement (OMP/MKL/OPENBLAS/NUMBA threads = 1)",
        "load_average_at_start": load_average(),
    }


def load_average():
    """1-minute load average (other processes compete for the cores when it exceeds ~0), or None."""
    try:
        return round(os.getloadavg()[0], 2)
    except (AttributeError, OSError):  # pragma: no cover - non-Unix
        return None


def machine_line(m: dict) -> str:
    return f"{m['cpu']}, {m['usable_cpus']} cores, Python {m['python']}, numpy {m['numpy']}, numba {m['numba']}"


def now_iso() -> str:
    return _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat()


def write_json(path: Path, payload: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as fh:
        json.dump(_jsonable(payload), fh, indent=1, sort_keys=False)
        fh.write("\n")


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating,)):
        return float(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def envelope(name: str, *, quick: bool, command: str, machine: dict, **body) -> dict:
    """Common header of every results file."""
    return {
        "benchmark": name,
        "schema_version": SCHEMA_VERSION,
        "generated": now_iso(),
        "quick": bool(quick),
        "command": command,
        "machine": machine,
        **body,
    }


# ---------------------------------------------------------------------------
# the user's baseline: scipy solve_ivp written directly
# ---------------------------------------------------------------------------
def scipy_rhs(inertia=INERTIA):
    """Right-hand side of (q, Omega) as a user would write it for ``solve_ivp``."""
    I1, I2, I3 = inertia
    a1, a2, a3 = (I2 - I3) / I1, (I3 - I1) / I2, (I1 - I2) / I3

    def f(t, y):
        w, x, yy, z, o1, o2, o3 = y
        return np.array(
            [
                -0.5 * (x * o1 + yy * o2 + z * o3),
                0.5 * (w * o1 + yy * o3 - z * o2),
                0.5 * (w * o2 - x * o3 + z * o1),
                0.5 * (w * o3 + x * o2 - yy * o1),
                a1 * o2 * o3,
                a2 * o3 * o1,
                a3 * o1 * o2,
            ]
        )

    return f


def scipy_solve(t_end: float, method: str, rtol: float, atol: float):
    """``solve_ivp`` from the reference initial state to ``t_end``; returns (q, Omega, nfev)."""
    from scipy.integrate import solve_ivp

    y0 = np.r_[Q0, OMEGA0]
    sol = solve_ivp(scipy_rhs(), (0.0, t_end), y0, method=method, rtol=rtol, atol=atol)
    if sol.status != 0:
        raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
    y = sol.y[:, -1]
    q = y[:4] / np.linalg.norm(y[:4])
    return q, y[4:], int(sol.nfev)


# ---------------------------------------------------------------------------
# heyoka (optional)
# ---------------------------------------------------------------------------
def heyoka_module():
    """The heyoka module, or None when it is not installed (or fails to import) or disabled."""
    if "heyoka" not in OPTIONAL_PEERS:
        return None
    try:
        import heyoka
    except Exception:  # noqa: BLE001
        return None
    return heyoka


def heyoka_system(hy, *, runtime_inertia: bool = False):
    """The ODE for heyoka: 7 state variables (w, x, y, z, O1, O2, O3).

    ``runtime_inertia=False``: the Euler coefficients ``(I2-I3)/I1`` ... are double constants
    (how a user writes it; the fastest form). ``True``: the moments are runtime parameters
    ``par[0..2]`` divided in the integrator's own arithmetic — needed for extended precision,
    where a constant ``-1/3`` would be rounded to double and limit the reference to ~1e-17
    per unit time.
    """
    w, x, y, z, o1, o2, o3 = hy.make_vars("w", "x", "y", "z", "o1", "o2", "o3")
    if runtime_inertia:
        I1, I2, I3 = hy.par[0], hy.par[1], hy.par[2]
        e1 = (I2 - I3) * o2 * o3 / I1
        e2 = (I3 - I1) * o3 * o1 / I2
        e3 = (I1 - I2) * o1 * o2 / I3
    else:
        I1, I2, I3 = INERTIA
        e1 = ((I2 - I3) / I1) * o2 * o3
        e2 = ((I3 - I1) / I2) * o3 * o1
        e3 = ((I1 - I2) / I3) * o1 * o2
    return [
        (w, -0.5 * (x * o1 + y * o2 + z * o3)),
        (x, 0.5 * (w * o1 + y * o3 - z * o2)),
        (y, 0.5 * (w * o2 - x * o3 + z * o1)),
        (z, 0.5 * (w * o3 + x * o2 - y * o1)),
        (o1, e1),
        (o2, e2),
        (o3, e3),
    ]


class HeyokaPeer:
    """heyoka's adaptive Taylor integrator (double precision) on the reference body.

    The integrator is compiled once (LLVM; not timed, like numba's compilation); each timed
    run resets the state to the initial condition and calls ``propagate_until``.
    """

    def __init__(self, hy, tol: float):
        self.hy = hy
        self.ic = np.r_[Q0, OMEGA0]
        self.ta = hy.taylor_adaptive(heyoka_system(hy), self.ic, tol=tol)
        self.order = int(self.ta.order)

    def run(self, t_end: float):
        self.ta.state[:] = self.ic
        self.ta.time = 0.0
        self.ta.propagate_until(float(t_end))
        st = self.ta.state
        q = st[:4] / np.linalg.norm(st[:4])
        return q, st[4:].copy()


def _heyoka_batch(hy, omega0, tol: float):
    """heyoka's batch (SIMD) integrator for the bodies ``omega0`` (B, 3), compiled, and a ``reset(ta, g)``
    that puts the ``g``-th group of ``recommended_simd_size()`` bodies at t = 0 (identity attitude).

    Returns ``(ta, reset, batch_size, groups)``; bodies beyond the last whole group are left out.
    """
    bs = int(hy.recommended_simd_size())
    groups = omega0.shape[0] // bs
    ic = np.zeros((7, bs))
    ic[0] = 1.0
    ic[4:] = omega0[:bs].T
    ta = hy.taylor_adaptive_batch(heyoka_system(hy), ic, tol=tol)

    def reset(tb, g):
        tb.set_time(0.0)
        st = tb.state
        st[:4] = 0.0
        st[0] = 1.0
        st[4:] = omega0[g * bs : (g + 1) * bs].T
        return tb

    return ta, reset, bs, groups


def heyoka_batch_throughput(hy, omega0, t_end: float, *, tol: float = EPS):
    """Body-seconds per second of heyoka's batch (SIMD) mode over the bodies ``omega0`` (B, 3).

    Batches of ``recommended_simd_size()`` bodies; each batch is reset and propagated to
    ``t_end``. Compilation is not timed. Returns (body_seconds_per_second, batch_size, wall).
    """
    ta, reset, bs, groups = _heyoka_batch(hy, omega0, tol)

    def run():
        for g in range(groups):
            reset(ta, g).propagate_until(float(t_end))
        return ta.state.copy()

    wall, _, _ = best_time(run, repeats=3, budget=3.0)
    return groups * bs * t_end / wall, bs, wall, groups * bs


def heyoka_ensemble(hy, omega0, t_end: float, workers: int, *, tol: float = EPS, per_thread: bool = False):
    """A callable running heyoka's batch (SIMD) integrator over the bodies ``omega0`` (B, 3) on ``workers`` threads.

    ``per_thread=False``: heyoka's own ensemble propagation, ``ensemble_propagate_until_batch``
    with ``max_workers=workers`` (one iteration per SIMD group of bodies; heyoka copies the
    integrator for each iteration, as its documentation describes). ``per_thread=True``: what a
    user who knows heyoka well would write instead: one batch integrator per thread, each resetting
    its state and propagating its share of the SIMD groups (no copies). The integrators are
    compiled before the callable is returned (compilation is not timed). Returns
    ``(run, batch_size, bodies)``; ``run()`` returns the final states.
    """
    from concurrent.futures import ThreadPoolExecutor
    from copy import deepcopy

    ta, reset, bs, groups = _heyoka_batch(hy, omega0, tol)
    B = groups * bs

    if not per_thread:

        def run():
            res = hy.ensemble_propagate_until_batch(ta, float(t_end), groups, reset, max_workers=workers)
            return [r[0].state.copy() for r in res]

        return run, bs, B

    tas = [ta] + [deepcopy(ta) for _ in range(workers - 1)]
    shares = np.array_split(np.arange(groups), workers)

    def work(k):
        tb = tas[k]
        out = []
        for g in shares[k]:
            reset(tb, int(g)).propagate_until(float(t_end))
            out.append(tb.state.copy())
        return out

    def run():
        with ThreadPoolExecutor(max_workers=workers) as ex:
            return [s for part in ex.map(work, range(workers)) for s in part]

    return run, bs, B


def heyoka_reference(hy, t_end: float, *, kind: str = "real", prec: int = 113):
    """High-precision reference state at ``t_end`` from heyoka in extended arithmetic.

    ``kind="real"``: multiprecision (``prec`` bits, 113 = IEEE quadruple) when heyoka was built
    with MPFR; ``kind="longdouble"``: 80-bit x87 (64-bit mantissa, eps 1.1e-19).
    Returns (q, omega) as long double arrays and a description, or None when unavailable.
    """
    sysm = heyoka_system(hy, runtime_inertia=True)
    if kind == "real":
        if not hasattr(hy, "real"):
            return None
        try:
            mk = lambda v: hy.real(float(v), prec)  # noqa: E731
            ic = np.array([mk(v) for v in (*Q0, *OMEGA0)])
            pars = np.array([mk(v) for v in INERTIA])
            ta = hy.taylor_adaptive(sysm, ic, fp_type=hy.real, prec=prec, pars=pars)
            ta.propagate_until(hy.real(float(t_end), prec))
        except Exception:  # noqa: BLE001 - a build without MPFR support
            return None
        st = np.array([np.longdouble(str(v)) for v in ta.state])
        desc = f"heyoka {hy.__version__} Taylor integrator in {prec}-bit floating point (tol = 2^-{prec - 1})"
    else:
        ld = np.longdouble
        ic = np.array([*Q0, *OMEGA0], dtype=ld)
        ta = hy.taylor_adaptive(sysm, ic, fp_type=ld, pars=np.array(INERTIA, dtype=ld))
        ta.propagate_until(ld(t_end))
        st = np.array(ta.state, dtype=ld)
        desc = f"heyoka {hy.__version__} Taylor integrator in 80-bit long double (tol = 1.1e-19)"
    q = st[:4] / np.sqrt(np.sum(st[:4] * st[:4]))
    return q, st[4:], desc


def taylor_longdouble_reference(t_end: float):
    """Reference from eulerpoisson's Taylor integrator in numpy long double (tol 2e-19)."""
    from eulerpoisson.solvers.taylor.method import integrate_principal

    ld = np.longdouble
    q, om, _ = integrate_principal(
        np.array(INERTIA, dtype=ld),
        np.array(OMEGA0, dtype=ld),
        np.array([t_end], dtype=ld),
        tol=ld(2e-19),
        backend="numpy",
    )
    return q[0], om[0], "eulerpoisson Taylor integrator in 80-bit long double (tol = 2e-19, numpy backend)"


# ---------------------------------------------------------------------------
# MuJoCo (optional)
# ---------------------------------------------------------------------------
_MJCF = """<mujoco>
  <option gravity="0 0 0" integrator="RK4" timestep="{dt}"/>
  <worldbody>
    <body name="body"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="{I1} {I2} {I3}"/></body>
  </worldbody>
</mujoco>"""


def mujoco_module():
    """The mujoco module, or None when it is not installed (or fails to import) or disabled."""
    if "mujoco" not in OPTIONAL_PEERS:
        return None
    try:
        import mujoco
    except Exception:  # noqa: BLE001
        return None
    return mujoco


class MujocoPeer:
    """MuJoCo's RK4 on one free body with the reference inertia (no gravity, no contacts).

    The free joint's angular velocity ``qvel[3:6]`` is in the body frame and ``qpos[3:7]`` is
    the scalar-first quaternion, the package's conventions. Model compilation is not timed;
    a timed run resets the data and calls ``mj_step(model, data, nstep=n)`` (one C call) with
    ``n = ceil(t_end / dt)`` equal steps of ``t_end / n <= dt``.
    """

    def __init__(self, mj, dt: float):
        self.mj = mj
        self.dt = float(dt)
        xml = _MJCF.format(dt=repr(self.dt), I1=INERTIA[0], I2=INERTIA[1], I3=INERTIA[2])
        self.model = mj.MjModel.from_xml_string(xml)
        self.data = mj.MjData(self.model)

    def run(self, t_end: float):
        mj, m, d = self.mj, self.model, self.data
        # n equal steps <= dt that land exactly on t_end
        n = max(1, int(np.ceil(t_end / self.dt - 1e-9)))
        m.opt.timestep = t_end / n
        mj.mj_resetData(m, d)
        d.qpos[3:7] = Q0
        d.qvel[3:6] = OMEGA0
        mj.mj_step(m, d, nstep=n)
        q = d.qpos[3:7] / np.linalg.norm(d.qpos[3:7])
        return q, d.qvel[3:6].copy(), n


def pin_single_thread() -> None:
    """Ask every threaded library for one thread (before numpy/numba are imported)."""
    for var in (
        "OMP_NUM_THREADS",
        "MKL_NUM_THREADS",
        "OPENBLAS_NUM_THREADS",
        "NUMBA_NUM_THREADS",
        "VECLIB_MAXIMUM_THREADS",
    ):
        os.environ.setdefault(var, "1")


def command_line(argv=None) -> str:
    argv = sys.argv[1:] if argv is None else list(argv)
    return " ".join([".venv/bin/python benchmarks/run.py", *argv]).strip()
