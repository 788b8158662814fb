"""The Python module against the command line (issue 15 item 4): each mode of `dynid payload`,
`validate` and `identify --physical` give the same dict as the command's JSON on the same data
(the command line reads a CSV and parses its flags, an independent path through the argument
handling), and the load is recovered inside its intervals from data made here in NumPy by the
Newton-Euler equations of the load, or by the closed-form planar 2R arm, not by dynid's load
regressor."""
import json
import os
import subprocess

import numpy as np
import pytest

import dynid
from test_dynid import G, I2, LC2, M2, fourier_run, planar2_torques, sensor_wrench

MASS, COM = 0.8, np.array([0.05, -0.02, 0.03])
INERTIA_COM = np.array([[2e-3, 1e-4, 0.0], [1e-4, 3e-3, -2e-4], [0.0, -2e-4, 4e-3]])
BIAS = np.array([0.3, -0.2, 0.5, 0.02, -0.01, 0.03])


def binary():
    """The dynid executable beside the module's folder (build/dynid), or $DYNID_BINARY."""
    return os.environ.get("DYNID_BINARY",
                          os.path.join(os.path.dirname(dynid.__file__), os.pardir, "dynid"))


def cli(tmp_path, columns, data, *flags):
    """Writes `data` as CSV (17 significant digits: the same doubles as the arrays) and returns
    the JSON of `dynid payload --data it --out ... flags`."""
    csv, out = tmp_path / "data.csv", tmp_path / "out.json"
    np.savetxt(csv, data, delimiter=",", header=",".join(columns), comments="", fmt="%.17g")
    run = subprocess.run([binary(), "payload", "--data", str(csv), "--out", str(out), *flags],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    return json.loads(out.read_text())


def assert_same(py, cl, path="", skip=()):
    """The two results hold the same keys and values (numbers to 1e-9 relative)."""
    if isinstance(cl, dict):
        assert isinstance(py, dict) and set(py) == set(cl), (path, set(py) ^ set(cl))
        for key in cl:
            if key not in skip:
                assert_same(py[key], cl[key], path + "." + key)
    elif isinstance(cl, list):
        assert isinstance(py, list) and len(py) == len(cl), path
        for i, (a, b) in enumerate(zip(py, cl)):
            assert_same(a, b, f"{path}[{i}]")
    elif isinstance(cl, float) and not isinstance(py, bool):
        assert py == pytest.approx(cl, rel=1e-9, abs=1e-12), path
    else:
        assert py == cl, path


def truth_about_origin(m, c, inertia_c):
    """Load parameters about the sensor/link origin (parallel axes)."""
    i_o = inertia_c + m * (c @ c * np.eye(3) - np.outer(c, c))
    return {"m": m, "mcx": m * c[0], "mcy": m * c[1], "mcz": m * c[2], "Ixx": i_o[0, 0],
            "Ixy": i_o[0, 1], "Ixz": i_o[0, 2], "Iyy": i_o[1, 1], "Iyz": i_o[1, 2],
            "Izz": i_o[2, 2]}


def assert_inside(result, truth):
    values = {p["name"]: p for p in result["parameters"]}
    for name, x in truth.items():
        assert values[name]["ci_low"] <= x <= values[name]["ci_high"], (values[name], x)


def rotation(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    if axis == 0:
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == 1:
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def quaternion_product(a, b):
    """(x, y, z, w) quaternions: a * b."""
    av, aw, bv, bw = a[:3], a[3], b[:3], b[3]
    return np.concatenate([aw * bv + bw * av + np.cross(av, bv), [aw * bw - av @ bv]])


def turning_sensor(samples=1500, rate=100.0):
    """A sensor turning about its fixed origin, R = Rz(al) Ry(be) Rx(ga) with smooth angles:
    t, the (x, y, z, w) quaternion, and the angular velocity and acceleration in the sensor frame
    (body rates of the Z-Y-X angles and their derivative, written out here)."""
    t = np.arange(samples) / rate
    amp, freq = np.array([1.2, 0.6, 0.9]), 2 * np.pi * np.array([0.13, 0.21, 0.17])
    ang = amp * np.sin(freq * t[:, None])
    d_ang = amp * freq * np.cos(freq * t[:, None])
    dd_ang = -amp * freq**2 * np.sin(freq * t[:, None])
    ex, ey, ez = np.eye(3)
    quat, w, dw, rot = (np.zeros((samples, k)) for k in (4, 3, 3, 9))
    for k in range(samples):
        al, be, ga = ang[k]
        dal, dbe, dga = d_ang[k]
        ddal, ddbe, ddga = dd_ang[k]
        rx, ry = rotation(0, ga), rotation(1, be)
        inner = ry.T @ ez * dal + ey * dbe
        w[k] = rx.T @ inner + ex * dga
        d_inner = -np.cross(ey, ry.T @ ez) * dbe * dal + ry.T @ ez * ddal + ey * ddbe
        dw[k] = -np.cross(ex, rx.T @ inner) * dga + rx.T @ d_inner + ex * ddga
        halves = [(2, al), (1, be), (0, ga)]
        q = np.array([0.0, 0.0, 0.0, 1.0])
        for axis, angle in halves:
            e = np.zeros(3)
            e[axis] = np.sin(angle / 2)
            q = quaternion_product(q, np.concatenate([e, [np.cos(angle / 2)]]))
        quat[k] = q
        rot[k] = (rotation(2, al) @ ry @ rx).ravel()
    return t, quat, w, dw, rot.reshape(samples, 3, 3)


def turning_wrench(w, dw, rot, m, c, inertia_c, gravity=(0.0, 0.0, -G)):
    """Newton-Euler of the load on a sensor turning about its origin (sensor frame):
    f = m (g - a_c), a_c = dw x c + w x (w x c); n = -(I_c dw + w x I_c w) + c x f."""
    out = np.zeros((len(w), 6))
    for k in range(len(w)):
        a_c = np.cross(dw[k], c) + np.cross(w[k], np.cross(w[k], c))
        f = m * (rot[k].T @ np.array(gravity) - a_c)
        n = -(inertia_c @ dw[k] + np.cross(w[k], inertia_c @ w[k])) + np.cross(c, f)
        out[k] = np.concatenate([f, n])
    return out


WRENCH = ["fx", "fy", "fz", "mx", "my", "mz"]


def test_the_turning_sensor_kinematics_match_finite_differences():
    """Oracle of the oracle: w and dw above against differences of R and of w."""
    t, _, w, dw, rot = turning_sensor(samples=400, rate=1000.0)
    h = t[1] - t[0]
    for k in (50, 200, 350):
        skew = rot[k].T @ (rot[k + 1] - rot[k - 1]) / (2 * h)
        np.testing.assert_allclose([skew[2, 1], skew[0, 2], skew[1, 0]], w[k], atol=1e-5)
        np.testing.assert_allclose((w[k + 1] - w[k - 1]) / (2 * h), dw[k], atol=1e-4)


def test_orientation_log_with_biases_recovers_the_load_as_the_command_line(tmp_path):
    t, quat, w, dw, rot = turning_sensor()
    rng = np.random.default_rng(11)
    wrench = turning_wrench(w, dw, rot, MASS, COM, INERTIA_COM) + BIAS
    wrench += rng.normal(0.0, [0.05, 0.05, 0.05, 0.002, 0.002, 0.002], size=wrench.shape)
    result = dynid.payload_from_orientation(t, quat, wrench, w=w, dw=dw, bias=True,
                                            estimator="wls")
    truth = truth_about_origin(MASS, COM, INERTIA_COM)
    truth.update(dict(zip(["fx0", "fy0", "fz0", "mx0", "my0", "mz0"], BIAS)))
    assert_inside(result, truth)
    assert result["physically_consistent"] and result["not_excited"] == []
    columns = ["t", "qx", "qy", "qz", "qw", "wx", "wy", "wz", "dwx", "dwy", "dwz"] + WRENCH
    expected = cli(tmp_path, columns, np.column_stack([t, quat, w, dw, wrench]), "--bias",
                   "--estimator", "wls")
    assert_same(result, expected)


def test_orientation_log_integral_and_static_models_as_the_command_line(tmp_path):
    t, quat, w, dw, rot = turning_sensor(samples=1000)
    rng = np.random.default_rng(12)
    # Integral model: w given, no accelerations used; a non-default gravity along -y.
    wrench = turning_wrench(w, dw, rot, MASS, COM, INERTIA_COM, gravity=(0.0, -G, 0.0))
    wrench += rng.normal(0.0, 0.01, size=wrench.shape)
    result = dynid.payload_from_orientation(t, quat, wrench, w=w, equations="integral",
                                            interval=0.1, gravity=[0.0, -G, 0.0])
    expected = cli(tmp_path, ["t", "qx", "qy", "qz", "qw", "wx", "wy", "wz"] + WRENCH,
                   np.column_stack([t, quat, w, wrench]), "--model", "integral", "--interval",
                   "0.1", "--gravity", f"0 {-G} 0")
    assert_same(result, expected)
    assert result["model"] == "integral" and result["interval"] == 0.1
    assert_inside(result, truth_about_origin(MASS, COM, INERTIA_COM))
    # Standing poses: every 100th sample held still (its wrench the load's weight only).
    poses = slice(0, None, 100)
    still = np.array([np.concatenate([MASS * r.T @ [0, 0, -G], np.cross(COM, MASS * r.T @
                                                                          [0, 0, -G])])
                      for r in rot[poses]]) + rng.normal(0.0, 0.01, size=(10, 6))
    standing = dynid.payload_from_orientation(None, quat[poses], still, equations="static")
    assert standing["inertia_com"] is None
    assert_inside(standing, {k: v for k, v in truth_about_origin(MASS, COM, INERTIA_COM).items()
                             if k in ("m", "mcx", "mcy", "mcz")})
    expected = cli(tmp_path, ["qx", "qy", "qz", "qw"] + WRENCH,
                   np.column_stack([quat[poses], still]), "--static")
    assert_same(standing, expected)


def test_robot_sensor_pose_integral_bias_and_static_as_the_command_line(tmp_path):
    planar2 = dynid.load_model("planar2")
    t, q, dq, ddq = fourier_run(13, samples=1200)
    rng = np.random.default_rng(14)
    wrench = sensor_wrench(q, dq, ddq, MASS, COM, INERTIA_COM) + BIAS
    wrench += rng.normal(0.0, 0.05, size=wrench.shape)
    # The sensor pose only moves the frame the load is reported in; the two paths must agree.
    pose = [0.01, 0.02, 0.0, 0.0, 0.0, 0.1]
    result = dynid.payload(planar2, "forearm", t, q, wrench, dq=dq, ddq=ddq, equations="integral",
                           bias=True, sensor_pose=pose, filter=False)
    columns = ["t", "q1", "q2", "dq1", "dq2", "ddq1", "ddq2"] + WRENCH
    expected = cli(tmp_path, columns, np.column_stack([t, q, dq, ddq, wrench]), "--robot",
                   "planar2", "--sensor-link", "forearm", "--sensor-pose",
                   " ".join(map(str, pose)), "--model", "integral", "--bias", "--no-filter")
    assert_same(result, expected)
    # Filtered (automatic cut-off) differential model: the same processing on both paths.
    result = dynid.payload(planar2, "forearm", t, q, wrench, bias=True)
    expected = cli(tmp_path, ["t", "q1", "q2"] + WRENCH, np.column_stack([t, q, wrench]),
                   "--robot", "planar2", "--sensor-link", "forearm", "--bias")
    assert_same(result, expected)
    standing = dynid.payload(planar2, "forearm", None, q[::60], wrench[::60], equations="static")
    expected = cli(tmp_path, ["q1", "q2"] + WRENCH, np.column_stack([q[::60], wrench[::60]]),
                   "--robot", "planar2", "--sensor-link", "forearm", "--static")
    assert_same(standing, expected)


def loaded_planar2(q, dq, ddq, m, x):
    """The closed-form planar 2R arm carrying a point mass m at x on the forearm's x axis (the
    forearm's mass, centre of mass and inertia changed by it): torques and the load's ten
    parameters about the forearm frame's origin."""
    m2 = M2 + m
    lc2 = (M2 * LC2 + m * x) / m2
    i2 = I2 + M2 * (LC2 - lc2) ** 2 + m * (x - lc2) ** 2  # about the new centre of mass
    c = np.array([x, 0.0, 0.0])
    return planar2_torques(q, dq, ddq, m2, lc2, i2), truth_about_origin(m, c, np.zeros((3, 3)))


def test_load_from_joint_torques_both_references_as_the_command_line(tmp_path):
    planar2 = dynid.load_model("planar2")
    rng = np.random.default_rng(15)
    t0, q0, dq0, ddq0 = fourier_run(16, samples=1500)
    t1, q1, dq1, ddq1 = fourier_run(17, samples=1500)
    # The unloaded reference 10x less noisy than the loaded run: an identified reference model's
    # own uncertainty is not propagated into the load's intervals (docs/cli.md), so its sigma
    # must be small against the load's, as the documentation asks of a reference.
    tau0 = planar2_torques(q0, dq0, ddq0) + rng.normal(0.0, 0.002, size=q0.shape)
    tau1, truth = loaded_planar2(q1, dq1, ddq1, 0.6, 0.7)
    tau1 = tau1 + rng.normal(0.0, 0.02, size=q1.shape)
    columns = ["t", "q1", "q2", "dq1", "dq2", "ddq1", "ddq2", "tau1", "tau2"]
    reference_csv = tmp_path / "unloaded.csv"
    np.savetxt(reference_csv, np.column_stack([t0, q0, dq0, ddq0, tau0]), delimiter=",",
               header=",".join(columns), comments="", fmt="%.17g")
    # Robot and load together from the two runs (no friction in the closed form: the columns
    # are estimated near zero).
    frame = [0.1, 0.0, 0.0, 0.0, 0.0, 0.0]
    reference = {"t": t0, "q": q0, "tau": tau0, "dq": dq0, "ddq": ddq0}
    result = dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1, reference, dq=dq1,
                                        ddq=ddq1, filter=False, frame=frame)
    expected = cli(tmp_path, columns, np.column_stack([t1, q1, dq1, ddq1, tau1]), "--robot",
                   "planar2", "--link", "forearm", "--reference", str(reference_csv),
                   "--no-filter", "--frame", "0.1 0 0 0 0 0")
    assert_same(result, expected, skip=("reference", "frame"))
    assert result["frame"]["frame"] == expected["frame"]["frame"] == "0.1 0 0 0 0 0"
    # Planar motion about z: the torques see m, mcx, mcy and Izz of the load, not the rest.
    assert sorted(result["determined_by_torques"]) == ["Izz", "m", "mcx", "mcy"]
    at_frame = dict(truth, mcx=truth["mcx"] - truth["m"] * 0.1,
                    Izz=truth["m"] * (0.7 - 0.1) ** 2)
    assert_inside(result, {k: at_frame[k] for k in result["determined_by_torques"]})

    # The identified unloaded robot as reference, from the command line's result.json and from
    # dynid.identify's dict.
    identified = tmp_path / "unloaded.json"
    run = subprocess.run([binary(), "identify", "--robot", "planar2", "--data",
                          str(reference_csv), "--filter", "none", "--out", str(identified)],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    from_file = json.loads(identified.read_text())
    result = dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1, from_file, dq=dq1,
                                        ddq=ddq1)
    expected = cli(tmp_path, columns, np.column_stack([t1, q1, dq1, ddq1, tau1]), "--robot",
                   "planar2", "--link", "forearm", "--reference", str(identified))
    assert_same(result, expected, skip=("reference", "choices"))
    assert result["choices"]["reference_model"].startswith("the torque of the reference")
    assert_inside(result, {k: truth[k] for k in result["determined_by_torques"]})
    ours = dynid.identify(planar2, t0, q0, tau0, dq=dq0, ddq=ddq0, filter=False)
    again = dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1, ours, dq=dq1, ddq=ddq1)
    assert_same(again, result, skip=("choices",))


