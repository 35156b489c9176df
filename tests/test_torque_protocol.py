"""The torque protocol: each Torque class carries its time shift, its integrals, its record and its CLI description.

- :meth:`Model.shifted` / :meth:`Torque.shifted` give, bit for bit, what the per-class chain of
  ``io.stream._shifted_torques`` gave (a frozen copy of it is kept here as the reference, so that the
  comparison outlives the chain), for every torque class, random parameters and several start times;
- ``from_dict(to_dict())`` and ``from_params`` for every registered torque kind;
- the command-line description (:class:`TorqueParam`) carries the flags and TOML keys of ``simulate``.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.errors import InvalidInputError
from eulerpoisson.numerics.quaternion import qmul
from eulerpoisson.torques import (
    TORQUES,
    BodyTorque,
    CallableTorque,
    Gravity,
    GravityGradient,
    MagneticDipoleTorque,
    SpaceTorque,
    Torque,
    TorqueParam,
    UnrecordedTorque,
    register_torque,
)

T_STARTS = (0.0, 1.7, -3.25, 123.456)


# ---------------------------------------------------------------------------
# the reference: the chain of io/stream.py as it was (frozen copy)
# ---------------------------------------------------------------------------
def _rotation_z(phi):
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.cos(phi / 2), np.zeros_like(phi), np.zeros_like(phi), np.sin(phi / 2)], -1)


def _rotate_z(v, phi):
    v = np.asarray(v, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack(
        [
            c * v[..., 0] - s * v[..., 1],
            s * v[..., 0] + c * v[..., 1],
            np.broadcast_to(v[..., 2], np.broadcast_shapes(v[..., 2].shape, np.shape(c))),
        ],
        -1,
    )


def reference_shift(torques, t_start):
    grads = [tq for tq in torques if isinstance(tq, GravityGradient)]
    phi = np.zeros(())
    for tq in grads:
        if np.any(tq.mean_motion != 0):
            phi = np.asarray(tq.mean_motion, dtype=float) * t_start
            break
    turn = bool(np.any(phi != 0))
    out = []
    for tq in torques:
        if isinstance(tq, (GravityGradient, BodyTorque)):
            out.append(tq)
        elif isinstance(tq, Gravity):
            out.append(Gravity(tq.mass, tq.center_of_mass, _rotate_z(tq.g, -phi)) if turn else tq)
        elif isinstance(tq, SpaceTorque):
            out.append(SpaceTorque(_rotate_z(tq.tau, -phi)) if turn else tq)
        elif isinstance(tq, CallableTorque):
            func, rz = tq.func, _rotation_z(phi)

            def shifted(s, q, omega, _f=func, _rz=rz, _turn=turn):
                return _f(np.asarray(s) + t_start, qmul(_rz, q) if _turn else q, omega)

            shifted.__name__ = getattr(func, "__name__", "torque")
            out.append(CallableTorque(shifted))
        elif tq.time_dependent or turn:
            raise InvalidInputError(
                f"the torque {tq!r} depends on time (or on the space frame with a gravity gradient) and "
                "cannot be continued from a later state; solve the run in one piece"
            )
        else:
            out.append(tq)
    return out, phi


def _stream_shift():
    """The chain of io/stream.py while it exists (the lead moves it onto Model.shifted)."""
    return getattr(importlib.import_module("eulerpoisson.io.stream"), "_shifted_torques", None)


def _unit_quaternions(rng, shape):
    q = rng.normal(size=shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _wobble(t, q, omega):
    """A time-dependent callable torque: depends on t, on the attitude and on omega."""
    t = np.asarray(t, dtype=float)
    return 0.1 * np.sin(t)[..., None] * q[..., 1:] - 0.05 * omega


def _torque_sets(rng, batch):
    """Lists of torques of every class that shifts, with and without a gravity gradient (zero or not)."""
    b = batch
    grav = Gravity(rng.uniform(0.5, 2.0, b), rng.normal(size=b + (3,)), rng.normal(size=b + (3,)))
    body = BodyTorque(rng.normal(size=b + (3,)))
    space = SpaceTorque(rng.normal(size=b + (3,)))
    call = CallableTorque(_wobble)
    sets = [
        [grav, body, space, call],
        [GravityGradient(rng.uniform(0.1, 2.0, b)), grav, body, space, call],
        [grav, GravityGradient(np.zeros(b)), space, GravityGradient(rng.uniform(0.1, 2.0, b)), call],
        [GravityGradient(0.0), grav, space],
        [body, call],
    ]
    return sets


def _same_array(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def _assert_same_torque(mine, ref, rng, batch):
    assert type(mine) is type(ref)
    if isinstance(ref, CallableTorque):
        assert mine.func.__name__ == ref.func.__name__
        for _ in range(3):
            s = float(rng.uniform(-4, 4))
            q = _unit_quaternions(rng, batch)
            w = rng.normal(size=batch + (3,))
            assert _same_array(mine.func(s, q, w), ref.func(s, q, w))
        return
    if mine is ref:
        return
    attrs = {
        Gravity: ("mass", "center_of_mass", "g"),
        SpaceTorque: ("tau",),
        BodyTorque: ("tau",),
        GravityGradient: ("mean_motion",),
    }[type(ref)]
    for a in attrs:
        assert _same_array(getattr(mine, a), getattr(ref, a)), a


@pytest.mark.parametrize("batch", [(), (3,), (2, 2)])
@pytest.mark.parametrize("t_start", T_STARTS)
def test_model_shifted_is_bitwise_the_old_chain(batch, t_start):
    rng = np.random.default_rng([len(batch), int(abs(t_start) * 1000)])
    body = ep.RigidBody(np.sort(rng.uniform(1.0, 1.5, 3)))
    chains = [reference_shift]
    if _stream_shift() is not None:
        chains.append(_stream_shift())
    for torques in _torque_sets(rng, batch):
        model = ep.Model(body, torques)
        shifted, phi = model.shifted(t_start)
        assert isinstance(shifted, ep.Model) and shifted.body is model.body
        for chain in chains:
            ref, ref_phi = chain(list(model.torques), t_start)
            assert _same_array(phi, ref_phi)
            assert len(shifted.torques) == len(ref)
            for mine, r in zip(shifted.torques, ref):
                _assert_same_torque(mine, r, rng, batch)


def test_torque_shifted_per_class_with_a_given_angle():
    """Each class alone, with a given phi: the same as the chain's branch for that class."""
    rng = np.random.default_rng(7)
    phi = np.asarray(0.8)
    grav = Gravity(1.5, rng.normal(size=3), rng.normal(size=3))
    g2 = grav.shifted(2.0, phi)
    assert _same_array(g2.g, _rotate_z(grav.g, -phi)) and _same_array(g2.mass, grav.mass)
    sp = SpaceTorque(rng.normal(size=3))
    assert _same_array(sp.shifted(2.0, phi).tau, _rotate_z(sp.tau, -phi))
    bt = BodyTorque(rng.normal(size=3))
    gg = GravityGradient(0.4)
    assert bt.shifted(2.0, phi) is bt and gg.shifted(2.0, phi) is gg
    # nothing turned: the same objects
    assert grav.shifted(2.0, np.zeros(())) is grav and sp.shifted(2.0, 0.0) is sp
    assert gg.frame_rate is gg.mean_motion
    for tq in (grav, sp, bt, CallableTorque(_wobble), UnrecordedTorque("x")):
        assert tq.frame_rate is None


