"""Observation files for ep.fit: CSV, NetCDF and TOML read back as written, and every refusal names what is wrong."""

import math

import numpy as np
import pytest

from eulerpoisson.attitude.core import Attitude
from eulerpoisson.errors import InvalidInputError
from eulerpoisson.io.observations import CSV_COLUMNS, Observations, read_observations

DEG = math.pi / 180


def _random_q(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _random_dirs(rng, n):
    a = rng.normal(size=(n, 3))
    return a / np.linalg.norm(a, axis=1, keepdims=True)


def _write_csv(path, header, rows, comments=()):
    lines = [f"# {c}" for c in comments] + [",".join(header)]
    for row in rows:
        lines.append(
            ",".join(
                ""
                if (isinstance(v, float) and math.isnan(v))
                else repr(float(v))
                if isinstance(v, (float, np.floating))
                else str(v)
                for v in row
            )
        )
    path.write_text("\n".join(lines) + "\n")
    return path


def _csv(tmp_path, text, name="obs.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


# ---------------------------------------------------------------------------
# CSV round trips
# ---------------------------------------------------------------------------
def test_csv_round_trip_all_columns(tmp_path, rng):
    n = 7
    t = np.cumsum(rng.uniform(0.1, 1.0, n))
    q = _random_q(rng, n)
    w = rng.normal(size=(n, 3))
    a = _random_dirs(rng, n)
    s_att = rng.uniform(0.01, 1.0, n)
    s_w = rng.uniform(0.01, 1.0, (n, 3))
    s_ax = rng.uniform(0.01, 1.0, n)
    header = [
        "t",
        "qw",
        "qx",
        "qy",
        "qz",
        "wx",
        "wy",
        "wz",
        "ax",
        "ay",
        "az",
        "sigma_attitude_deg",
        "sigma_wx",
        "sigma_wy",
        "sigma_wz",
        "sigma_axis_deg",
    ]
    rows = np.column_stack([t, q, w, a, s_att, s_w, s_ax])
    p = _write_csv(tmp_path / "obs.csv", header, rows, comments=["star tracker + gyro + sun sensor"])
    obs = read_observations(p, axis=[0, 0, 2])
    assert isinstance(obs, Observations) and len(obs) == n and obs.source == str(p)
    np.testing.assert_array_equal(obs.t, t)
    np.testing.assert_allclose(obs.attitude, q, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(obs.omega, w)
    np.testing.assert_allclose(obs.axis_direction, a, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(obs.axis, [0.0, 0.0, 1.0])  # normalized
    np.testing.assert_allclose(obs.attitude_sigma, s_att * DEG, rtol=1e-15)
    np.testing.assert_array_equal(obs.omega_sigma, s_w)
    np.testing.assert_allclose(obs.axis_sigma, s_ax * DEG, rtol=1e-15)
    assert obs.omega_frame == "body" and obs.principal_axes is None
    assert all(v.dtype == np.float64 for v in (obs.t, obs.attitude, obs.omega, obs.axis_direction))
    with pytest.raises(ValueError):  # read-only
        obs.t[0] = 1.0


def test_csv_missing_cells_comments_and_sigma_nan_where_missing(tmp_path):
    p = _csv(
        tmp_path,
        (
            "\ufeff# a comment before the header\n"
            "\n"
            "t, qw, qx, qy, qz, wx, wy, wz, sigma_attitude_deg, sigma_omega\r\n"
            "0.0,1,0,0,0,0.10,0.02,0.50,0.05,0.01\r\n"
            "   # a comment between rows\n"
            '0.5,"0.9689",0.0125,0.0081,0.2470,nan,NAN,NaN,0.05,\n'
            "1.0,,,,,0.09,0.04,0.49,,0.02\n"
            "1.5,nan,nan,nan,nan,,,,-1,\n"
        ),
    )
    obs = read_observations(p)
    np.testing.assert_array_equal(obs.t, [0.0, 0.5, 1.0, 1.5])
    assert np.isnan(obs.attitude[2:]).all() and np.isfinite(obs.attitude[:2]).all()
    np.testing.assert_allclose(np.linalg.norm(obs.attitude[1]), 1.0, atol=1e-15)  # renormalized
    assert np.isnan(obs.omega[[1, 3]]).all() and np.isfinite(obs.omega[[0, 2]]).all()
    # a sigma is NaN where its observation is missing (its cell is not checked there: -1 is ignored)
    np.testing.assert_allclose(obs.attitude_sigma, [0.05 * DEG, 0.05 * DEG, np.nan, np.nan])
    np.testing.assert_allclose(obs.omega_sigma, [0.01, np.nan, 0.02, np.nan])


def test_csv_quaternion_within_tolerance_is_renormalized(tmp_path):
    q = np.array([0.5, 0.5, 0.5, 0.5]) * (1 + 9e-7)
    p = _write_csv(tmp_path / "o.csv", ["t", "qw", "qx", "qy", "qz"], [[0.0, *q], [1.0, 1, 0, 0, 0]])
    obs = read_observations(p)
    np.testing.assert_allclose(obs.attitude[0], [0.5] * 4, rtol=0, atol=2e-16)


@pytest.mark.parametrize("seq", ["ZXZ", "zxz", "XYZ", "zyx", "YXY"])
def test_csv_euler_columns_match_attitude_from_euler(tmp_path, rng, seq):
    ang = rng.uniform(-180, 180, (5, 3))
    ang[:, 1] = rng.uniform(10, 170, 5) if seq[0].lower() == seq[2].lower() else rng.uniform(-80, 80, 5)
    t = np.arange(5.0)
    cols = [f"euler_{seq}_{k}" for k in (1, 2, 3)]
    rows = np.column_stack([t, ang]).tolist()
    rows[3][1:] = [math.nan] * 3
    p = _write_csv(tmp_path / "e.csv", ["t", *cols], rows)
    obs = read_observations(p)
    keep = [0, 1, 2, 4]
    want = Attitude.from_euler(seq, ang[keep], degrees=True).as_quaternion()
    np.testing.assert_allclose(obs.attitude[keep], want, rtol=0, atol=1e-15)
    assert np.isnan(obs.attitude[3]).all()


def test_csv_other_columns_are_ignored_and_not_read(tmp_path):
    # as examples/tumbling_data/phone_toss_*.csv: a gyro with the source's own clock beside t
    p = _csv(tmp_path, "t,wx,wy,wz,t_phyphox,note\n0,19.38,7.52,0.47,128.5988,start\n0.00995,19.33,7.60,1.35,,\n")
    obs = read_observations(p)
    assert obs.ignored == ("t_phyphox", "note")
    np.testing.assert_array_equal(obs.omega, [[19.38, 7.52, 0.47], [19.33, 7.60, 1.35]])
    assert "t_phyphox" not in obs.fit_kwargs() and "ignored" not in obs.fit_kwargs()


def test_csv_columns_in_any_order_and_only_some_groups(tmp_path):
    p = _csv(tmp_path, "wz,wy,t,wx\n3,2,0,1\n6,5,1,4\n")
    obs = read_observations(p, omega_frame="space")
    np.testing.assert_array_equal(obs.omega, [[1, 2, 3], [4, 5, 6]])
    assert obs.attitude is None and obs.axis_direction is None and obs.omega_frame == "space"
    assert obs.omega_sigma is None


def test_sigma_keywords_override_file_columns(tmp_path):
    p = _csv(
        tmp_path,
        "t,qw,qx,qy,qz,wx,wy,wz,ax,ay,az,sigma_attitude_deg,sigma_omega,sigma_axis_deg\n"
        "0,1,0,0,0,1,2,3,0,0,1,0.1,0.2,0.3\n1,1,0,0,0,1,2,3,0,1,0,0.1,0.2,0.3\n",
    )
    obs = read_observations(p, axis=(1, 0, 0), sigma_attitude_deg=2.0, sigma_omega=0.5, sigma_axis_deg=3)
    assert obs.attitude_sigma == pytest.approx(2.0 * DEG) and isinstance(obs.attitude_sigma, float)
    assert obs.omega_sigma == 0.5
    assert obs.axis_sigma == pytest.approx(3 * DEG)
    # without keywords, the file's columns
    obs = read_observations(p, axis=(1, 0, 0))
    np.testing.assert_allclose(obs.attitude_sigma, [0.1 * DEG] * 2)
    np.testing.assert_allclose(obs.omega_sigma, [0.2] * 2)
    np.testing.assert_allclose(obs.axis_sigma, [0.3 * DEG] * 2)


def test_sigma_keyword_without_file_sigma(tmp_path):
    p = _csv(tmp_path, "t,wx,wy,wz\n0,1,2,3\n")
    assert read_observations(p, sigma_omega=0.25).omega_sigma == 0.25


def test_fit_kwargs(tmp_path):
    p = _csv(tmp_path, "t,qw,qx,qy,qz,wx,wy,wz\n0,1,0,0,0,1,2,3\n1,0,1,0,0,1,2,3\n")
    obs = read_observations(p, sigma_omega=0.1)
    kw = obs.fit_kwargs()
    assert list(kw) == ["t", "attitude", "omega", "omega_sigma", "omega_frame"]
    np.testing.assert_array_equal(kw["attitude"], obs.attitude)
    kw["t"][0] = -1.0  # a writable copy
    assert obs.t[0] == 0.0
    assert "principal_axes" not in kw and "axis" not in kw
    assert "Observations(" in repr(obs) and "attitude: 2 given" in repr(obs)


# ---------------------------------------------------------------------------
# CSV refusals
# ---------------------------------------------------------------------------
Q = "t,qw,qx,qy,qz\n"

CSV_ERRORS = [
    ("t,qw,qx\n0,1,0\n", {}, r"columns qw, qx without qy, qz: the attitude quaternion needs all of qw, qx, qy, qz"),
    ("t,wx,wy,wz,ax,ay\n0,1,2,3,0,0\n", {"axis": [0, 0, 1]}, r"columns ax, ay without az"),
    ("t,wx,wy,wz,sigma_wx\n0,1,2,3,1\n", {}, r"column sigma_wx without sigma_wy, sigma_wz"),
    ("qw,qx,qy,qz\n1,0,0,0\n", {}, r"no column 't' \(the times\)"),
    ("t,sigma_omega\n0,1\n", {}, r"no observation columns \(only t, sigma_omega\)"),
    ("t\n0\n1\n", {}, r"no observation columns"),
    (Q + "0,1,0,0,0\n1,1,x,0,0\n", {}, r"obs\.csv, line 3, column 'qx': 'x' is not a number"),
    (Q + "0,1,0,0,0\n1,1,1_0,0,0\n", {}, r"line 3, column 'qx': '1_0' is not a number"),
    (
        Q + "0,1,0,0,0\n2,1,0,0,0\n1,1,0,0,0\n",
        {},
        r"line 4: time t = 1\.0 is before t = 2\.0 at line 3; times must be strictly increasing",
    ),
    (Q + "0,1,0,0,0\n# c\n0,1,0,0,0\n", {}, r"line 4: duplicate time t = 0\.0 \(also at line 2\)"),
    (Q + "0,1,0,0,0\ninf,1,0,0,0\n", {}, r"line 3, column 't': the time is inf, not finite"),
    (Q + "0,1,0,0,0\n,1,0,0,0\n", {}, r"line 3, column 't': the time is missing"),
    (Q + "0,1,0,0,0\n1,1,0,0,0.01\n", {}, r"line 3: the quaternion \[1\.0, 0\.0, 0\.0, 0\.01\] has norm 1\.00004999"),
    (Q + "0,1,0,0,0\n1,1.00001,0,0,0\n", {}, r"line 3: the quaternion .* has norm 1\.00001, not 1 \(tolerance 1e-06\)"),
    (Q + "0,0,0,0,0\n", {}, r"line 2: the quaternion is the zero vector"),
    (Q + "0,1,0,0,0\n1,1,0,,0\n", {}, r"line 3: the quaternion is partly missing \(column 'qy' empty/NaN"),
    (
        "t,qw,qx,qy,qz,euler_ZXZ_1,euler_ZXZ_2,euler_ZXZ_3\n0,1,0,0,0,0,0,0\n",
        {},
        r"both quaternion columns \(qw, qx, qy, qz\) and Euler angle columns \(euler_ZXZ_\*\)",
    ),
    (
        "t,euler_ZXZ_1,euler_ZXZ_2,euler_xyz_1,euler_xyz_2,euler_xyz_3\n0,0,0,0,0,0\n",
        {},
        r"Euler angles in more than one sequence \(ZXZ, xyz\)",
    ),
    ("t,euler_ZXZ_1,euler_ZXZ_2\n0,0,0\n", {}, r"columns euler_ZXZ_1, euler_ZXZ_2 without euler_ZXZ_3"),
    (
        "t,euler_ZZX_1,euler_ZZX_2,euler_ZZX_3\n0,0,0,0\n",
        {},
        r"column 'euler_ZZX_1': invalid Euler sequence: .*consecutive axes must differ",
    ),
    ("t,euler_ZxZ_1,euler_ZxZ_2,euler_ZxZ_3\n0,0,0,0\n", {}, r"euler_ZxZ_1.*mixes lower case"),
    (
        "t,euler_XYZ_1,euler_XYZ_2,euler_XYZ_3\n0,0,0,0\n1,0,,0\n",
        {},
        r"line 3: the Euler angles \(XYZ\) is partly missing \(column 'euler_XYZ_2'",
    ),
    (
        "t,ax,ay,az\n0,0,0,1\n",
        {},
        r"columns ax, ay, az give the space direction of a body axis, but not which axis: pass axis=",
    ),
    ("t,wx,wy,wz\n0,1,2,3\n", {"axis": [0, 0, 1]}, r"axis=\[0\.0, 0\.0, 1\.0\] is given, but .*obs\.csv has no axis"),
    ("t,ax,ay,az\n0,0,0,1\n1,0,0,0\n", {"axis": [0, 0, 1]}, r"line 3: the axis direction is the zero vector"),
    (
        "t,ax,ay,az\n0,0,0,1\n1,0,0.5,0.5\n",
        {"axis": [0, 0, 1]},
        r"line 3: the axis direction \[0\.0, 0\.5, 0\.5\] has norm 0\.7071067812, not 1",
    ),
    ("t,wx,wy,wz\n0,1,2,3\n", {"omega_frame": "inertial"}, r"omega_frame must be 'body' or 'space', got 'inertial'"),
    (
        "t,wx,wy,wz,qW\n0,1,2,3,4\n",
        {},
        r"line 1: unknown column 'qW' \(did you mean 'qw'\? names are case sensitive\); "
        r"known columns: t, qw, qx, qy, qz, euler_SEQ_1, euler_SEQ_2, euler_SEQ_3, wx, wy, wz, ax, ay, az, "
        r"sigma_attitude_deg, sigma_omega, sigma_wx, sigma_wy, sigma_wz, sigma_axis_deg$",
    ),
    ("t,wx,wy,wz,sigma_w\n0,1,2,3,4\n", {}, r"unknown column 'sigma_w' \(sigma columns are sigma_attitude_deg, "),
    ("t,wx,wy,wz,euler_1\n0,1,2,3,4\n", {}, r"unknown column 'euler_1' \(Euler angle columns are euler_SEQ_1, "),
    ("t,wx,wy,wz,wx\n0,1,2,3,4\n", {}, r"column 'wx' appears twice in the header"),
    ("t,wx,wy,wz\n0,1,2,3\n1,1,2\n", {}, r"line 3: 3 cells, but the header \(line 1\) has 4 columns"),
    ("t,wx,,wz\n0,1,2,3\n", {}, r"line 1: column 3 of the header has no name"),
    ("# only a comment\n\n", {}, r"no header row"),
    ("t,wx,wy,wz\n# no data\n", {}, r"no data rows after the header \(line 1\)"),
    ("t,wx,wy,wz\n0,1,inf,3\n", {}, r"line 2, column 'wy': value inf is not finite"),
    (
        "t,wx,wy,wz,sigma_omega\n0,1,2,3,0\n",
        {},
        r"line 2, column 'sigma_omega': sigma is 0\.0; a sigma must be positive and finite where its observation",
    ),
    (
        "t,wx,wy,wz\n0,1,2,3\n1,1,,3\n",
        {},
        r"line 3: the angular velocity is partly missing \(column 'wy' empty/NaN, the rest given in columns wx, wy, wz\)",
    ),
    (
        "t,wx,wy,wz,sigma_wx,sigma_wy,sigma_wz\n0,,,,1,,1\n1,1,2,3,1,,1\n",
        {},
        r"line 3, column 'sigma_wy': sigma is missing",
    ),
    (Q + "0,1,0,0,0,\n", {}, r"line 2: 6 cells, but the header \(line 1\) has 5 columns"),
    ("t,qw,qx,qy,qz,sigma_attitude_deg\n0,1,0,0,0,inf\n", {}, r"column 'sigma_attitude_deg': sigma is inf deg"),
    (
        "t,wx,wy,wz,sigma_axis_deg\n0,1,2,3,1\n",
        {},
        r"column sigma_axis_deg without ax, ay, az: a sigma needs its observation",
    ),
    (
        "t,wx,wy,wz,sigma_omega,sigma_wx,sigma_wy,sigma_wz\n0,1,2,3,1,1,1,1\n",
        {},
        r"both sigma_omega and sigma_wx, sigma_wy, sigma_wz",
    ),
    ("t,wx,wy,wz\n0,1,2,3\n", {"sigma_attitude_deg": 1.0}, r"sigma_attitude_deg=1\.0 is given, but .* has no attitude"),
    ("t,wx,wy,wz\n0,1,2,3\n", {"sigma_omega": -1}, r"sigma_omega must be positive and finite, got -1"),
    ("t,wx,wy,wz\n0,1,2,3\n", {"sigma_omega": "0.1"}, r"sigma_omega must be a positive number, got str '0\.1'"),
    ("t,wx,wy,wz\n0,1,2,3\n", {"sigma_omega": math.nan}, r"sigma_omega must be positive and finite, got nan"),
    ("t,ax,ay,az\n0,0,0,1\n", {"axis": [0, 0, 0]}, r"axis must be a nonzero vector, got \[0\.0, 0\.0, 0\.0\]"),
    ("t,ax,ay,az\n0,0,0,1\n", {"axis": [0, 1]}, r"axis must be three numbers \(a body axis\), got shape \(2,\)"),
]


@pytest.mark.parametrize("text, kwargs, match", CSV_ERRORS)
def test_csv_errors(tmp_path, text, kwargs, match):
    p = _csv(tmp_path, text)
    with pytest.raises(InvalidInputError, match=match):
        read_observations(p, **kwargs)


def test_file_errors(tmp_path):
    with pytest.raises(InvalidInputError, match=r"nowhere\.csv: no such file"):
        read_observations(tmp_path / "nowhere.csv")
    (tmp_path / "dir.csv").mkdir()
    with pytest.raises(InvalidInputError, match=r"dir\.csv: not a file"):
        read_observations(tmp_path / "dir.csv")
    (tmp_path / "obs.txt").write_text("t,wx,wy,wz\n0,1,2,3\n")
    with pytest.raises(
        InvalidInputError,
        match=r"obs\.txt: unknown observations file extension '\.txt'; "
        r"expected \.csv, \.nc or \.toml",
    ):
        read_observations(tmp_path / "obs.txt")
    with pytest.raises(InvalidInputError, match=r"path must be a file name .* got int 3"):
        read_observations(3)
    (tmp_path / "latin.csv").write_bytes(b"t,wx,wy,wz\n0,1,2,3 \xe9\n")
    with pytest.raises(InvalidInputError, match=r"latin\.csv: not UTF-8 text"):
        read_observations(tmp_path / "latin.csv")
    # the extension is case insensitive
    (tmp_path / "UP.CSV").write_text("t,wx,wy,wz\n0,1,2,3\n")
    assert read_observations(tmp_path / "UP.CSV").omega.shape == (1, 3)


def test_csv_column_list_is_documented():
    import eulerpoisson.io.observations as mod

    for col in CSV_COLUMNS:
        assert f"``{col}" in mod.__doc__ or f", {col}" in mod.__doc__, col


# ---------------------------------------------------------------------------
# NetCDF
# ---------------------------------------------------------------------------
@pytest.fixture
def xr():
    return pytest.importorskip("xarray")


def _dataset(xr, rng, n=6):
    t = np.linspace(0.0, 5.0, n)
    q = _random_q(rng, n)
    q[2] = np.nan
    w = rng.normal(size=(n, 3))
    a = _random_dirs(rng, n)
    ds = xr.Dataset(
        {
            "q": (("t", "quaternion"), q),
            "omega": (("t", "xyz"), w, {"frame": "space"}),
            "axis_direction": (("t", "xyz"), a, {"axis": [0.0, 1.0, 0.0]}),
            "attitude_sigma": ((), 0.5, {"units": "deg"}),
            "omega_sigma": (("t", "xyz"), np.full((n, 3), 0.01)),
            "axis_sigma": (("t",), np.full(n, 0.02)),
        },
        coords={"t": t},
        attrs={"principal_axes": "fit"},
    )
    return ds, t, q, w, a


@pytest.mark.parametrize("engine, fmt", [("h5netcdf", None), ("scipy", "NETCDF3_64BIT")])
def test_netcdf_round_trip(tmp_path, rng, xr, engine, fmt):
    pytest.importorskip(engine if engine != "scipy" else "scipy.io")
    ds, t, q, w, a = _dataset(xr, rng)
    ds["temperature"] = ("t", np.arange(6.0))  # not ours: ignored
    p = tmp_path / "obs.nc"
    ds.to_netcdf(p, engine=engine, **({"format": fmt} if fmt else {}))
    obs = read_observations(p)
    np.testing.assert_array_equal(obs.t, t)
    np.testing.assert_allclose(obs.attitude, q, rtol=0, atol=1e-15)
    assert np.isnan(obs.attitude[2]).all()
    np.testing.assert_array_equal(obs.omega, w)
    assert obs.omega_frame == "space" and obs.principal_axes == "fit" and obs.ignored == ("temperature",)
    np.testing.assert_array_equal(obs.axis, [0.0, 1.0, 0.0])
    np.testing.assert_allclose(obs.axis_direction, a, rtol=0, atol=1e-15)
    assert obs.attitude_sigma == pytest.approx(0.5 * DEG)
    np.testing.assert_array_equal(obs.omega_sigma, np.full((6, 3), 0.01))
    np.testing.assert_array_equal(obs.axis_sigma, np.full(6, 0.02))
    kw = obs.fit_kwargs()
    assert kw["principal_axes"] == "fit" and kw["omega_frame"] == "space"
    # keywords that agree with the file are accepted; sigma keywords replace the file's
    obs = read_observations(p, omega_frame="space", axis=[0, 2, 0], sigma_omega=0.3)
    assert obs.omega_sigma == 0.3


def test_netcdf_attitude_name_and_float32(tmp_path, rng, xr):
    q = _random_q(rng, 3).astype(np.float32)
    ds = xr.Dataset({"attitude": (("t", "c"), q)}, coords={"t": [0.0, 1.0, 2.0]})
    p = tmp_path / "a.nc"
    ds.to_netcdf(p, engine="h5netcdf")
    obs = read_observations(p)
    assert obs.attitude.dtype == np.float64
    np.testing.assert_allclose(np.linalg.norm(obs.attitude, axis=1), 1.0, atol=1e-15)
    assert obs.omega is None and obs.omega_frame == "body"


def _nc_error(tmp_path, ds, match, **kwargs):
    p = tmp_path / "bad.nc"
    ds.to_netcdf(p, engine="scipy")  # NetCDF-3: quicker to write than HDF5
    with pytest.raises(InvalidInputError, match=match):
        read_observations(p, **kwargs)


def test_netcdf_errors(tmp_path, rng, xr):
    ds, *_ = _dataset(xr, rng)
    _nc_error(
        tmp_path, ds, r"omega_frame='body' contradicts .*bad\.nc, where omega has frame = 'space'", omega_frame="body"
    )
    _nc_error(
        tmp_path,
        ds,
        r"axis=\[1\.0, 0\.0, 0\.0\] contradicts .*where axis_direction has axis = \[0\.0, 1\.0",
        axis=[1, 0, 0],
    )
    _nc_error(
        tmp_path,
        ds.assign(sigma_omega=("t", np.zeros(6))),
        r"unknown variable 'sigma_omega' \(a misspelt name\?\); known variables: t \(coordinate\), q, attitude",
    )
    _nc_error(tmp_path, ds.drop_vars("omega").assign(Omega=ds["omega"]), r"unknown variable 'Omega'")
    _nc_error(
        tmp_path,
        ds.assign(attitude=(("t", "quaternion"), ds["q"].values)),
        r"both variables 'q' and 'attitude'; give one of them",
    )
    bad = ds.copy()
    bad["q"] = bad["q"] * 2
    _nc_error(tmp_path, bad, r"bad\.nc, t index 0: the quaternion .* has norm 2, not 1")
    _nc_error(
        tmp_path,
        ds.drop_vars("q").assign(q=(("quaternion", "t"), ds["q"].values.T)),
        r"variable 'q' must have dimensions \(t, 4\), got \('quaternion', 't'\)",
    )
    bad = ds.copy()
    bad["omega"].attrs["frame"] = "world"
    _nc_error(tmp_path, bad, r"attribute 'frame' of variable 'omega' must be 'body' or 'space', got 'world'")
    bad = ds.copy()
    bad["attitude_sigma"].attrs["units"] = "arcsec"
    _nc_error(tmp_path, bad, r"variable 'attitude_sigma': units 'arcsec' must be 'rad' or 'deg'")
    bad = ds.copy()
    bad["axis_sigma"] = ("t", np.r_[0.02, -1.0, 0.02, 0.02, 0.02, 0.02])
    _nc_error(tmp_path, bad, r"t index 1, variable 'axis_sigma': sigma is -1\.0 rad; a sigma must be positive")
    bad = ds.copy()
    del bad["axis_direction"].attrs["axis"]
    _nc_error(tmp_path, bad, r"variable 'axis_direction' give the space direction of a body axis, but not which")
    _nc_error(
        tmp_path,
        ds.drop_vars(["q", "omega", "axis_direction", "attitude_sigma", "omega_sigma", "axis_sigma"]),
        r"no observation variables; give at least one of q \(or attitude\), omega, axis_direction",
    )
    _nc_error(tmp_path, ds.drop_vars(["q"]), r"variable 'attitude_sigma' without its observation")
    _nc_error(tmp_path, ds.assign_coords(t=ds.t.values[::-1].copy()), r"t index 1: time t = 4\.0 is before t = 5\.0")
    _nc_error(
        tmp_path,
        xr.Dataset({"omega": (("time", "xyz"), np.zeros((2, 3)))}),
        r"no dimension 't' \(the times of the observations\); dimensions: time, xyz",
    )
    (tmp_path / "junk.nc").write_bytes(b"this is not a netcdf file")
    with pytest.raises(InvalidInputError, match=r"junk\.nc: not a readable NetCDF file"):
        read_observations(tmp_path / "junk.nc")


# ---------------------------------------------------------------------------
# TOML
# ---------------------------------------------------------------------------
def test_toml_settings_and_relative_file(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    _csv(data, "t,qw,qx,qy,qz,wx,wy,wz,ax,ay,az,sigma_omega\n0,1,0,0,0,1,2,3,1,0,0,0.5\n1,1,0,0,0,1,2,3,0,1,0,0.5\n")
    cfg = data / "obs.toml"
    cfg.write_text(
        "[observations]\n"
        'file = "obs.csv"\n'
        "sigma_attitude_deg = 0.5\n"
        "sigma_axis_deg = 2\n"
        'omega_frame = "space"\n'
        "axis = [0, 0, 1]\n"
        'principal_axes = "given"\n'
        "[fit]  # other tables belong to other readers\n"
        "anything = 1\n"
    )
    obs = read_observations(cfg)
    assert obs.source == str(cfg)
    assert obs.attitude_sigma == pytest.approx(0.5 * DEG) and obs.axis_sigma == pytest.approx(2 * DEG)
    np.testing.assert_array_equal(obs.omega_sigma, [0.5, 0.5])  # from the CSV: not set in the TOML
    assert obs.omega_frame == "space" and obs.principal_axes == "given"
    np.testing.assert_array_equal(obs.axis, [0, 0, 1])
    assert obs.fit_kwargs()["principal_axes"] == "given"
    # keyword arguments (command-line flags) override the TOML
    obs = read_observations(cfg, sigma_attitude_deg=1.0, omega_frame="body", axis=[1, 0, 0], sigma_omega=0.1)
    assert obs.attitude_sigma == pytest.approx(DEG) and obs.omega_frame == "body" and obs.omega_sigma == 0.1
    np.testing.assert_array_equal(obs.axis, [1, 0, 0])


def test_toml_netcdf_principal_axes_conflict(tmp_path, rng, xr):
    ds, *_ = _dataset(xr, rng)
    ds.to_netcdf(tmp_path / "obs.nc", engine="h5netcdf")
    (tmp_path / "ok.toml").write_text('[observations]\nfile = "obs.nc"\nprincipal_axes = "fit"\n')
    assert read_observations(tmp_path / "ok.toml").principal_axes == "fit"
    (tmp_path / "obs.toml").write_text('[observations]\nfile = "obs.nc"\nprincipal_axes = "given"\n')
    with pytest.raises(
        InvalidInputError,
        match=r"obs\.toml: \[observations\] principal_axes = 'given' contradicts "
        r".*obs\.nc, whose attribute principal_axes = 'fit'",
    ):
        read_observations(tmp_path / "obs.toml")


TOML_ERRORS = [
    ('[observations\nfile = "obs.csv"\n', r"cfg\.toml: invalid TOML"),
    ('[obs]\nfile = "obs.csv"\n', r"cfg\.toml: no \[observations\] table"),
    ("observations = 3\n", r"'observations' must be a table"),
    (
        '[observations]\nfile = "obs.csv"\nsigma_att = 1\n',
        r"cfg\.toml: unknown key 'sigma_att' in \[observations\]; allowed keys: file, sigma_attitude_deg, sigma_omega, "
        r"sigma_axis_deg, omega_frame, axis, principal_axes",
    ),
    ("[observations]\nsigma_omega = 1\n", r"\[observations\] file is required"),
    ("[observations]\nfile = 3\n", r"\[observations\] file must be a file name"),
    ('[observations]\nfile = "obs.dat"\n', r"file = 'obs\.dat' must be a \.csv or \.nc file"),
    ('[observations]\nfile = "other.csv"\n', r"other\.csv \(the file of .*cfg\.toml\): no such file"),
    (
        '[observations]\nfile = "obs.csv"\nsigma_omega = "big"\n',
        r"cfg\.toml: \[observations\] sigma_omega must be a positive number, got str 'big'",
    ),
    ('[observations]\nfile = "obs.csv"\nsigma_omega = 0\n', r"\[observations\] sigma_omega must be positive"),
    (
        '[observations]\nfile = "obs.csv"\nomega_frame = "Body"\n',
        r"\[observations\] omega_frame must be 'body' or 'space', got 'Body'",
    ),
    ('[observations]\nfile = "obs.csv"\naxis = [0, 1]\n', r"\[observations\] axis must be three numbers"),
    ('[observations]\nfile = "obs.csv"\naxis = "z"\n', r"\[observations\] axis must be three numbers .* string 'z'"),
    (
        '[observations]\nfile = "obs.csv"\nprincipal_axes = "yes"\n',
        r"\[observations\] principal_axes must be 'given' or 'fit', got 'yes'",
    ),
    (
        '[observations]\nfile = "obs.csv"\nsigma_axis_deg = 1\n',
        r"cfg\.toml: \[observations\] sigma_axis_deg = 1\.0 is given, but .*obs\.csv has no axis direction",
    ),
    (
        '[observations]\nfile = "obs.csv"\naxis = [0, 0, 1]\n',
        r"cfg\.toml: \[observations\] axis = \[0\.0, 0\.0, 1\.0\] is given, but .*obs\.csv has no axis direction",
    ),
]


@pytest.mark.parametrize("text, match", TOML_ERRORS)
def test_toml_errors(tmp_path, text, match):
    _csv(tmp_path, "t,wx,wy,wz\n0,1,2,3\n")
    cfg = tmp_path / "cfg.toml"
    cfg.write_text(text)
    with pytest.raises(InvalidInputError, match=match):
        read_observations(cfg)