def test_payload_modes_refuse_bad_input_with_a_message():
    planar2 = dynid.load_model("planar2")
    t, quat, w, dw, rot = turning_sensor(samples=200)
    wrench = turning_wrench(w, dw, rot, MASS, COM, INERTIA_COM)
    with pytest.raises(TypeError, match="valid options are equations"):
        dynid.payload_from_orientation(t, quat, wrench, sensor_pose=[0] * 6)
    with pytest.raises(dynid.Error, match="quaternion must be 200 x 4"):
        dynid.payload_from_orientation(t, quat[:, :3], wrench)
    with pytest.raises(dynid.Error, match="w must be 200 x 3"):
        dynid.payload_from_orientation(t, quat, wrench, w=w[:, :2])
    with pytest.raises(ValueError, match="t is required"):
        dynid.payload_from_orientation(None, quat, wrench)
    with pytest.raises(ValueError, match="gravity must be"):
        dynid.payload_from_orientation(t, quat, wrench, gravity=[0, 0])
    t1, q1, dq1, ddq1 = fourier_run(18, samples=300)
    tau1 = planar2_torques(q1, dq1, ddq1)
    with pytest.raises(ValueError, match="reference has no 'tau'"):
        dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1, {"t": t1, "q": q1})
    with pytest.raises(ValueError, match="unknown key 'torque'"):
        dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1,
                                   {"t": t1, "q": q1, "torque": tau1})
    with pytest.raises(dynid.Error, match="forearm2"):
        dynid.payload_from_torques(planar2, "forearm2", t1, q1, tau1,
                                   {"t": t1, "q": q1, "tau": tau1})
    other = {"model": {"name": "puma560"}, "parameters": [{"name": "ZZ1R", "value": 1.0}]}
    with pytest.raises(dynid.Error, match="reference is of robot 'puma560', not 'planar2'"):
        dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1, other)
    with pytest.raises(ValueError, match="cutoff_hz and filter come from the reference"):
        dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1, other, filter=False)
    with pytest.raises(ValueError, match="frame must be"):
        dynid.payload_from_torques(planar2, "forearm", t1, q1, tau1,
                                   {"t": t1, "q": q1, "tau": tau1}, frame=[0, 0, 0])


