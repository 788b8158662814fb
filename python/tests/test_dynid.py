"""Tests of the dynid Python module (issue 15 item 4). Oracles: the closed-form planar 2R arm
(written out here in NumPy), NumPy's own rank, and identification from torques of that closed
form with noise, the truth inside the predicted intervals."""
import os

import numpy as np
import pytest

import dynid

# examples/robots/planar2.yaml: gravity -9.81 along y, link lengths 1.0, centres of mass on x.
M1, LC1, I1 = 2.0, 0.5, 1.0 / 6.0
M2, LC2, I2 = 1.5, 0.4, 0.08
L1, G = 1.0, 9.81


def planar2_torques(q, dq, ddq, m2=M2, lc2=LC2, i2=I2, m1=M1, lc1=LC1, i1=I1):
    """Closed-form inverse dynamics of the planar 2R arm (Spong, Hutchinson, Vidyasagar ch. 7);
    m2, lc2, i2 (m1, lc1, i1): the forearm's (upper arm's) mass, centre of mass on its x axis and
    inertia about it."""
    c2, s2 = np.cos(q[:, 1]), np.sin(q[:, 1])
    m11 = i1 + m1 * lc1**2 + i2 + m2 * (L1**2 + lc2**2 + 2 * L1 * lc2 * c2)
    m12 = i2 + m2 * (lc2**2 + L1 * lc2 * c2)
    m22 = i2 + m2 * lc2**2
    h = m2 * L1 * lc2 * s2
    g1 = (m1 * lc1 + m2 * L1) * G * np.cos(q[:, 0]) + m2 * lc2 * G * np.cos(q[:, 0] + q[:, 1])
    g2 = m2 * lc2 * G * np.cos(q[:, 0] + q[:, 1])
    tau1 = m11 * ddq[:, 0] + m12 * ddq[:, 1] - h * (2 * dq[:, 0] * dq[:, 1] + dq[:, 1] ** 2) + g1
    tau2 = m12 * ddq[:, 0] + m22 * ddq[:, 1] + h * dq[:, 0] ** 2 + g2
    return np.column_stack([tau1, tau2])


def fourier_run(seed, samples=1500, rate=100.0):
    rng = np.random.default_rng(seed)
    t = np.arange(samples) / rate
    a = rng.uniform(0.3, 0.8, size=(3, 2))
    w = 2 * np.pi * np.array([0.2, 0.45, 0.7])
    q = sum(a[k] * np.sin(w[k] * t)[:, None] for k in range(3))
    dq = sum(a[k] * w[k] * np.cos(w[k] * t)[:, None] for k in range(3))
    ddq = sum(-a[k] * w[k] ** 2 * np.sin(w[k] * t)[:, None] for k in range(3))
    return t, q, dq, ddq


@pytest.fixture(scope="module")
def planar2():
    return dynid.load_model("planar2")


def test_model_properties(planar2):
    assert planar2.dof == 2
    assert planar2.joint_names == ["shoulder", "elbow"]
    assert planar2.standard_parameter_names[:3] == ["XX1", "XY1", "XZ1"]
    assert planar2.summary()["name"] == "planar2"
    assert "planar2" in repr(planar2)


def test_inverse_dynamics_matches_the_closed_form(planar2):
    rng = np.random.default_rng(1)
    q, dq, ddq = (rng.uniform(-2, 2, size=(50, 2)) for _ in range(3))
    tau = dynid.inverse_dynamics(planar2, q, dq, ddq)
    assert tau.shape == (50, 2)
    np.testing.assert_allclose(tau, planar2_torques(q, dq, ddq), rtol=1e-12, atol=1e-12)


def test_regressor_times_standard_parameters_is_the_inverse_dynamics(planar2):
    rng = np.random.default_rng(2)
    q, dq, ddq = (rng.uniform(-2, 2, size=(20, 2)) for _ in range(3))
    y, names = dynid.regressor(planar2, q, dq, ddq, armature=False, viscous=False,
                               coulomb=False, offset=False)
    assert y.shape == (40, 20) and names == planar2.standard_parameter_names
    tau = (y @ planar2.standard_parameters).reshape(20, 2)  # sample-major rows
    np.testing.assert_allclose(tau, planar2_torques(q, dq, ddq), rtol=1e-12, atol=1e-12)