class _Clock(Torque):
    """A time-dependent torque that does not know how to shift."""

    kind = "test_clock"
    time_dependent = True

    def evaluate(self, t, R, omega, inertia):
        return np.zeros(np.shape(omega))

    def __repr__(self):
        return "_Clock()"


class _Fixed(Torque):
    """An autonomous torque fixed in the body that does not override shifted."""

    kind = "test_fixed"

    def evaluate(self, t, R, omega, inertia):
        return np.ones(np.shape(omega))

    def __repr__(self):
        return "_Fixed()"


@pytest.mark.parametrize("torques", [[_Clock()], [UnrecordedTorque("f")], [GravityGradient(0.3), _Fixed()]])
def test_unshiftable_torques_raise_the_same_error(torques):
    model = ep.Model([1.0, 2.0, 2.5], torques)
    with pytest.raises(InvalidInputError) as ref:
        reference_shift(list(model.torques), 2.0)
    with pytest.raises(InvalidInputError, match="cannot be continued from a later state") as mine:
        model.shifted(2.0)
    assert str(mine.value) == str(ref.value)


def test_autonomous_unknown_torque_is_kept_without_a_turn():
    model = ep.Model([1.0, 2.0, 2.5], [_Fixed(), GravityGradient(0.0)])
    shifted, phi = model.shifted(5.0)
    assert shifted.torques[0] is model.torques[0] and float(phi) == 0.0


