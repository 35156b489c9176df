"""Derivatives of the JAX closed form against two independent truths (issue 24).

1. The fit's variational equations (``eulerpoisson.estimation.variational.propagate``: a Taylor
   integrator of the motion and its sensitivities, which shares no code with the closed form):
   ``jax.jacfwd`` of the attitude and rates with respect to the initial rate and the inertia
   tensor agree to 1e-9 relative, on the standard cases and 1e-6 from the separatrix, both sides.
2. 30-digit mpmath central differences of an independent Taylor integrator
   (``tests/_torque_reference.py``, no eulerpoisson code), step 1e-10: the same columns, and the
   derivatives with respect to the initial attitude and the time.

The attitude sensitivity is compared as the body-frame vector ``eta`` defined by
``R(p + dp) = R(p) (1 + [eta dp]x)``, i.e. ``eta = 2 vec(conj(q) (x) dq/dp)``.
"""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")
mpmath = pytest.importorskip("mpmath")

import _jax_programs as programs  # noqa: E402  (tests/: the compiled programs the JAX test files share)
import eulerpoisson as ep  # noqa: E402
from _torque_reference import reference_motion_mp  # noqa: E402
from eulerpoisson.estimation.variational import propagate  # noqa: E402
from eulerpoisson.oracle import reference_cases  # noqa: E402

IDENT = np.array([1.0, 0.0, 0.0, 0.0])


def _qmul(p, q):
    pw, pv = p[..., :1], p[..., 1:]
    qw, qv = q[..., :1], q[..., 1:]
    w = pw * qw - np.sum(pv * qv, axis=-1, keepdims=True)
    v = pw * qv + qw * pv + np.cross(pv, qv)
    return np.concatenate([w, v], axis=-1)


