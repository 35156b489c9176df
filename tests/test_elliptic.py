"""Tests of the float64 elliptic functions and integrals against mpmath.

Independent truth: mpmath evaluated at 40+ significant digits at the *exact*
binary values of the float inputs (errors are measured in ulp of the true
result).  Measured maxima on x86-64 (numpy 2.x), see the final report:
sn/cn/dn <= 4.2 ulp for m1 in {1, 0.5, 1e-3, 1e-8, 1e-12, 1e-15, 1e-30, 0,
1e-300} (also near the zeros of cn and dn); K <= 0.3 ulp; R_F, R_D, R_J, R_C
<= 3.3 ulp over 25 decades of arguments; F, Pi (n > -1) <= 2 ulp.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

mp = pytest.importorskip("mpmath")

from eulerpoisson.errors import InvalidInputError  # noqa: E402
from eulerpoisson.numerics import elliptic as el  # noqa: E402

EPS = np.finfo(np.float64).eps
M1_VALUES = [1.0, 0.5, 1e-3, 1e-8, 1e-12, 1e-15, 0.0]


def _dps(m1):
    """Enough digits to represent 1 - m1 exactly and then 40 more."""
    return 40 + (int(-math.log10(m1)) if m1 > 0 else 0)


def _ulp_err(x, ref):
    ref = np.asarray(ref, dtype=float)
    err = np.abs(np.asarray(x) - ref) / np.abs(ref) / EPS
    # mpmath returns ~1e-57 noise for exact zeros (sn(0)); those we compare absolutely
    tiny = np.abs(ref) < 1e-40
    assert np.all(np.abs(np.asarray(x)[tiny]) < 1e-40)
    return np.where(tiny, 0.0, err)


def _sample_u(m1, rng, n=30):
    K = float(el.ellipk(m1=m1)) if m1 > 0 else 6.0
    special = [K, 2 * K, 3 * K, K / 2, 1.5 * K, 1e-3, 1e-200, -K, 7.25]
    return np.concatenate([rng.uniform(-4.2 * K, 4.2 * K, n), special])


@pytest.mark.parametrize("m1", M1_VALUES)
def test_sncndn_vs_mpmath(m1):
    rng = np.random.default_rng(int(1e3 * (m1 + 1)))
    u = _sample_u(m1, rng)
    sn, cn, dn = el.jacobi_sncndn(u, m1=m1)
    with mp.workdps(_dps(m1)):
        mm = 1 - mp.mpf(m1)
        for val, name in ((sn, "sn"), (cn, "cn"), (dn, "dn")):
            ref = [float(mp.ellipfun(name, mp.mpf(x), m=mm)) for x in u]
            err = _ulp_err(val, ref)
            assert err.max() <= 8.0, (name, m1, err.max(), u[np.argmax(err)])


@pytest.mark.parametrize("m1", [1e-30, 1e-300])
def test_sncndn_extreme_complement(m1):
    rng = np.random.default_rng(5)
    u = _sample_u(m1, rng, n=10)
    sn, cn, dn = el.jacobi_sncndn(u, m1=m1)
    with mp.workdps(_dps(m1)):
        mm = 1 - mp.mpf(m1)
        for val, name in ((sn, "sn"), (cn, "cn"), (dn, "dn")):
            ref = [float(mp.ellipfun(name, mp.mpf(x), m=mm)) for x in u]
            assert _ulp_err(val, ref).max() <= 8.0, name


def test_sncndn_large_argument_reduction():
    """u ~ 1e6 K: the double-double reduction loses nothing beyond the input."""
    m1 = 1e-10
    K = float(el.ellipk(m1=m1))
    u = np.array([1e6 * K + 0.3, 12345678.9, -9.87654321e7, 4e6 * K])
    sn, cn, dn = el.jacobi_sncndn(u, m1=m1)
    with mp.workdps(80):
        mm = 1 - mp.mpf(m1)
        for val, name in ((sn, "sn"), (cn, "cn"), (dn, "dn")):
            ref = [float(mp.ellipfun(name, mp.mpf(x), m=mm)) for x in u]
            assert _ulp_err(val, ref).max() <= 8.0, name


def test_identities_many_points():
    rng = np.random.default_rng(2)
    m1 = 10.0 ** rng.uniform(-16, 0, 2000)
    m1[:20] = 0.0
    u = rng.uniform(-50, 50, 2000)
    sn, cn, dn = el.jacobi_sncndn(u, m1=m1)
    assert np.max(np.abs(sn * sn + cn * cn - 1.0)) < 10 * EPS
    m = 1.0 - m1
    assert np.max(np.abs(dn * dn + m * sn * sn - 1.0)) < 10 * EPS
    assert np.all(dn > 0.0)


def test_parameter_forms_agree_and_match_scipy():
    from scipy.special import ellipj

    rng = np.random.default_rng(3)
    u = rng.uniform(-10, 10, 200)
    m = rng.uniform(0, 0.9, 200)
    a = el.jacobi_sncndn(u, m=m)
    b = el.jacobi_sncndn(u, m1=1.0 - m)
    c = el.jacobi_sncndn(u, m=m, m1=1.0 - m)
    for x, y, z in zip(a, b, c):
        np.testing.assert_allclose(x, y, rtol=0, atol=8 * EPS)
        np.testing.assert_allclose(x, z, rtol=0, atol=8 * EPS)
    sp = ellipj(u, m)
    for x, y in zip(a, sp[:3]):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-13)


def test_symmetries_and_limits():
    u = np.linspace(-7, 7, 57)
    sn, cn, dn = el.jacobi_sncndn(u, m=0.0)
    np.testing.assert_allclose(sn, np.sin(u), rtol=0, atol=2 * EPS)
    np.testing.assert_allclose(cn, np.cos(u), rtol=0, atol=2 * EPS)
    np.testing.assert_array_equal(dn, 1.0)
    sn, cn, dn = el.jacobi_sncndn(u, m1=0.0)
    np.testing.assert_allclose(sn, np.tanh(u), rtol=2 * EPS)
    np.testing.assert_allclose(cn, 1 / np.cosh(u), rtol=4 * EPS)
    np.testing.assert_array_equal(cn, dn)
    # odd/even symmetry is exact
    s1, c1, d1 = el.jacobi_sncndn(u, m1=1e-9)
    s2, c2, d2 = el.jacobi_sncndn(-u, m1=1e-9)
    np.testing.assert_array_equal(s1, -s2)
    np.testing.assert_array_equal(c1, c2)
    np.testing.assert_array_equal(d1, d2)
    # huge arguments on the separatrix: no overflow, no NaN
    s, c, d = el.jacobi_sncndn(np.array([800.0, -1e5]), m1=0.0)
    assert np.all(np.isfinite([s, c, d]))
    np.testing.assert_array_equal(s, [1.0, -1.0])


@pytest.mark.parametrize("m1", [1.0, 0.5, 1e-3, 1e-8, 1e-15, 0.0])
def test_am_vs_mpmath(m1):
    rng = np.random.default_rng(4)
    K = float(el.ellipk(m1=m1)) if m1 > 0 else 3.0
    u = rng.uniform(-5 * K, 5 * K, 25)
    am = el.jacobi_am(u, m1=m1)
    with mp.workdps(_dps(m1)):
        mm = 1 - mp.mpf(m1)
        ref = []
        for x, a in zip(u, am):
            b = mp.atan2(mp.ellipfun("sn", x, m=mm), mp.ellipfun("cn", x, m=mm))
            ref.append(float(b + 2 * mp.pi * mp.nint((a - b) / (2 * mp.pi))))
    assert _ulp_err(am, ref).max() <= 4.0
    if m1 > 0:  # quasi-periodicity am(u + 2K) = am(u) + pi; monotone
        np.testing.assert_allclose(el.jacobi_am(u + 2 * K, m1=m1) - am, np.pi, atol=1e-13)
    uu = np.linspace(-3 * K, 3 * K, 301)
    assert np.all(np.diff(el.jacobi_am(uu, m1=m1)) > 0)


@pytest.mark.parametrize("m1", [1.0, 0.5, 1e-3, 1e-8, 1e-15, 1e-100, 1e-300, 5e-324])
def test_ellipk_vs_mpmath(m1):
    with mp.workdps(_dps(m1) if m1 > 1e-300 else 400):
        ref = mp.ellipk(1 - mp.mpf(m1))
        K = el.ellipk(m1=m1)
        assert abs((mp.mpf(float(K)) - ref) / ref) <= 0.6 * EPS
        # the internal double-double value is accurate to ~1e-31
        kh, kl, _ = el._ellipk_dd(np.array(m1))
        assert abs((mp.mpf(float(kh)) + mp.mpf(float(kl)) - ref) / ref) < 1e-30
        # K'(m) = K(1 - m)
        refp = mp.ellipk(mp.mpf(m1))
        if 0 < m1 < 1:
            assert abs((mp.mpf(float(el.ellipkp(m=1 - m1, m1=m1))) - refp) / refp) <= 2 * EPS
    assert el.ellipk(m1=0.0) == np.inf
    assert el.ellipkp(m=0.0) == np.inf


def test_carlson_vs_mpmath():
    rng = np.random.default_rng(1)
    X = 10.0 ** rng.uniform(-20, 5, (120, 4))
    X[:15, 0] = 0.0
    with mp.workdps(40):
        checks = [
            (el.elliprf(X[:, 0], X[:, 1], X[:, 2]), [mp.elliprf(*x[:3]) for x in X]),
            (el.elliprd(X[:, 0], X[:, 1], X[:, 2]), [mp.elliprd(*x[:3]) for x in X]),
            (el.elliprj(*X.T), [mp.elliprj(*x) for x in X]),
            (el.elliprc(X[:, 0], X[:, 1]), [mp.elliprc(*x[:2]) for x in X]),
        ]
        for val, ref in checks:
            assert _ulp_err(val, [float(r) for r in ref]).max() <= 5.0


def test_carlson_hard_regimes():
    """R_J with p << x,y,z (cancellation in 1 + e_m) and R_C(x, y ~ x)."""
    rng = np.random.default_rng(6)
    x, y, z = 10.0 ** rng.uniform(-3, 4, (3, 60))
    p = 10.0 ** rng.uniform(-22, -12, 60)
    xx = rng.uniform(0.5, 2, 60)
    yy = xx * (1 + 10.0 ** rng.uniform(-16, -1, 60))
    with mp.workdps(40):
        ref_j = [float(mp.elliprj(*v)) for v in zip(x, y, z, p)]
        ref_c = [float(mp.elliprc(a, b)) for a, b in zip(xx, yy)]
    assert _ulp_err(el.elliprj(x, y, z, p), ref_j).max() <= 6.0
    assert _ulp_err(el.elliprc(xx, yy), ref_c).max() <= 4.0


@pytest.mark.parametrize("m1", [1.0, 0.5, 1e-3, 1e-8, 1e-15, 0.0])
def test_ellipf_ellippi_vs_mpmath(m1):
    rng = np.random.default_rng(8)
    phi = np.concatenate([rng.uniform(-12, 12, 10), [math.pi / 2, 1e-10, 1000.25]])
    if m1 == 0.0:
        phi = np.concatenate([np.clip(phi, -1.5, 1.5), [math.pi / 2]])
    with mp.workdps(_dps(m1) + 10):
        mm = 1 - mp.mpf(m1)
        ref = [float(mp.ellipf(mp.mpf(v), mm)) for v in phi]
        assert _ulp_err(el.ellipf(phi, m1=m1), ref).max() <= 4.0
        for n in (-0.5, 0.9):
            ref = [float(mp.ellippi(n, mp.mpf(v), mm)) for v in phi]
            assert _ulp_err(el.ellippi(n, phi, m1=m1), ref).max() <= 6.0
        # documented cancellation for n << -1 stays moderate
        ref = [float(mp.ellippi(-50, mp.mpf(v), mm)) for v in phi[:5]]
        assert _ulp_err(el.ellippi(-50.0, phi[:5], m1=m1), ref).max() <= 200.0
        if m1 > 0:
            ref = float(mp.ellippi(0.3, mm))
            assert abs(el.ellippi_complete(0.3, m1=m1) - ref) <= 4 * EPS * ref


def test_ellipf_separatrix_diverges():
    assert el.ellipf(2.0, m=1.0) == np.inf
    assert el.ellipf(-2.0, m=1.0) == -np.inf
    assert np.isfinite(el.ellipf(np.pi / 2, m=1.0))  # fl(pi/2) < pi/2
    assert el.ellippi_complete(0.5, m1=0.0) == np.inf


def test_batch_independence_bitwise():
    """Results do not depend on what else is in the batch."""
    rng = np.random.default_rng(9)
    u = rng.uniform(-30, 30, 50)
    m1 = 10.0 ** rng.uniform(-15, 0, 50)
    sn, cn, dn = el.jacobi_sncndn(u, m1=m1)
    for i in (0, 17, 49):
        s1, c1, d1 = el.jacobi_sncndn(u[i], m1=m1[i])
        assert (s1, c1, d1) == (sn[i], cn[i], dn[i])
    x = 10.0 ** rng.uniform(-10, 10, (4, 50))
    rj = el.elliprj(*x)
    for i in (3, 30):
        assert el.elliprj(*x[:, i]) == rj[i]


def test_shapes_and_scalars():
    sn, cn, dn = el.jacobi_sncndn(0.5, m=0.3)
    assert np.ndim(sn) == 0 and isinstance(float(sn), float)
    out = el.jacobi_sncndn(np.zeros((2, 1, 3)), m=np.array([0.1, 0.9]).reshape(2, 1, 1))
    assert all(o.shape == (2, 1, 3) for o in out)
    assert el.elliprf(np.ones((2, 3)), 2.0, 3.0).shape == (2, 3)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: el.jacobi_sncndn(1.0, m=1.5), r"parameter m must lie in \[0, 1\]"),
        (lambda: el.jacobi_sncndn(1.0, m=-0.1), r"parameter m must lie in \[0, 1\]"),
        (lambda: el.jacobi_sncndn(1.0, m1=2.0), r"complementary parameter m1"),
        (lambda: el.jacobi_sncndn(1.0), r"give the parameter m or its complement"),
        (lambda: el.jacobi_sncndn(1.0, m=0.5, m1=0.4), r"m \+ m1 != 1"),
        (lambda: el.jacobi_sncndn(np.nan, m=0.5), r"u must be finite"),
        (lambda: el.jacobi_sncndn(1.0, m=np.inf), r"m must be finite"),
        (lambda: el.jacobi_sncndn("abc", m=0.5), r"u must be a real array_like"),
        (lambda: el.jacobi_am(1.0, m=3.0), r"parameter m must lie"),
        (lambda: el.ellipk(m=1.1), r"parameter m must lie"),
        (lambda: el.ellipf(1.0, m=-1.0), r"parameter m must lie"),
        (lambda: el.elliprf(-1.0, 1.0, 1.0), r"x must be >= 0"),
        (lambda: el.elliprf(0.0, 0.0, 1.0), r"at most one of x, y, z may be zero"),
        (lambda: el.elliprd(1.0, 1.0, 0.0), r"z must be > 0"),
        (lambda: el.elliprd(0.0, 0.0, 1.0), r"x and y must not both be zero"),
        (lambda: el.elliprj(1.0, 1.0, 1.0, 0.0), r"p must be > 0"),
        (lambda: el.elliprj(0.0, 0.0, 1.0, 1.0), r"at most one of x, y, z"),
        (lambda: el.elliprj(1.0, -2.0, 1.0, 1.0), r"y must be >= 0"),
        (lambda: el.elliprc(1.0, -1.0), r"y must be > 0"),
        (lambda: el.elliprc(np.nan, 1.0), r"x must be finite"),
        (lambda: el.ellippi(1.0, 0.3, m=0.5), r"characteristic n must be < 1"),
        (lambda: el.ellippi_complete(2.0, m=0.5), r"characteristic n must be < 1"),
    ],
)
def test_bad_inputs_raise(call, match):
    with pytest.raises(InvalidInputError, match=match):
        call()