def test_validate_processes_the_run_as_the_command_line_does(tmp_path):
    """dynid.validate without options rebuilds identify's processing from the result (friction
    set, filter, the cut-off and zero-velocity thresholds identify used), as `dynid validate`."""
    planar2 = dynid.load_model("planar2")
    rng = np.random.default_rng(19)
    columns = ["t", "q1", "q2", "tau1", "tau2"]
    paths = []
    for seed in (20, 21):
        t, q, dq, ddq = fourier_run(seed, samples=1500)
        tau = planar2_torques(q, dq, ddq) + rng.normal(0.0, 0.05, size=q.shape)
        paths.append((tmp_path / f"run{seed}.csv", t, q, tau))
        np.savetxt(paths[-1][0], np.column_stack([t, q, tau]), delimiter=",",
                   header=",".join(columns), comments="", fmt="%.17g")
    identified, validated = tmp_path / "id.json", tmp_path / "val.json"
    for args in (["identify", "--robot", "planar2", "--data", str(paths[0][0]), "--friction",
                  "viscous", "--out", str(identified)],
                 ["validate", "--robot", "planar2", "--params", str(identified), "--data",
                  str(paths[1][0]), "--json", str(validated)]):
        run = subprocess.run([binary(), *args], capture_output=True, text=True, check=False)
        assert run.returncode == 0, run.stderr
    result = json.loads(identified.read_text())
    _, t, q, tau = paths[1]
    ours = dynid.validate(planar2, result, t, q, tau)
    assert_same(ours, json.loads(validated.read_text()))
    assert 0.0 < ours["relative_error"] < 0.05
    other = dict(result, model=dict(result["model"], name="puma560"))
    with pytest.raises(dynid.Error, match="result is of robot 'puma560', not 'planar2'"):
        dynid.validate(planar2, other, t, q, tau)