@pytest.mark.parametrize("t_start", T_STARTS[1:])
def test_shifted_model_is_the_motion_seen_from_t_start(t_start):
    """tau'(s, R_z(-phi) R) = tau(t_start + s, R) for every torque class, magnetic ones included."""
    rng = np.random.default_rng(11)
    field = rng.normal(size=3)
    torques = [
        GravityGradient(0.37),
        Gravity(1.2, rng.normal(size=3), rng.normal(size=3)),
        BodyTorque(rng.normal(size=3)),
        SpaceTorque(rng.normal(size=3)),
        CallableTorque(_wobble),
        MagneticDipoleTorque(rng.normal(size=3), rng.normal(size=3)),
        MagneticDipoleTorque(rng.normal(size=3), lambda t: np.cos(t)[..., None] * field),
    ]
    model = ep.Model(np.diag([1.0, 2.0, 2.5]), torques)
    shifted, phi = model.shifted(t_start)
    assert np.isclose(phi, 0.37 * t_start, rtol=0, atol=0)
    rz_inv = _rotation_z(-phi)
    for _ in range(4):
        s = float(rng.uniform(0, 3))
        q = _unit_quaternions(rng, ())
        w = rng.normal(size=3)
        q_turned = qmul(rz_inv, q)
        for old, new in zip(model.torques, shifted.torques):
            a = ep.Model(model.body, old).torque(t_start + s, q, w)
            b = ep.Model(model.body, new).torque(s, q_turned, w)
            np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-12, err_msg=repr(old))


# ---------------------------------------------------------------------------
# records
# ---------------------------------------------------------------------------
def _examples(rng, batch=()):
    """One torque of every registered kind (random parameters)."""
    b = batch
    return {
        "gravity": Gravity(rng.uniform(0.5, 2.0, b), rng.normal(size=b + (3,)), rng.normal(size=b + (3,))),
        "gravity_gradient": GravityGradient(rng.uniform(0.0, 2.0, b)),
        "body_torque": BodyTorque(rng.normal(size=b + (3,))),
        "space_torque": SpaceTorque(rng.normal(size=b + (3,))),
        "magnetic_dipole": MagneticDipoleTorque(rng.normal(size=b + (3,)), rng.normal(size=b + (3,))),
        "unrecorded": UnrecordedTorque("CallableTorque('f')"),
    }


def test_every_registered_kind_has_an_example_here():
    assert set(_examples(np.random.default_rng(0))) == set(TORQUES)
    assert list(TORQUES)[:5] == ["gravity", "gravity_gradient", "body_torque", "space_torque", "magnetic_dipole"]
    for kind, cls in TORQUES.items():
        assert cls.kind == kind and issubclass(cls, Torque)


@pytest.mark.parametrize("batch", [(), (2,), (2, 3)])
def test_from_dict_of_to_dict_round_trips_every_registered_torque(batch):
    import json

    rng = np.random.default_rng(len(batch))
    for kind, tq in _examples(rng, batch).items():
        rec = json.loads(json.dumps(tq.to_dict()))
        assert rec["kind"] == kind
        for back in (Torque.from_dict(rec), TORQUES[kind].from_dict(rec), ep.torques.torque_from_dict(rec)):
            assert type(back) is type(tq)
            assert back.to_dict() == tq.to_dict()
            assert repr(back) == repr(tq)
            assert back.batch_shape == tq.batch_shape


def test_from_dict_errors():
    with pytest.raises(InvalidInputError, match="must be a dict with a 'kind'"):
        Torque.from_dict({"mass": 1.0})
    with pytest.raises(InvalidInputError, match="unknown torque kind 'nope'; known: body_torque, gravity"):
        Torque.from_dict({"kind": "nope"})
    with pytest.raises(InvalidInputError, match="torque 'gravity'"):
        Torque.from_dict({"kind": "gravity", "mass": 1.0})
    with pytest.raises(InvalidInputError, match="is a BodyTorque, not a SpaceTorque"):
        SpaceTorque.from_dict({"kind": "body_torque", "tau": [0.0, 0.0, 1.0]})


def test_callable_torques_are_not_recorded():
    with pytest.raises(NotImplementedError):
        CallableTorque(_wobble).to_dict()
    with pytest.raises(NotImplementedError, match="callable field"):
        MagneticDipoleTorque([0.0, 0.0, 1.0], lambda t: [0.0, 0.0, 1.0]).to_dict()


