"""Tests of eulerpoisson.model.body.RigidBody: validation, principal frame, point-mass bodies (paper eq. 1.1-1.3)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from eulerpoisson.errors import InvalidInertiaError, InvalidInputError
from eulerpoisson.model.body import RigidBody

try:  # tests/ as a package or as a plain directory on sys.path
    from . import strategies as S
except ImportError:  # pragma: no cover
    import strategies as S

EPS = np.finfo(float).eps
PROP = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _diag(m):
    return np.asarray(m)[..., :, None] * np.eye(3)


# ---------------------------------------------------------------------------
# construction, principal frame
# ---------------------------------------------------------------------------
def test_principal_moments_input():
    b = RigidBody([1.0, 2.0, 3.0], name="box")
    np.testing.assert_array_equal(b.inertia, np.diag([1.0, 2.0, 3.0]))
    np.testing.assert_array_equal(b.principal_moments, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(b.principal_axes, np.eye(3))
    assert b.batch_shape == () and b.is_diagonal and b.kind == "asymmetric"
    assert b.is_symmetric is False and b.is_sphere is False
    assert repr(b) == "RigidBody('box', principal_moments=[1, 2, 3], kind='asymmetric')"
    # order of the given moments is kept
    np.testing.assert_array_equal(RigidBody([3.0, 1.0, 2.5]).principal_moments, [3.0, 1.0, 2.5])


@PROP
@given(parts=S.inertia_tensors(frame="rotated", return_parts=True))
def test_full_tensor_principal_frame(parts):
    I, m, P0 = parts
    b = RigidBody(I)
    P = b.principal_axes
    assert b.batch_shape == I.shape[:-2]
    # orthonormal, right-handed, diagonalizing, moments ascending and equal to the generating ones
    np.testing.assert_allclose(np.swapaxes(P, -1, -2) @ P, np.broadcast_to(np.eye(3), P.shape), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(P), 1.0, atol=1e-14)
    np.testing.assert_allclose(b.principal_moments, np.sort(m, -1), rtol=1e-13)
    D = np.swapaxes(P, -1, -2) @ b.inertia @ P
    np.testing.assert_allclose(D, _diag(b.principal_moments), atol=1e-13)
    np.testing.assert_allclose(P @ _diag(b.principal_moments) @ np.swapaxes(P, -1, -2), I, atol=1e-13)
    # inverse inertia, eq. 1.24 maps
    np.testing.assert_allclose(b.inertia @ b.inertia_inv, np.broadcast_to(np.eye(3), I.shape), atol=1e-12)
    # to/from principal components
    v = np.ones(I.shape[:-1])
    np.testing.assert_allclose(b.from_principal(b.to_principal(v)), v, atol=1e-14)
    np.testing.assert_allclose(b.to_principal(v), np.einsum("...ji,...j->...i", P, v), atol=1e-15)
    # a rotated tensor is not flagged diagonal, the principal-frame body is
    d = b.in_principal_frame()
    assert d.is_diagonal
    np.testing.assert_allclose(d.principal_moments, b.principal_moments)


@PROP
@given(m=S.principal_moments(), data=st.data())
def test_flags_match_kind(m, data):
    b = RigidBody.from_moments(m)
    s = np.sort(m, -1)
    kind = np.broadcast_to(b.kind, b.batch_shape)
    close01 = np.isclose(s[..., 0], s[..., 1], rtol=1e-12, atol=0)
    close12 = np.isclose(s[..., 1], s[..., 2], rtol=1e-12, atol=0)
    np.testing.assert_array_equal(kind == "sphere", close01 & close12)
    np.testing.assert_array_equal(kind == "oblate", close01 & ~close12)
    np.testing.assert_array_equal(kind == "prolate", close12 & ~close01)
    np.testing.assert_array_equal(np.asarray(b.is_symmetric), close01 | close12)
    np.testing.assert_array_equal(np.asarray(b.is_sphere), close01 & close12)
    planar = np.isclose(s[..., 0] + s[..., 1], s[..., 2], rtol=1e-12, atol=0)
    np.testing.assert_array_equal(np.asarray(b.is_planar), planar)
    # the flags do not depend on the frame
    P = S.random_rotation_matrices(data.draw(S.rngs()), m.shape[:-1])
    br = RigidBody(P @ _diag(m) @ np.swapaxes(P, -1, -2))
    np.testing.assert_array_equal(np.broadcast_to(br.kind, b.batch_shape), kind)
    np.testing.assert_array_equal(np.asarray(br.is_planar), planar)


@pytest.mark.parametrize(
    "moments, kind, planar",
    [
        ([1.0, 2.0, 2.5], "asymmetric", False),
        ([2.0, 2.0, 1.0], "prolate", False),  # rod-like: unique moment smallest
        ([1.0, 1.0, 1.5], "oblate", False),  # disk-like: unique moment largest
        ([1.0, 1.0, 2.0], "oblate", True),  # a flat disk: symmetric and planar
        ([3.0, 3.0, 3.0], "sphere", False),
        ([1.0, 2.0, 3.0], "asymmetric", True),  # a flat plate
        ([1e-9, 1.0, 1.0], "prolate", False),  # a thin rod
    ],
)
def test_degenerate_physical_bodies_accepted_and_flagged(moments, kind, planar):
    b = RigidBody(moments)
    assert b.kind == kind
    assert b.is_planar is planar
    assert b.is_symmetric is (kind != "asymmetric")
    assert b.is_sphere is (kind == "sphere")


def test_moments_versus_tensor_ambiguity():
    # a (3, 3) batch of moment triples is read as one tensor by the constructor...
    m = np.array([[1.0, 2.0, 2.5], [2.0, 2.0, 1.0], [3.0, 3.0, 3.0]])
    with pytest.raises(InvalidInertiaError, match="not symmetric"):
        RigidBody(m)
    # ...and as three bodies by from_moments
    b = RigidBody.from_moments(m)
    assert b.batch_shape == (3,)
    np.testing.assert_array_equal(b.kind, ["asymmetric", "prolate", "sphere"])
    with pytest.raises(InvalidInputError, match=r"moments must have shape \(\.\.\., 3\)"):
        RigidBody.from_moments(np.eye(2))
    with pytest.raises(InvalidInertiaError, match="moments violates the triangle inequality"):
        RigidBody.from_moments([[1.0, 2.0, 2.5], [1.0, 1.0, 3.0]])
    # a batch mixing diagonal and full tensors: diagonal ones keep their order and frame
    I = np.stack([np.diag([3.0, 1.0, 2.5]), [[2.0, 0.5, 0], [0.5, 2.0, 0], [0, 0, 3.0]]])
    bb = RigidBody(I)
    np.testing.assert_array_equal(bb.principal_moments[0], [3.0, 1.0, 2.5])
    np.testing.assert_array_equal(bb.principal_axes[0], np.eye(3))
    np.testing.assert_allclose(bb.principal_moments[1], [1.5, 2.5, 3.0])


def test_batched_bodies():
    m = np.array([[1.0, 2.0, 2.5], [2.0, 2.0, 1.0], [1.0, 1.0, 2.0], [3.0, 3.0, 3.0], [1.0, 2.0, 3.0]])
    b = RigidBody(m)
    assert b.batch_shape == (5,)
    np.testing.assert_array_equal(b.kind, ["asymmetric", "prolate", "oblate", "sphere", "asymmetric"])
    np.testing.assert_array_equal(b.is_planar, [False, False, True, False, True])
    assert repr(b) == "RigidBody(batch_shape=(5,))"
    np.testing.assert_array_equal(b[1].principal_moments, [2.0, 2.0, 1.0])
    assert b[1].kind == "prolate" and b[1:3].batch_shape == (2,)
    # (2, 3) batch of full tensors
    rng = np.random.default_rng(0)
    P = S.random_rotation_matrices(rng, (2, 3))
    I = P @ _diag(np.broadcast_to([1.0, 2.0, 2.5], (2, 3, 3))) @ np.swapaxes(P, -1, -2)
    bb = RigidBody(I)
    assert bb.batch_shape == (2, 3) and bb.kind.shape == (2, 3)
    assert not bb.is_diagonal
    w = rng.standard_normal((2, 3, 3))
    np.testing.assert_allclose(bb.energy(w), 0.5 * np.einsum("...i,...ij,...j->...", w, I, w), rtol=1e-14)
    # one omega broadcast against the batch
    assert bb.energy([1.0, 0.0, 0.0]).shape == (2, 3)
    with pytest.raises(TypeError, match="cannot be indexed"):
        RigidBody([1.0, 2.0, 2.5])[0]


@PROP
@given(I=S.inertia_tensors(), data=st.data())
def test_energy_momentum_identities(I, data):
    b = RigidBody(I)
    w = data.draw(S.angular_velocities(shape=b.batch_shape))
    M = b.angular_momentum(w)
    np.testing.assert_allclose(M, np.einsum("...ij,...j->...i", I, w), rtol=1e-14, atol=1e-300)
    np.testing.assert_allclose(b.angular_velocity(M), w, rtol=1e-10, atol=1e-12 * np.abs(w).max())
    E = b.energy(w)
    # eq. 1.25: E = 1/2 Omega.I.Omega = 1/2 M.I^-1.M, positive
    np.testing.assert_allclose(E, 0.5 * np.einsum("...i,...ij,...j->...", M, b.inertia_inv, M), rtol=1e-10)
    assert np.all(E > 0)
    # frame independence: in the principal frame the energy is sum I_k Omega_k^2 / 2
    wp = b.to_principal(w)
    np.testing.assert_allclose(E, 0.5 * np.sum(b.principal_moments * wp**2, -1), rtol=1e-12)


@PROP
@given(m=S.principal_moments(kind="asymmetric", shape=(5,)), data=st.data())
def test_near_separatrix_strategy(m, data):
    w = data.draw(S.angular_velocities(kind="near_separatrix", moments=m))
    b = RigidBody.from_moments(m)
    M2 = np.sum(b.angular_momentum(w) ** 2, -1)
    D = M2 / (2 * b.energy(w))
    mid = np.sort(m, -1)[..., 1]
    rel = np.abs(D / mid - 1)
    assert np.all(rel < 3e-6) and np.all(rel > 1e-7)


@PROP
@given(I=S.inertia_tensors())
def test_mass_matrix_inverts_eq_1_3(I):
    b = RigidBody(I)
    g = b.mass_matrix
    tr = np.trace(g, axis1=-2, axis2=-1)
    np.testing.assert_allclose(tr[..., None, None] * np.eye(3) - g, I, atol=1e-13)
    # eigenvalues of g are (I_i + I_j - I_k)/2 >= 0: the triangle inequalities
    ev = np.sort(b.principal_moments, -1)
    expected = np.sort(0.5 * (ev.sum(-1, keepdims=True) - 2 * ev), -1)
    np.testing.assert_allclose(np.linalg.eigvalsh(g), expected, atol=1e-13)
    assert np.all(np.linalg.eigvalsh(g) >= -1e-13)


# ---------------------------------------------------------------------------
# from_particles: the system of paper eq. 1.1
# ---------------------------------------------------------------------------
def test_from_particles_rectangle_by_hand():
    # four unit masses at the corners of a 2a x 2b rectangle in the plane z = 5, centred at c
    a, bb = 1.5, 0.5
    c = np.array([10.0, -3.0, 5.0])
    x = c + np.array([[a, bb, 0], [-a, bb, 0], [a, -bb, 0], [-a, -bb, 0]])
    body = RigidBody.from_particles(np.ones(4), x)
    np.testing.assert_allclose(body.center_of_mass, c, rtol=1e-15)
    # I_xx = sum m (y^2 + z^2) = 4 b^2, I_yy = 4 a^2, I_zz = 4 (a^2 + b^2)
    np.testing.assert_allclose(body.inertia, np.diag([4 * bb**2, 4 * a**2, 4 * (a**2 + bb**2)]), atol=1e-13)
    assert body.is_planar and body.kind == "asymmetric"
    np.testing.assert_allclose(body.positions, x - c, atol=1e-14)
    np.testing.assert_allclose(body.masses, np.ones(4))
    # mass matrix g_ij = sum m x_i x_j (eq. 1.3): diag(4a^2, 4b^2, 0)
    np.testing.assert_allclose(body.mass_matrix, np.diag([4 * a**2, 4 * bb**2, 0.0]), atol=1e-13)
    # a square is an oblate symmetric plate
    sq = RigidBody.from_particles(np.ones(4), [[1, 1, 0], [-1, 1, 0], [1, -1, 0], [-1, -1, 0]])
    assert sq.kind == "oblate" and sq.is_planar
    np.testing.assert_allclose(sq.principal_moments, [4.0, 4.0, 8.0])


def test_from_particles_unequal_masses_and_cube():
    # masses 1 and 3 at x = 0 and x = 4, plus mass 2 at (1, 2, 0): COM = (14/6, 4/6, 0)
    m = np.array([1.0, 3.0, 2.0])
    x = np.array([[0.0, 0, 0], [4.0, 0, 0], [1.0, 2.0, 0]])
    body = RigidBody.from_particles(m, x)
    com = (m[:, None] * x).sum(0) / m.sum()
    np.testing.assert_allclose(body.center_of_mass, [14 / 6, 4 / 6, 0.0])
    r = x - com
    expected = sum(mi * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for mi, ri in zip(m, r))
    np.testing.assert_allclose(body.inertia, expected, atol=1e-13)
    assert body.is_planar  # three masses are always coplanar
    # eight equal masses at the corners of a cube: a spherical top
    cube = RigidBody.from_particles(np.ones(8), [[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    assert cube.kind == "sphere" and not cube.is_planar
    np.testing.assert_allclose(cube.principal_moments, [4.0, 4.0, 4.0])
    # equilateral triangle: oblate and planar
    tri = RigidBody.from_particles([1.0, 1.0, 1.0], [[1, 0, 0], [-0.5, np.sqrt(3) / 2, 0], [-0.5, -np.sqrt(3) / 2, 0]])
    assert tri.kind == "oblate" and tri.is_planar


@PROP
@given(rng=S.rngs(), n=st.integers(3, 12), shift=st.sampled_from([0.0, 1.0, 1e3]))
def test_from_particles_translation_invariance_and_rotation_covariance(rng, n, shift):
    m = rng.uniform(0.1, 3.0, n)
    x = rng.standard_normal((n, 3))
    b0 = RigidBody.from_particles(m, x)
    t = shift * rng.standard_normal(3)
    b1 = RigidBody.from_particles(m, x + t)
    scale = np.abs(b0.inertia).max()
    np.testing.assert_allclose(b1.inertia, b0.inertia, atol=1e-13 * scale * (1 + shift**2 / 10))
    np.testing.assert_allclose(b1.center_of_mass, b0.center_of_mass + t, atol=1e-12 * (1 + shift))
    np.testing.assert_allclose(b1.positions, b0.positions, atol=1e-12 * (1 + shift))
    # rotating the particles rotates the tensor: I -> Q I Q^T
    Q = S.random_rotation_matrices(rng)
    b2 = RigidBody.from_particles(m, x @ Q.T)
    np.testing.assert_allclose(b2.inertia, Q @ b0.inertia @ Q.T, atol=1e-12 * scale)
    np.testing.assert_allclose(b2.principal_moments, b0.principal_moments, rtol=0, atol=1e-13 * scale)
    # the principal-frame body: positions rotated by P^T, the tensor of those positions is diagonal
    p = b0.in_principal_frame()
    np.testing.assert_allclose(p.positions, b0.positions @ b0.principal_axes, atol=1e-14)
    again = RigidBody.from_particles(m, p.positions)
    np.testing.assert_allclose(again.inertia, np.diag(b0.principal_moments), atol=1e-12 * scale)
    np.testing.assert_array_equal(p.center_of_mass, b0.center_of_mass)
    # tr(g) 1 - g with g = sum m x x^T (eq. 1.3)
    g = np.einsum("n,ni,nj->ij", m, b0.positions, b0.positions)
    np.testing.assert_allclose(b0.mass_matrix, g, atol=1e-12 * scale)


# ---------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "inertia, exc, msg",
    [
        ([[1.0, 0.1, 0], [0, 2.0, 0], [0, 0, 2.5]], InvalidInertiaError, "not symmetric"),
        ([1.0, -2.0, 2.5], InvalidInertiaError, "not positive definite"),
        ([0.0, 2.0, 2.0], InvalidInertiaError, "not positive definite"),
        ([[1.0, 2.0, 0], [2.0, 1.0, 0], [0, 0, 2.0]], InvalidInertiaError, "not positive definite"),
        ([1.0, 1.0, 3.0], InvalidInertiaError, r"triangle inequality I1 \+ I2 >= I3.*1.0 \+ 1.0 < 3.0"),
        ([[1.0, 1.0, 2.0], [1.0, 1.0, 3.0]], InvalidInertiaError, "triangle inequality"),
        (np.zeros((3, 3)), InvalidInertiaError, "inertia is zero"),
        ([1.0, np.nan, 2.0], InvalidInputError, "inertia contains NaN or infinite"),
        ([[1.0, 0, 0], [0, np.inf, 0], [0, 0, 1]], InvalidInputError, "inertia contains NaN or infinite"),
        ([1.0, 2.0], InvalidInputError, r"three principal moments.*got shape \(2,\)"),
        (np.ones((3, 2)), InvalidInputError, r"got shape \(3, 2\)"),
        (2.0, InvalidInputError, r"got shape \(\)"),
        (np.ones((2, 2)), InvalidInputError, r"got shape \(2, 2\)"),
    ],
)
def test_invalid_inertia(inertia, exc, msg):
    with pytest.raises(exc, match=msg):
        RigidBody(inertia)


def test_invalid_inertia_types():
    with pytest.raises(TypeError, match="inertia must be numeric"):
        RigidBody("1 2 3")
    with pytest.raises(TypeError, match="real"):
        RigidBody([1j, 2.0, 2.5])
    assert issubclass(InvalidInertiaError, ValueError)


def test_triangle_equality_within_rounding_is_accepted():
    # a plate whose moments come out of eigh with rounding errors
    rng = np.random.default_rng(5)
    P = S.random_rotation_matrices(rng)
    I = P @ np.diag([0.3, 0.7, 1.0]) @ P.T
    b = RigidBody(0.5 * (I + I.T))
    assert b.is_planar
    # but a real violation, relative 1e-9, is not
    with pytest.raises(InvalidInertiaError, match="triangle inequality"):
        RigidBody([0.3, 0.7, 1.0 + 1e-9])


@pytest.mark.parametrize(
    "masses, positions, msg",
    [
        ([1.0, 1.0], [[0, 0, 0], [1, 0, 0]], "at least three non-collinear masses, got 2"),
        ([1.0, 1.0, 1.0], [[0, 0, 0], [1, 0, 0]], r"same N; got \(3,\) and \(2, 3\)"),
        ([[1.0, 1.0, 1.0]], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], r"masses must have shape \(N,\)"),
        ([1.0, -1.0, 1.0], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "masses must all be > 0"),
        ([1.0, 0.0, 1.0], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "masses must all be > 0"),
        ([1.0, 1.0, 1.0, 2.0], [[0, 0, 0], [1, 1, 1], [2, 2, 2], [-3, -3, -3]], "collinear"),
        ([1.0, 1.0, 1.0], [[1, 2, 3]] * 3, "collinear \\(or coincide\\)"),
        ([1.0, 1.0, 1.0], [[0, 0, 0], [1, 0, 0], [0, 1]], "could not be converted|must have shape"),
        ([1.0, 1.0, 1.0], [[0, 0, 0], [1, 0, 0], [0, np.nan, 0]], "positions contains NaN"),
        ([1.0, np.inf, 1.0], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "masses contains NaN or infinite"),
        ([1.0, 1.0, 1.0], [[0, 0], [1, 0], [0, 1]], r"positions must have shape \(\.\.\., 3\)"),
    ],
)
def test_from_particles_errors(masses, positions, msg):
    with pytest.raises(InvalidInputError, match=msg):
        RigidBody.from_particles(masses, positions)


def test_nearly_collinear_but_valid():
    # a long thin triangle is a valid (prolate-ish) body
    b = RigidBody.from_particles([1.0, 1.0, 1.0], [[0, 0, 0], [1, 0, 0], [0.5, 1e-6, 0]])
    assert b.is_planar and np.all(b.principal_moments > 0)