def test_identify_physical_and_its_plot_as_the_command_line(tmp_path):
    """identify(physical=True): the consistent standard parameters, their distance and the plot
    section equal those of `dynid identify --physical`; export_urdf writes them loadably."""
    planar2 = dynid.load_model("planar2")
    rng = np.random.default_rng(22)
    t, q, dq, ddq = fourier_run(23, samples=1500)
    tau = planar2_torques(q, dq, ddq) + rng.normal(0.0, 0.05, size=q.shape)
    data, out = tmp_path / "run.csv", tmp_path / "id.json"
    np.savetxt(data, np.column_stack([t, q, dq, ddq, tau]), delimiter=",", comments="",
               header="t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2", fmt="%.17g")
    run = subprocess.run([binary(), "identify", "--robot", "planar2", "--data", str(data),
                          "--friction", "none", "--no-armature", "--filter", "none",
                          "--physical", "--out", str(out)],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    expected = json.loads(out.read_text())
    ours = dynid.identify(planar2, t, q, tau, dq=dq, ddq=ddq, armature=False, viscous=False,
                          coulomb=False, offset=False, filter=False, physical=True)
    for key in ("parameters", "standard_parameters", "physically_consistent", "physical",
                "plot"):
        assert_same(ours[key], expected[key], key)
    assert ours["options"]["physical"] is True
    urdf = tmp_path / "identified.urdf"
    dynid.export_urdf(planar2, ours, str(urdf))
    exported = dynid.load_model(str(urdf))
    masses = [p["value"] for p in ours["standard_parameters"] if p["name"] in ("M1", "M2")]
    np.testing.assert_allclose(exported.standard_parameters[[9, 19]], masses, rtol=1e-12)
    with pytest.raises(TypeError, match="physical is an option of identify"):
        dynid.validate(planar2, ours, t, q, tau, physical=True)