def test_register_torque():
    class Spring(Torque):
        """tau = -k (R^T e_z) x e_z: an example."""

        kind = "test_spring"

        def __init__(self, k):
            self.k = float(k)

        def evaluate(self, t, R, omega, inertia):
            return np.zeros(np.shape(omega))

        def to_dict(self):
            return {"kind": self.kind, "k": self.k}

    try:
        assert register_torque(Spring) is Spring
        assert register_torque(Spring) is Spring  # again: fine
        back = Torque.from_dict({"kind": "test_spring", "k": 2.0})
        assert isinstance(back, Spring) and back.k == 2.0
        Other = type("Other", (Spring,), {})
        with pytest.raises(InvalidInputError, match="already Spring's"):
            register_torque(Other)
    finally:
        TORQUES.pop("test_spring", None)
    with pytest.raises(InvalidInputError, match="not a Torque subclass"):
        register_torque(int)
    with pytest.raises(InvalidInputError, match="non-empty string"):
        register_torque(type("NoKind", (Torque,), {}))


def test_describe_is_one_line():
    rng = np.random.default_rng(3)
    for tq in [*_examples(rng).values(), CallableTorque(_wobble)]:
        d = tq.describe()
        assert "\n" not in d and d.startswith(repr(tq)) and tq.summary in d
    assert _Clock().describe() == "_Clock()"


# ---------------------------------------------------------------------------
# integrals: the class hooks and the base rule
# ---------------------------------------------------------------------------
def test_integrals_of_a_mix_of_conservative_autonomous_torques_is_the_energy():
    rng = np.random.default_rng(5)
    model = ep.Model(
        [1.0, 2.0, 2.5],
        [Gravity(1.0, [0.0, 0.1, 0.2]), MagneticDipoleTorque([0.3, 0.0, 0.1], [0.0, 1.0, 2.0])],
    )
    t = np.linspace(0, 1, 5)
    q = _unit_quaternions(rng, (5,))
    w = rng.normal(size=(5, 3))
    ints = model.integrals(t, q, w)
    assert set(ints) == {"energy"}
    np.testing.assert_allclose(ints["energy"], model.energy(t, q, w), rtol=1e-14, atol=1e-14)
    # a batch of bodies
    model_b = ep.Model(ep.RigidBody([[1.0, 2.0, 2.5], [2.0, 2.0, 1.0]]), model.torques)
    qb = _unit_quaternions(rng, (2, 5))
    wb = rng.normal(size=(2, 5, 3))
    eb = model_b.integrals(t, qb, wb)["energy"]
    for i in range(2):
        np.testing.assert_allclose(eb[i], model_b.element((i,)).energy(t, qb[i], wb[i]), rtol=1e-14, atol=1e-14)
    # not all conservative or autonomous: nothing
    assert (
        model.__class__([1.0, 2.0, 2.5], [Gravity(1.0, [0, 0, 1.0]), BodyTorque([0, 0, 1.0])]).integrals(t, q, w) == {}
    )
    assert ep.Model([1.0, 2.0, 2.5], [Gravity(1.0, [0, 0, 1.0]), GravityGradient(0.1)]).integrals(t, q, w) == {}


def test_integrals_hook_of_a_user_torque_class():
    class Pinned(Torque):
        kind = "test_pinned"

        def evaluate(self, t, R, omega, inertia):
            return np.zeros(np.shape(omega))

        @classmethod
        def integrals(cls, model, torques, ctx):
            return {"m_z": ctx.m[..., 2], "n": np.full(ctx.kinetic.shape, float(len(torques)))}

    rng = np.random.default_rng(9)
    t = np.linspace(0, 1, 4)
    q = _unit_quaternions(rng, (4,))
    w = rng.normal(size=(4, 3))
    ints = ep.Model([1.0, 2.0, 2.5], [Pinned(), Pinned()]).integrals(t, q, w)
    free = ep.Model([1.0, 2.0, 2.5]).integrals(t, q, w)
    assert set(ints) == {"m_z", "n"} and np.array_equal(ints["m_z"], free["m_z"]) and np.all(ints["n"] == 2)