def test_base_parameter_rank_is_the_rank_of_the_sampled_regressor(planar2):
    base = dynid.base_parameters(planar2, armature=False, viscous=False, coulomb=False,
                                 offset=False)
    rng = np.random.default_rng(3)
    q, dq, ddq = (rng.uniform(-3, 3, size=(200, 2)) for _ in range(3))
    y, _ = dynid.regressor(planar2, q, dq, ddq, armature=False, viscous=False, coulomb=False,
                           offset=False)
    assert base["rank"] == np.linalg.matrix_rank(y) == len(base["base_parameters"])
    # W theta = W_1 (theta_1 + K_d theta_2)
    theta = planar2.standard_parameters
    theta_b = theta[base["base_indices"]] + base["K_d"] @ theta[base["dependent_indices"]]
    np.testing.assert_allclose(y[:, base["base_indices"]] @ theta_b, y @ theta, atol=1e-10)


def test_identify_recovers_the_closed_form_arm_within_its_intervals(planar2):
    t, q, dq, ddq = fourier_run(4)
    rng = np.random.default_rng(5)
    tau = planar2_torques(q, dq, ddq) + rng.normal(0.0, 0.05, size=q.shape)
    options = dict(armature=False, viscous=False, coulomb=False, offset=False, filter=False)
    result = dynid.identify(planar2, t, q, tau, dq=dq, ddq=ddq, **options)
    base = dynid.base_parameters(planar2, armature=False, viscous=False, coulomb=False,
                                 offset=False)
    theta = planar2.standard_parameters
    truth = theta[base["base_indices"]] + base["K_d"] @ theta[base["dependent_indices"]]
    names = [p["name"] for p in base["base_parameters"]]
    assert [p["name"] for p in result["parameters"]] == names
    for p, x in zip(result["parameters"], truth):
        assert p["ci_low"] <= x <= p["ci_high"], (p, x)
    assert result["model"]["name"] == "planar2" and result["condition_number"] > 1.0

    t2, q2, dq2, ddq2 = fourier_run(6)
    tau2 = planar2_torques(q2, dq2, ddq2) + rng.normal(0.0, 0.05, size=q2.shape)
    v = dynid.validate(planar2, result, t2, q2, tau2, dq=dq2, ddq=ddq2, **options)
    assert 0.0 < v["relative_error"] < 0.05


def test_time_shift_is_stored_and_validate_applies_it(planar2):
    # identify's --time-shift (issue 26 item 7): stored as the command line stores it, and a
    # validate() of the stored result shifts the other run alike. Oracle: the closed-form torques
    # delayed by half a sample and shifted back are the closed-form torques again (to the
    # interpolation error), so the shifted fit predicts them better than the unshifted one.
    t, q, dq, ddq = fourier_run(4)
    dt = t[1] - t[0]
    tau = planar2_torques(q, dq, ddq)
    delayed = np.vstack([tau[:1], 0.5 * (tau[1:] + tau[:-1])])  # tau(t - dt/2), linear
    options = dict(armature=False, viscous=False, coulomb=False, offset=False, filter=False)
    shifted = dynid.identify(planar2, t, q, delayed, dq=dq, ddq=ddq, time_shift=-dt / 2, **options)
    plain = dynid.identify(planar2, t, q, delayed, dq=dq, ddq=ddq, **options)
    assert shifted["options"]["time_shift_s"] == pytest.approx(-dt / 2)
    assert plain["options"]["time_shift_s"] == 0.0
    assert shifted["relative_error"] < 0.5 * plain["relative_error"]
    v = dynid.validate(planar2, shifted, t, q, delayed, dq=dq, ddq=ddq)
    assert v["relative_error_moving"] == v["relative_error"]
    assert v["relative_error_all_rows"] < 0.5 * dynid.validate(
        planar2, plain, t, q, delayed, dq=dq, ddq=ddq)["relative_error_all_rows"]


def test_bad_input_raises_with_a_message(planar2):
    z = np.zeros((5, 3))
    with pytest.raises(dynid.Error, match="q must be 5 x 2"):
        dynid.inverse_dynamics(planar2, z, z, z)
    with pytest.raises(TypeError, match="valid options are armature"):
        dynid.identify(planar2, np.arange(5.0), np.zeros((5, 2)), np.zeros((5, 2)), speed=1)
    with pytest.raises(dynid.Error, match="unknown robot|puma999"):
        dynid.load_model("puma999")
    nan = np.full((1, 2), np.nan)
    with pytest.raises(dynid.Error, match="NaN"):
        dynid.inverse_dynamics(planar2, nan, nan, nan)