def _conj(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def _eta(q, dq):
    """Body-frame rotation sensitivity from a quaternion derivative: 2 vec(conj(q) dq)."""
    return 2.0 * _qmul(_conj(q), dq)[..., 1:]


def _sym(i, j):
    e = np.zeros((3, 3))
    e[i, j] = e[j, i] = 1.0
    return e


#: inertia directions: the six independent entries of the symmetric tensor
DIRECTIONS = np.array([_sym(0, 0), _sym(1, 1), _sym(2, 2), _sym(0, 1), _sym(0, 2), _sym(1, 2)])


def _jax_columns(inertia, omega0, t):
    """(q, w, eta, domega): eta and domega of shapes (T, P, 3), the 3 omega0 columns, then the inertia
    directions (the 6 of DIRECTIONS for a tensor, the 3 diagonal ones for moments).

    Each column is one ``jax.jvp`` (``jax.jacfwd`` is jvp over the basis) of the session's one forward
    program (tests/_jax_programs.py), at the initial attitude IDENT.
    """
    inertia = np.asarray(inertia, dtype=float)
    moments = inertia.shape == (3,)
    zero_t = np.zeros(len(t))
    tangents = [(np.zeros_like(inertia), np.eye(3)[j]) for j in range(3)]
    tangents += [(np.eye(3)[j], np.zeros(3)) for j in range(3)] if moments else [(D, np.zeros(3)) for D in DIRECTIONS]
    etas, dws = [], []
    for d_inertia, d_omega in tangents:
        q, w, dq, dw = programs.jvp(inertia, IDENT, omega0, t, d_inertia, np.zeros(4), d_omega, zero_t)
        etas.append(_eta(q, dq))
        dws.append(dw)
    return q, w, np.stack(etas, axis=1), np.stack(dws, axis=1)


def _assert_columns(actual, expected, rtol, what):
    """Each column (parameter) agrees relative to that column's largest entry over the times."""
    for j in range(expected.shape[1]):
        scale = max(np.max(np.abs(expected[:, j])), 1e-300)
        err = np.max(np.abs(actual[:, j] - expected[:, j])) / scale
        assert err <= rtol, f"{what}, column {j}: relative error {err:.3e} > {rtol:.1e}"


def _near_separatrix(side):
    """A body 1e-6 (relative, in 2E I2 - |M|^2) from the separatrix, on one side."""
    I = np.array([1.0, 2.0, 3.0])
    w1, w3 = 1.0, None
    # M^2 - 2 E I2 = M1^2 (I1 - I2)/I1 + M3^2 (I3 - I2)/I3 = 0 on the separatrix (M2 free)
    M1 = I[0] * w1
    M3 = np.sqrt(M1**2 * (I[1] - I[0]) / I[0] * I[2] / (I[2] - I[1])) * (1.0 + side * 1e-6)
    w3 = M3 / I[2]
    return I, np.array([w1, 0.2, w3])


#: where the derivative is that of a special formula, not of the motion (documented in
#: ``eulerpoisson.jax.exact.exact_motion``): exact relative equilibria (M along a principal axis: every
#: axis of a sphere) and data exactly on the separatrix
SPECIAL = {"sphere", "principal_axis_1", "principal_axis_2", "principal_axis_3", "tennis_racket_separatrix"}


def _standard():
    out = []
    for name, case in reference_cases().items():
        if name in SPECIAL:
            continue
        # moments stay moments (a symmetric top has no unique principal axes as a tensor)
        out.append(pytest.param(case.inertia_array, np.asarray(case.omega0, float), min(case.t_end, 20.0), id=name))
    for side, label in ((-1, "inside"), (1, "outside")):
        I, w0 = _near_separatrix(side)
        out.append(pytest.param(np.diag(I), w0, 20.0, id=f"separatrix-1e-6-{label}"))
    return out


@pytest.mark.parametrize(("inertia", "omega0", "t_end"), _standard())
def test_jacfwd_matches_the_variational_equations(inertia, omega0, t_end):
    t = np.linspace(0.0, t_end, 7)
    tensor = np.diag(inertia) if inertia.shape == (3,) else inertia
    directions = DIRECTIONS[:3] if inertia.shape == (3,) else DIRECTIONS
    ref = propagate(tensor, omega0, directions, t)
    q, w, eta, dw = _jax_columns(inertia, omega0, t)
    # the motion itself against the NumPy closed form (the Taylor reference is less accurate near the separatrix)
    exact = ep.solve(inertia, t, omega0=omega0, method="exact")
    dot = np.abs(np.sum(q * exact.quaternion, axis=-1))
    assert np.max(2 * np.arccos(np.clip(dot, -1, 1))) < 1e-7  # arccos resolution; tests/test_jax_exact.py is sharp
    np.testing.assert_allclose(w, exact.omega, rtol=0, atol=1e-13 * np.max(np.abs(exact.omega)))
    _assert_columns(eta, ref.eta, 1e-9, "attitude sensitivity")
    _assert_columns(dw, ref.domega, 1e-9, "rate sensitivity")


def _mp_central(inertia, q0, omega0, t, which, index):
    """Central difference of the 30-digit reference in one input coordinate; returns (dq, dw) arrays."""
    with mpmath.workdps(40):
        return _mp_central_at_40_digits(inertia, q0, omega0, t, which, index, mpmath.mpf("1e-10"))


def _mp_central_at_40_digits(inertia, q0, omega0, t, which, index, h):
    I = [[mpmath.mpf(float(x)) for x in row] for row in np.asarray(inertia)]
    q = [mpmath.mpf(float(x)) for x in q0]
    w = [mpmath.mpf(float(x)) for x in omega0]

    def run(sign):
        II = [row[:] for row in I]
        qq, ww = q[:], w[:]
        if which == "omega0":
            ww[index] += sign * h
        elif which == "quaternion0":
            qq[index] += sign * h
        else:
            i, j = index
            II[i][j] += sign * h
            if i != j:
                II[j][i] += sign * h
        return reference_motion_mp(II, qq, ww, t, dps=30)

    qp, wp = run(1)
    qm, wm = run(-1)
    dq = np.array([[float((a - b) / (2 * h)) for a, b in zip(x, y)] for x, y in zip(qp, qm)])
    dw = np.array([[float((a - b) / (2 * h)) for a, b in zip(x, y)] for x, y in zip(wp, wm)])
    return dq, dw


MP_CASES = [
    pytest.param(np.array([[1.0, 0.1, 0.0], [0.1, 2.0, 0.05], [0.0, 0.05, 3.0]]), (1.0, 0.3, -0.4), id="full-tensor"),
    pytest.param(np.diag(_near_separatrix(1)[0]), tuple(_near_separatrix(1)[1]), id="separatrix-1e-6-outside"),
    pytest.param(np.diag(_near_separatrix(-1)[0]), tuple(_near_separatrix(-1)[1]), id="separatrix-1e-6-inside"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("inertia", "omega0"), MP_CASES)
def test_jacfwd_matches_30_digit_central_differences(inertia, omega0):
    q0 = np.array([0.9, 0.1, -0.3, 0.2])
    q0 = q0 / np.linalg.norm(q0)
    t = np.array([0.5, 4.0])
    coords = [("omega0", k) for k in range(3)] + [("quaternion0", k) for k in range(4)]
    coords += [("inertia", (0, 0)), ("inertia", (1, 2))]
    # jax.jacfwd, one column (a jvp of the session's one forward program) per input coordinate
    zeros = (np.zeros((3, 3)), np.zeros(4), np.zeros(3), np.zeros(t.size))
    jq, jw = [], []
    for k, shape in enumerate(((3, 3), (4,), (3,))):
        cq, cw = [], []
        for flat in range(int(np.prod(shape))):
            tans = list(zeros)
            tans[k] = np.zeros(shape)
            tans[k][np.unravel_index(flat, shape)] = 1.0
            _, _, dq, dw = programs.jvp(inertia, q0, omega0, t, *tans)
            cq.append(dq)
            cw.append(dw)
        jq.append(np.moveaxis(np.stack(cq), 0, -1).reshape(t.shape + (4,) + shape))
        jw.append(np.moveaxis(np.stack(cw), 0, -1).reshape(t.shape + (3,) + shape))
    # d/dt: the equations of motion at the same points, from the reference at the same times (the tangent
    # of t all ones: each output depends on its own time only, the diagonal of jax.jacfwd in t)
    _, _, dq_dt, dw_dt = programs.jvp(inertia, q0, omega0, t, *zeros[:3], np.ones(t.size))
    for which, index in coords:
        dq, dw = _mp_central(inertia, q0, omega0, t, which, index)
        if which == "omega0":
            aq, aw = jq[2][..., index], jw[2][..., index]
        elif which == "quaternion0":
            aq, aw = jq[1][..., index], jw[1][..., index]
        else:
            i, j = index
            # a symmetric perturbation moves both (i, j) and (j, i)
            aq = jq[0][..., i, j] + (jq[0][..., j, i] if i != j else 0.0)
            aw = jw[0][..., i, j] + (jw[0][..., j, i] if i != j else 0.0)
        scale_q = max(np.max(np.abs(dq)), 1e-3)
        scale_w = max(np.max(np.abs(dw)), 1e-3)
        assert np.max(np.abs(aq - dq)) <= 1e-9 * scale_q, (which, index, aq, dq)
        assert np.max(np.abs(aw - dw)) <= 1e-9 * scale_w, (which, index, aw, dw)
    # time derivative: the equations of motion evaluated on the reference state
    qr, wr = reference_motion_mp(np.asarray(inertia), q0, omega0, t, dps=30)
    qr = np.array([[float(x) for x in row] for row in qr])
    wr = np.array([[float(x) for x in row] for row in wr])
    I = np.asarray(inertia)
    q_dot = 0.5 * _qmul(qr, np.concatenate([np.zeros((len(t), 1)), wr], axis=-1))
    w_dot = np.linalg.solve(I, np.cross(wr @ I.T, wr).T).T
    np.testing.assert_allclose(dq_dt, q_dot, atol=1e-12)
    np.testing.assert_allclose(dw_dt, w_dot, atol=1e-12)