# ---------------------------------------------------------------------------
# the command line's description
# ---------------------------------------------------------------------------
#: what ``simulate`` has today (cli/commands.py: _FLAGS, _TOML_KINDS["torque"], the argparse metavars)
CLI_TODAY = {
    ("gravity", "center_of_mass"): ("--com", "center_of_mass", "numbers", "CX,CY,CZ"),
    ("gravity", "mass"): ("--mass", "mass", "number", "M"),
    ("gravity", "g"): ("--gravity", "gravity", "numbers", "GX,GY,GZ"),
    ("gravity_gradient", "mean_motion"): ("--gravity-gradient", "gravity_gradient", "number", "NU"),
    ("body_torque", "tau"): ("--body-torque", "body_torque", "numbers", "TX,TY,TZ"),
    ("space_torque", "tau"): ("--space-torque", "space_torque", "numbers", "TX,TY,TZ"),
    ("magnetic_dipole", "dipole"): ("--magnetic-dipole", "magnetic_dipole", "numbers", "MX,MY,MZ"),
    ("magnetic_dipole", "field"): ("--magnetic-field", "magnetic_field", "numbers", "BX,BY,BZ"),
}


def test_cli_descriptions_carry_the_flags_and_keys_of_simulate():
    got = {
        (kind, p.name): (p.flag, p.toml_key, p.toml_kind, p.metavar) for kind, cls in TORQUES.items() for p in cls.cli
    }
    assert got == CLI_TODAY
    g = {p.name: p for p in Gravity.cli}
    assert g["center_of_mass"].required and not g["mass"].required and not g["g"].required
    assert g["mass"].default == 1.0 and g["g"].default == (0.0, 0.0, -ep.torques.STANDARD_GRAVITY)
    assert g["mass"].kind == "positive" and GravityGradient.cli[0].kind == "number"
    for cls in TORQUES.values():
        for p in cls.cli:
            assert isinstance(p, TorqueParam) and p.help and p.units
            # the record's field is the parameter's name (fingerprints map records back to flags by it)
    for kind, tq in _examples(np.random.default_rng(1)).items():
        names = {p.name for p in TORQUES[kind].cli}
        assert names <= set(tq.to_dict()) - {"kind"}


def _values(cls, rng):
    out = {}
    for p in cls.cli:
        if p.kind == "vector3":
            out[p.name] = rng.normal(size=3).tolist()
        else:
            out[p.name] = float(rng.uniform(0.1, 2.0))
    return out


def test_from_params_builds_every_registered_torque_with_a_description():
    rng = np.random.default_rng(2)
    for cls in TORQUES.values():
        if not cls.cli:
            with pytest.raises(InvalidInputError, match="no command-line parameters"):
                cls.from_params({})
            continue
        values = _values(cls, rng)
        tq = cls.from_params(values)
        assert type(tq) is cls
        assert tq.to_dict() == cls(**values).to_dict()
        # by TOML key as well
        by_toml = {p.toml_key: values[p.name] for p in cls.cli}
        assert cls.from_params(by_toml).to_dict() == tq.to_dict()
        # defaults fill what is left out; required parameters must be given
        for p in cls.cli:
            rest = {k: v for k, v in values.items() if k != p.name}
            if p.required:
                with pytest.raises(InvalidInputError, match=f"needs {p.name}: {p.flag} {p.metavar} or"):
                    cls.from_params(rest)
            else:
                rec = cls.from_params(rest).to_dict()
                default = list(p.default) if isinstance(p.default, tuple) else p.default
                assert rec[p.name] == default


def test_from_params_errors_name_the_flag():
    with pytest.raises(InvalidInputError, match=r"mass \(--mass or \[torque\] mass\) must be a finite number > 0"):
        Gravity.from_params({"center_of_mass": [0, 0, 1.0], "mass": 0.0})
    with pytest.raises(InvalidInputError, match=r"--gravity-gradient.*>= 0"):
        GravityGradient.from_params({"mean_motion": -1.0})
    with pytest.raises(InvalidInputError, match=r"--gravity-gradient.*must be a number"):
        GravityGradient.from_params({"mean_motion": True})
    with pytest.raises(InvalidInputError, match=r"--body-torque"):
        BodyTorque.from_params({"tau": [1.0, 2.0]})
    with pytest.raises(InvalidInputError, match=r"--magnetic-field"):
        MagneticDipoleTorque.from_params({"dipole": [0, 0, 1.0], "field": [np.nan, 0, 0]})
    with pytest.raises(InvalidInputError, match="unknown parameter"):
        SpaceTorque.from_params({"torque": [1.0, 2.0, 3.0]})
    with pytest.raises(InvalidInputError, match="given twice"):
        SpaceTorque.from_params({"tau": [1.0, 2.0, 3.0], "space_torque": [1.0, 2.0, 3.0]})
    with pytest.raises(InvalidInputError, match="needs center_of_mass: --com CX,CY,CZ or"):
        Gravity.from_params({"mass": 2.0})