def test_malformed_results_and_non_finite_arrays_raise_dynid_error(planar2):
    """Issue 27 item 5: a result dict with NaN, or a value of the wrong type, raised a raw
    [json.exception...] error; a NaN time stamp or one corrupt sample reached the fit."""
    t, q, dq, ddq = fourier_run(4)
    tau = planar2_torques(q, dq, ddq)
    options = dict(armature=False, viscous=False, coulomb=False, offset=False, filter=False)
    result = dynid.identify(planar2, t, q, tau, dq=dq, ddq=ddq, **options)
    bad = dict(result, parameters=[dict(p, value=float("nan")) for p in result["parameters"]])
    with pytest.raises(dynid.Error, match="finite numbers") as e:
        dynid.validate(planar2, bad, t, q, tau, dq=dq, ddq=ddq)
    assert "json.exception" not in str(e.value)
    typed = dict(result, parameters=[dict(p, value="one") for p in result["parameters"]])
    with pytest.raises(dynid.Error) as e:
        dynid.validate(planar2, typed, t, q, tau, dq=dq, ddq=ddq)
    assert "json.exception" not in str(e.value)
    t_nan = t.copy()
    t_nan[10] = np.nan
    with pytest.raises(dynid.Error, match="t contains NaN"):
        dynid.identify(planar2, t_nan, q, tau, dq=dq, ddq=ddq, **options)
    # A NaN cut-off silently became the automatic one.
    with pytest.raises(dynid.Error, match="cutoff_hz"):
        dynid.identify(planar2, t, q, tau, dq=dq, ddq=ddq, cutoff_hz=float("nan"))
    corrupt = tau.copy()
    corrupt[523, 1] = 1e200
    with pytest.raises(dynid.Error, match="tau2 at sample 524"):
        dynid.identify(planar2, t, q, corrupt, dq=dq, ddq=ddq, **options)


def test_recursive_payload_reports_its_residual_and_what_planar_motion_leaves_undetermined(
        planar2):
    """Issue 27 item 3: estimator='rls' reported relative error 0 and the inertias planar motion
    cannot excite (about z only: Ixx, Iyy, Ixy) as 0 +- 0. Oracle: the physics of a planar arm
    and the wrench noise of 0.05 added here."""
    t, q, dq, ddq = fourier_run(8, samples=2000)
    m, c = 0.8, np.array([0.05, -0.02, 0.03])
    rng = np.random.default_rng(9)
    wrench = sensor_wrench(q, dq, ddq, m, c, np.diag([2e-3, 3e-3, 4e-3]))
    wrench += rng.normal(0.0, 0.05, size=(len(t), 6))
    result = dynid.payload(planar2, "forearm", t, q, wrench, dq=dq, ddq=ddq, filter=False,
                           estimator="rls")
    assert 0.0 < result["relative_error"] < 0.05
    assert {"Ixx", "Iyy", "Ixy"} <= set(result["not_excited"])
    values = {p["name"]: p for p in result["parameters"]}
    for name in ("Ixx", "Iyy", "Ixy"):
        assert values[name]["value"] is None and values[name]["std"] is None, values[name]


def sensor_wrench(q, dq, ddq, m, c, inertia_c):
    """Force and moment a rigid load exerts on a sensor in the forearm frame of planar2, by
    Newton-Euler of the load itself (not dynid's load regressor): f = m (g - a_c),
    n = -(I_c w' + w x I_c w) + c x f, all in the sensor frame (MDH: elbow at (cos q1, sin q1),
    frame rotated by q1 + q2 about z)."""
    th = q[:, 0] + q[:, 1]
    a_elbow = np.column_stack([-np.sin(q[:, 0]) * ddq[:, 0] - np.cos(q[:, 0]) * dq[:, 0] ** 2,
                               np.cos(q[:, 0]) * ddq[:, 0] - np.sin(q[:, 0]) * dq[:, 0] ** 2,
                               np.zeros(len(q))])
    out = np.zeros((len(q), 6))
    for k in range(len(q)):
        ct, st = np.cos(th[k]), np.sin(th[k])
        r = np.array([[ct, -st, 0.0], [st, ct, 0.0], [0.0, 0.0, 1.0]])  # sensor in world
        w = np.array([0.0, 0.0, dq[k, 0] + dq[k, 1]])
        dw = np.array([0.0, 0.0, ddq[k, 0] + ddq[k, 1]])
        a_c = r.T @ a_elbow[k] + np.cross(dw, c) + np.cross(w, np.cross(w, c))
        g = r.T @ np.array([0.0, -G, 0.0])
        f = m * (g - a_c)
        n = -(inertia_c @ dw + np.cross(w, inertia_c @ w)) + np.cross(c, f)
        out[k] = np.concatenate([f, n])
    return out


def test_payload_recovers_a_load_on_the_forearm_within_its_intervals(planar2):
    t, q, dq, ddq = fourier_run(8, samples=2000)
    m, c = 0.8, np.array([0.05, -0.02, 0.03])
    inertia_c = np.diag([2e-3, 3e-3, 4e-3])
    rng = np.random.default_rng(9)
    wrench = sensor_wrench(q, dq, ddq, m, c, inertia_c) + rng.normal(0.0, 0.05, size=(len(t), 6))
    result = dynid.payload(planar2, "forearm", t, q, wrench, dq=dq, ddq=ddq, filter=False)
    # The keys of `dynid payload`'s JSON (payload_to_json, shared with the command line).
    for key in ("command", "model", "frame", "parameters", "mass", "com", "inertia_com",
                "physically_consistent", "not_excited", "residual_rms", "condition_number",
                "residual_rms_per_component", "choices", "version"):
        assert key in result, key
    assert result["command"] == "payload" and result["frame"]["sensor_link"] == "forearm"
    # Inertias about the sensor origin: I_O = I_c + m (|c|^2 1 - c c^T) (parallel axes).
    inertia_o = inertia_c + m * (c @ c * np.eye(3) - np.outer(c, c))
    truth = {"m": m, "mcx": m * c[0], "mcy": m * c[1], "mcz": m * c[2], "Ixz": inertia_o[0, 2],
             "Iyz": inertia_o[1, 2], "Izz": inertia_o[2, 2]}
    values = {p["name"]: p for p in result["parameters"]}
    for name, x in truth.items():
        assert values[name]["ci_low"] <= x <= values[name]["ci_high"], (values[name], x)
    # Planar motion turns the load about z only: Ixx, Iyy and the products are not all excited.
    assert sorted(result["not_excited"]) == ["Ixx", "Ixy", "Iyy"]
    # The force equations alone (dynid payload --components): the mass and the in-plane centre
    # of mass, every inertia and mcz named not excited.
    forces = dynid.payload(planar2, "forearm", t, q, wrench, dq=dq, ddq=ddq, filter=False,
                           components="fx,fy,fz")
    assert forces["components"] == ["fx", "fy", "fz"]
    values = {p["name"]: p for p in forces["parameters"]}
    for name in ("m", "mcx", "mcy"):
        assert values[name]["ci_low"] <= truth[name] <= values[name]["ci_high"], values[name]
    assert sorted(forces["not_excited"]) == ["Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz", "mcz"]
    with pytest.raises(dynid.Error, match="not a wrench component"):
        dynid.payload(planar2, "forearm", t, q, wrench, components="fx,torque")
    with pytest.raises(TypeError, match="valid options are sensor_pose"):
        dynid.payload(planar2, "forearm", t, q, wrench, speed=1)
    with pytest.raises(dynid.Error, match="wrench must be"):
        dynid.payload(planar2, "forearm", t, q, wrench[:, :5])


MODELS = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "models")


def merged(parts):
    """(mass, centre of mass on x, inertia about it) of planar parts (m, x, izz about their own
    centre of mass), by the parallel-axis theorem about z."""
    m = sum(p[0] for p in parts)
    lc = sum(p[0] * p[1] for p in parts) / m
    zz = sum(p[2] + p[0] * p[1] ** 2 for p in parts)
    return m, lc, zz - m * lc**2


def test_load_model_locks_the_joints_a_log_lacks():
    """Issue 26 item 1: planar2_gripper.urdf with the finger held at 0.05 m and the camera pan at
    pi is the planar arm whose links carry them (summed here by hand)."""
    robot = os.path.join(MODELS, "planar2_gripper.yaml")
    m = dynid.load_model(robot, joints=["shoulder", "elbow"],
                         lock={"finger": 0.05, "camera_pan": np.pi})
    assert m.dof == 2 and m.joint_names == ["shoulder", "elbow"]
    assert m.locked_joints == {"finger": 0.05, "camera_pan": np.pi}
    m1, lc1, i1 = merged([(2.0, 0.5, 1.0 / 6.0), (0.4, 0.5 + 0.1 * np.cos(np.pi), 0.002)])
    m2, lc2, i2 = merged([(1.5, 0.4, 0.08), (0.3, 0.85, 0.0005)])
    rng = np.random.default_rng(26)
    q, dq, ddq = (rng.uniform(-2, 2, size=(40, 2)) for _ in range(3))
    np.testing.assert_allclose(
        dynid.inverse_dynamics(m, q, dq, ddq),
        planar2_torques(q, dq, ddq, m2=m2, lc2=lc2, i2=i2, m1=m1, lc1=lc1, i1=i1),
        rtol=1e-10, atol=1e-10)
    t, q, dq, ddq = fourier_run(7)
    tau = planar2_torques(q, dq, ddq, m2=m2, lc2=lc2, i2=i2, m1=m1, lc1=lc1, i1=i1)
    result = dynid.identify(m, t, q, tau, dq=dq, ddq=ddq, armature=False, viscous=False,
                            coulomb=False, offset=False, filter=False)
    assert result["locked_joints"] == [{"name": "finger", "value": 0.05},
                                       {"name": "camera_pan", "value": np.pi}]
    with pytest.raises(dynid.Error, match="joint 'gripper' is not a moving joint"):
        dynid.load_model(robot, joints=["shoulder", "gripper"])


def test_load_model_warns_of_a_vendor_inertia_and_refuses_it_when_strict():
    """Issue 26 item 4: a 2.9 % triangle-inequality violation is a UserWarning naming the link;
    strict=True refuses it."""
    path = os.path.join(MODELS, "vendor_triangle.urdf")
    with pytest.warns(UserWarning, match="link 'wrist' has a non-physical inertia"):
        assert dynid.load_model(path).dof == 2
    with pytest.raises(dynid.Error, match="link 'wrist'"):
        dynid.load_model(path, strict=True)


def test_nominal_and_lockstep_facts_of_the_data(planar2):
    # issue 26 item 5: each base parameter carries the nominal model's value (the NumPy oracle:
    # theta_1 + K_d theta_2 of the model's own parameters; None where the model has no friction),
    # and an elbow that follows the shoulder is named as lockstep with what it leaves undetermined.
    t, q, dq, ddq = fourier_run(4)
    options = dict(armature=False, viscous=True, coulomb=False, offset=False, filter=False)
    result = dynid.identify(planar2, t, q, planar2_torques(q, dq, ddq), dq=dq, ddq=ddq, **options)
    base = dynid.base_parameters(planar2, armature=False, viscous=True, coulomb=False,
                                 offset=False)
    theta = np.concatenate([planar2.standard_parameters,
                            np.zeros(len(base["layout_names"]) - 20)])
    nominal = theta[base["base_indices"]] + base["K_d"] @ theta[base["dependent_indices"]]
    for p, x, b in zip(result["parameters"], nominal, base["base_parameters"]):
        assert p["name"] == b["name"]
        if p["name"].startswith("Fv"):
            assert p["nominal"] is None
        else:
            assert p["nominal"] == pytest.approx(x, rel=1e-12, abs=1e-12)
    assert result["lockstep"] == []

    q2 = np.column_stack([q[:, 0], 0.6 * q[:, 0] + 0.2])
    dq2 = np.column_stack([dq[:, 0], 0.6 * dq[:, 0]])
    ddq2 = np.column_stack([ddq[:, 0], 0.6 * ddq[:, 0]])
    locked = dynid.identify(planar2, t, q2, planar2_torques(q2, dq2, ddq2), dq=dq2, ddq=ddq2,
                            **options)
    assert len(locked["lockstep"]) == 1
    assert locked["lockstep"][0]["joints"] == ["shoulder", "elbow"]
    assert locked["lockstep"][0]["correlation"] == pytest.approx(1.0, abs=1e-9)
    assert any("move in lockstep" in w for w in locked["warnings"])
