"""The Python module as complete as the command line (issue 29 item 3): identify's integral model,
several runs, closed-loop projection, maximum likelihood, repeated estimates and the one-joint
experiments, and excite, simulate and average, each against the command line on the same files
(numbers to round-off, keys exactly; only the `options` echo differs, since the command line
records its flags and file names there). Oracles besides the command line: the closed-form planar
2R arm's torques (test_dynid.planar2_torques) and MuJoCo as the plant, whose injected sensor
noise `average` must measure."""
import json
import os
import subprocess

import numpy as np
import pytest

import dynid
from test_cli_parity import binary
from test_dynid import fourier_run, planar2_torques

NO_FRICTION = dict(armature=False, viscous=False, coulomb=False, offset=False)
NO_FRICTION_FLAGS = ["--friction", "none", "--no-armature"]


def cli(*args):
    run = subprocess.run([binary(), *map(str, args)], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    return run


def write_csv(path, columns, *blocks):
    """17 significant digits: the command line reads the very doubles of the arrays."""
    np.savetxt(path, np.column_stack(blocks), delimiter=",", header=",".join(columns),
               comments="", fmt="%.17g")
    return path


def joint_columns(prefix, n=2):
    return [f"{prefix}{j + 1}" for j in range(n)]


def assert_same(py, cl, path="", skip=()):
    """Same keys at every level and the same values, numbers to 1e-9 relative; `skip` holds
    paths (".options", ".runs[0].file") left out."""
    if path in skip:
        return
    if isinstance(cl, dict):
        assert isinstance(py, dict) and set(py) == set(cl), (path, set(py) ^ set(cl))
        for key in cl:
            assert_same(py[key], cl[key], f"{path}.{key}", skip)
    elif isinstance(cl, list):
        assert isinstance(py, list) and len(py) == len(cl), path
        for i, (a, b) in enumerate(zip(py, cl)):
            assert_same(a, b, f"{path}[{i}]", skip)
    elif isinstance(cl, float) and not isinstance(py, bool):
        assert py == pytest.approx(cl, rel=1e-9, abs=1e-12), path
    else:
        assert py == cl, path


def run_files(count):
    return tuple(f".runs[{i}].file" for i in range(count))


def base_truth(model, **layout):
    base = dynid.base_parameters(model, **layout)
    theta = model.standard_parameters
    return dict(zip([p["name"] for p in base["base_parameters"]],
                    theta[base["base_indices"]] + base["K_d"] @ theta[base["dependent_indices"]]))


def assert_truth_inside(result, truth):
    for p in result["parameters"]:
        assert p["ci_low"] <= truth[p["name"]] <= p["ci_high"], (p, truth[p["name"]])


@pytest.fixture(scope="module")
def planar2():
    return dynid.load_model("planar2")


def test_integral_model_of_two_runs_as_the_command_line(planar2, tmp_path):
    rng = np.random.default_rng(31)
    runs, flags = [], []
    for seed in (32, 33):
        t, q, dq, ddq = fourier_run(seed, samples=1200)
        tau = planar2_torques(q, dq, ddq) + rng.normal(0.0, 0.05, size=q.shape)
        runs.append({"t": t, "q": q, "tau": tau, "dq": dq})
        columns = ["t"] + joint_columns("q") + joint_columns("dq") + joint_columns("tau")
        flags += ["--data", write_csv(tmp_path / f"run{seed}.csv", columns, t, q, dq, tau)]
    # Unfiltered, with the exact velocity the energy model's power needs: the estimate is then
    # unbiased and the truth must lie inside its intervals.
    ours = dynid.identify_runs(planar2, runs, equations="integral", interval=0.05, filter=False,
                               **NO_FRICTION)
    out = tmp_path / "integral.json"
    cli("identify", "--robot", "planar2", *flags, "--model", "integral", "--interval", "0.05",
        "--filter", "none", *NO_FRICTION_FLAGS, "--out", out)
    expected = json.loads(out.read_text())
    assert_same(ours, expected, skip=(".options",) + run_files(2))
    assert len(ours["runs"]) == 2 and ours["plot"]["energy"]["measured"]
    assert ours["options"]["model"] == "integral" and ours["options"]["interval"] == 0.05
    # Oracle: the closed-form arm's base parameters inside the energy model's intervals.
    assert_truth_inside(ours, base_truth(planar2, **NO_FRICTION))
    # One run through identify() is identify_runs() of that run.
    one = dynid.identify(planar2, runs[0]["t"], runs[0]["q"], runs[0]["tau"], dq=runs[0]["dq"],
                         equations="integral", interval=0.05, **NO_FRICTION)
    again = dynid.identify_runs(planar2, runs[:1], equations="integral", interval=0.05,
                                **NO_FRICTION)
    assert_same(one, again)


def periodic_reference(period=2.0, rate=500.0):
    """One period of a smooth two-joint reference: harmonics 1-3 of 1/period, zero mean."""
    t = np.arange(int(round(period * rate))) / rate
    w = 2 * np.pi / period * np.array([1.0, 2.0, 3.0])
    a = np.array([[0.5, 0.3], [0.25, 0.4], [0.1, 0.15]])
    q = sum(a[k] * np.sin(w[k] * t)[:, None] for k in range(3))
    dq = sum(a[k] * w[k] * np.cos(w[k] * t)[:, None] for k in range(3))
    ddq = sum(-a[k] * w[k] ** 2 * np.sin(w[k] * t)[:, None] for k in range(3))
    return t, q, dq, ddq


SIMULATE = dict(periods=4, torque_noise=0.05, position_noise=2e-5, seed=3)
SIMULATE_FLAGS = ["--periods", 4, "--torque-noise", 0.05, "--position-noise", 2e-5, "--seed", 3]


@pytest.fixture(scope="module")
def closed_loop_run(planar2, tmp_path_factory):
    """A closed-loop run of planar2 on the MuJoCo plant from dynid.simulate, the same from `dynid
    simulate` on the same reference file, and the run without its first period (the loop settling
    from rest, which the identification leaves out) as arrays and as a file."""
    folder = tmp_path_factory.mktemp("closed_loop")
    t, q, dq, ddq = periodic_reference()
    reference = write_csv(folder / "reference.csv",
                          ["t"] + joint_columns("q") + joint_columns("dq") + joint_columns("ddq"),
                          t, q, dq, ddq)
    ours = dynid.simulate(planar2, t, q, dq=dq, ddq=ddq, **SIMULATE)
    path = folder / "run.csv"
    cli("simulate", "--robot", "planar2", "--trajectory", reference, "--out", path,
        *SIMULATE_FLAGS)
    period = len(t)
    steady = {key: ours[key][period:] for key in ("t", "qr", "q", "tau")}
    steady_path = write_csv(folder / "steady.csv", ours["columns"], ours["data"][period:])
    return ours, path, steady, steady_path


def test_simulate_writes_what_the_command_line_writes(closed_loop_run):
    ours, path, _, _ = closed_loop_run
    with open(path) as f:
        header = f.readline().strip().split(",")
    assert ours["columns"] == header == ["t", "qr1", "qr2", "q1", "q2", "tau1", "tau2"]
    np.testing.assert_array_equal(ours["data"], np.loadtxt(path, delimiter=",", skiprows=1))
    np.testing.assert_array_equal(ours["q"], ours["data"][:, 3:5])
    gains = json.loads((path.parent / "run.gains.json").read_text())
    assert_same(ours["gains"], gains)


def test_closed_loop_projection_and_maximum_likelihood_as_the_command_line(
        planar2, closed_loop_run, tmp_path):
    _, _, run, path = closed_loop_run
    arrays = dict(qr=run["qr"])
    projected = dynid.identify(planar2, run["t"], run["q"], run["tau"], closed_loop="projection",
                               **arrays, **NO_FRICTION)
    out = tmp_path / "projection.json"
    cli("identify", "--robot", "planar2", "--data", path, "--closed-loop", "projection",
        *NO_FRICTION_FLAGS, "--out", out)
    assert_same(projected, json.loads(out.read_text()), skip=(".options",) + run_files(1))
    assert projected["closed_loop"]["method"] == "projection"
    # Maximum likelihood with the sensor noise the plant was given.
    ml = dynid.identify(planar2, run["t"], run["q"], run["tau"], estimator="ml",
                        noise_std="q=2e-5,tau=0.05", **NO_FRICTION)
    out = tmp_path / "ml.json"
    cli("identify", "--robot", "planar2", "--data", path, "--estimator", "ml", "--noise-std",
        "q=2e-5,tau=0.05", *NO_FRICTION_FLAGS, "--out", out)
    assert_same(ml, json.loads(out.read_text()), skip=(".options",) + run_files(1))
    # Oracle: MuJoCo's arm is the model's; its base parameters inside both estimates' intervals.
    truth = base_truth(planar2, **NO_FRICTION)
    assert_truth_inside(projected, truth)
    assert_truth_inside(ml, truth)


def test_maximum_likelihood_with_the_noise_average_measured_as_the_command_line(
        planar2, closed_loop_run, tmp_path):
    """identify --estimator ml --noise avg.json: the raw std for the run itself, std_averaged for
    its mean period (seed 2 §3.4: average, then fit the mean)."""
    _, _, run, path = closed_loop_run
    names = ["qr1", "qr2", "q1", "q2", "tau1", "tau2"]
    blocks = np.column_stack([run["qr"], run["q"], run["tau"]])
    noise = dynid.average(run["t"], dict(zip(names, blocks.T)), period=2.0)
    mean, noise_file = tmp_path / "mean.csv", tmp_path / "noise.json"
    cli("average", "--data", path, "--period", 2, "--out", mean, "--json", noise_file)
    for data, arrays in ((path, run), (mean, None)):
        if arrays is None:  # the mean period: phase t, then the columns in `names` order
            m = noise["mean"]
            arrays = {"t": m[:, 0], "qr": m[:, 1:3], "q": m[:, 3:5], "tau": m[:, 5:7]}
        ours = dynid.identify(planar2, arrays["t"], arrays["q"], arrays["tau"], estimator="ml",
                              noise=noise, **NO_FRICTION)
        out = tmp_path / "ml.json"
        cli("identify", "--robot", "planar2", "--data", data, "--estimator", "ml", "--noise",
            noise_file, *NO_FRICTION_FLAGS, "--out", out)
        expected = json.loads(out.read_text())
        which = expected["choices"].pop("noise_file")  # the file the command line read
        assert_same(ours, expected, skip=(".options",) + run_files(1))
        field = "std_averaged" if data == mean else "std"
        assert which.startswith(f"{noise_file}: {field},")
        assert ours["options"]["noise"].split(",")[0].split()[0] == field


def test_repeated_estimates_over_periods_as_the_command_line(planar2, closed_loop_run, tmp_path):
    _, _, run, path = closed_loop_run
    ours = dynid.identify(planar2, run["t"], run["q"], run["tau"], qr=run["qr"],
                          repeat="periods", filter=False, **NO_FRICTION)
    out = tmp_path / "repeat.json"
    cli("identify", "--robot", "planar2", "--data", path, "--repeat", "periods", "--filter",
        "none", *NO_FRICTION_FLAGS, "--out", out)
    assert_same(ours, json.loads(out.read_text()), skip=(".options",) + run_files(1))
    assert ours["repeated"]["n"] == SIMULATE["periods"] - 1


def test_average_measures_the_injected_noise_as_the_command_line(planar2, tmp_path):
    # A loop without position noise: after the first period's transient the applied torque
    # repeats, so the logged torque's spread across periods is the sensor's noise alone.
    t, q, dq, ddq = periodic_reference()
    run = dynid.simulate(planar2, t, q, dq=dq, ddq=ddq, periods=5, torque_noise=0.05, seed=4)
    path = write_csv(tmp_path / "run.csv", run["columns"], run["data"])
    columns = {name: run["data"][:, i] for i, name in enumerate(run["columns"]) if name != "t"}
    ours = dynid.average(run["t"], columns, period=2.0, skip_periods=1, filter="butterworth:4",
                         cutoff_hz=10.0, decimate=5)
    mean, noise = tmp_path / "mean.csv", tmp_path / "noise.json"
    cli("average", "--data", path, "--period", 2, "--skip-periods", 1, "--filter",
        "butterworth:4", "--cutoff", 10, "--decimate", 5, "--out", mean, "--json", noise)
    expected = json.loads(noise.read_text())
    assert (expected.pop("data"), expected.pop("out")) == (str(path), str(mean))
    assert_same({k: v for k, v in ours.items() if k not in ("columns", "mean")}, expected)
    np.testing.assert_array_equal(ours["mean"], np.loadtxt(mean, delimiter=",", skiprows=1))
    assert ours["mean"].shape == (200, 7) and ours["periods"] == 4
    # Oracle: the plant's torque sensor noise (std 0.05 N m, white) is what average measures.
    std = {c["name"]: c["std"] for c in ours["channels"]}
    assert std["tau1"] == pytest.approx(0.05, rel=0.1)
    assert std["tau2"] == pytest.approx(0.05, rel=0.1)
    assert std["qr1"] < 1e-9  # the reference repeats exactly


def test_excite_fourier_as_the_command_line(planar2, tmp_path):
    options = dict(harmonics=3, f0=0.25, starts=1, max_evaluations=200, max_time=0, rate=50,
                   velocity_limit=[2.0], acceleration_limit=[8.0, 10.0])
    ours = dynid.excite(planar2, **options)
    trajectory, result = tmp_path / "trajectory.csv", tmp_path / "excitation.json"
    cli("excite", "--robot", "planar2", "--harmonics", 3, "--f0", 0.25, "--starts", 1,
        "--max-evaluations", 200, "--max-time", 0, "--rate", 50, "--velocity-limit", 2,
        "--acceleration-limit", "8,10", "--out", trajectory, "--json", result)
    # `seconds` is the search's wall-clock time, not a result.
    assert_same({k: v for k, v in ours.items() if k != "trajectory"},
                json.loads(result.read_text()), skip=(".seconds",))
    written = np.loadtxt(trajectory, delimiter=",", skiprows=1)
    t = ours["trajectory"]
    np.testing.assert_array_equal(np.column_stack([t["t"], t["q"], t["dq"], t["ddq"]]), written)
    # Oracle: the trajectory's velocity is the finite difference of its positions.
    h = t["t"][1] - t["t"][0]
    np.testing.assert_allclose((t["q"][2:] - t["q"][:-2]) / (2 * h), t["dq"][1:-1], atol=2e-3)


def test_one_joint_experiments_from_excited_and_simulated_runs_as_the_command_line(
        planar2, closed_loop_run, tmp_path):
    """excite(family='slope') -> simulate -> identify(equations='gravity'), then 'decoupled' on
    the same run and 'friction' on bang-bang moves compensated with that gravity result, each
    step against the command line; the fitted gravity torque of the shoulder against the closed
    form, and the (absent) friction inside its intervals."""
    slope = dict(family="slope", joint=1, range=(-1.0, 1.0), velocity=0.4, acceleration=2.0,
                 cycles=2, rate=500)
    reference = dynid.excite(planar2, **slope)["trajectory"]
    path = tmp_path / "slope.csv"
    cli("excite", "--robot", "planar2", "--family", "slope", "--joint", 1, "--range", "-1:1",
        "--velocity", 0.4, "--acceleration", 2, "--cycles", 2, "--rate", 500, "--out", path)
    np.testing.assert_array_equal(
        np.column_stack([reference["t"], reference["q"], reference["dq"], reference["ddq"]]),
        np.loadtxt(path, delimiter=",", skiprows=1))
    run = dynid.simulate(planar2, reference["t"], reference["q"], dq=reference["dq"],
                         ddq=reference["ddq"], periods=1, torque_noise=0.02, seed=5)
    logged = tmp_path / "gravity_run.csv"
    cli("simulate", "--robot", "planar2", "--trajectory", path, "--out", logged, "--periods", 1,
        "--torque-noise", 0.02, "--seed", 5)
    ours = dynid.identify(planar2, run["t"], run["q"], run["tau"], equations="gravity", joint=1)
    out = tmp_path / "gravity.json"
    cli("identify", "--robot", "planar2", "--data", logged, "--model", "gravity", "--joint", 1,
        "--out", out)
    assert_same(ours, json.loads(out.read_text()), skip=(".options",))
    # Oracle: with the elbow held at 0 the shoulder's gravity torque is
    # (m1 lc1 + m2 (l1 + lc2)) g cos(q1) (planar2_torques at rest).
    values = {p["name"]: p["value"] for p in ours["parameters"]}
    q1 = np.linspace(-1.0, 1.0, 5)
    rest = np.zeros((5, 2))
    closed_form = planar2_torques(np.column_stack([q1, np.zeros(5)]), rest, rest)[:, 0]
    fitted = values["k1"] * np.sin(q1 + values["qoff1"])
    np.testing.assert_allclose(fitted, closed_form, rtol=0.02, atol=0.05)

    # The decoupled model of the same run (one joint moving, the other held).
    decoupled = dynid.identify(planar2, run["t"], run["q"], run["tau"], equations="decoupled",
                               joint=1)
    decoupled_out = tmp_path / "decoupled.json"
    cli("identify", "--robot", "planar2", "--data", logged, "--model", "decoupled", "--joint", 1,
        "--out", decoupled_out)
    assert_same(decoupled, json.loads(decoupled_out.read_text()), skip=(".options",))

    # Friction from bang-bang moves, compensated with the gravity just identified (seed 2's
    # chain: --params gravity.json, here the dict). planar2 has no friction: the truth is 0.
    moves = dynid.excite(planar2, family="bang-bang", joint=1, range=(-1.0, 1.0),
                         acceleration=3.0, cycles=2, rate=500)["trajectory"]
    run = dynid.simulate(planar2, moves["t"], moves["q"], dq=moves["dq"], ddq=moves["ddq"],
                         periods=1, torque_noise=0.02, seed=6)
    logged = write_csv(tmp_path / "friction_run.csv", run["columns"], run["data"])
    friction = dynid.identify(planar2, run["t"], run["q"], run["tau"], equations="friction",
                              joint=1, params=ours)
    friction_out = tmp_path / "friction.json"
    cli("identify", "--robot", "planar2", "--data", logged, "--model", "friction", "--joint", 1,
        "--params", out, "--out", friction_out)
    assert_same(friction, json.loads(friction_out.read_text()), skip=(".options",))
    assert_truth_inside(friction, {"Fvp1": 0.0, "Fvn1": 0.0, "Fcp1": 0.0, "Fcn1": 0.0})

    # That friction known, the rigid body of a whole-arm run (seed 2 §3.4: --friction-known).
    _, _, steady, steady_path = closed_loop_run
    rigid = dynid.identify(planar2, steady["t"], steady["q"], steady["tau"],
                           friction_known=[friction], armature=False)
    rigid_out = tmp_path / "rigid.json"
    cli("identify", "--robot", "planar2", "--data", steady_path, "--friction-known",
        friction_out, "--no-armature", "--out", rigid_out)
    assert_same(rigid, json.loads(rigid_out.read_text()), skip=(".options",) + run_files(1))
    assert [k["name"] for k in rigid["options"]["known_friction"]] == ["Fvp1", "Fvn1", "Fcp1",
                                                                      "Fcn1"]


def test_bad_options_name_the_keyword(planar2):
    t, q, dq, ddq = fourier_run(40, samples=300)
    tau = planar2_torques(q, dq, ddq)
    with pytest.raises(TypeError, match="closed_loop is an option of identify"):
        dynid.validate(planar2, {"parameters": []}, t, q, tau, closed_loop="projection")
    with pytest.raises(ValueError, match="closed_loop must be"):
        dynid.identify(planar2, t, q, tau, closed_loop="forward")
    with pytest.raises(ValueError, match="fir sets the projection"):
        dynid.identify(planar2, t, q, tau, fir=[2, 2])
    with pytest.raises(ValueError, match="needs joint=J"):
        dynid.identify(planar2, t, q, tau, equations="gravity")
    with pytest.raises(ValueError, match="noise and noise_std are the noise of estimator='ml'"):
        dynid.identify(planar2, t, q, tau, noise_std="q=1e-4,tau=0.1")
    with pytest.raises(dynid.Error, match="noise_std"):
        dynid.identify(planar2, t, q, tau, estimator="ml", noise_std="q=-1")
    with pytest.raises(ValueError, match=r"runs\[1\] has no 'tau'"):
        dynid.identify_runs(planar2, [{"t": t, "q": q, "tau": tau}, {"t": t, "q": q}])
    with pytest.raises(dynid.Error, match="qr"):  # the projection needs the reference
        dynid.identify(planar2, t, q, tau, closed_loop="projection")
    with pytest.raises(dynid.Error, match="harmonics"):
        dynid.excite(planar2, harmonics=1)
    # planar2 has no joint limits: the library's message names the keywords, not the flags.
    with pytest.raises(dynid.Error, match="give velocity_limit or acceleration_limit"):
        dynid.excite(planar2, max_time=0, starts=1, max_evaluations=50)
    with pytest.raises(dynid.Error, match="range"):
        dynid.excite(planar2, family="slope", joint=1, velocity=0.4, acceleration=2.0)
    with pytest.raises(ValueError, match="criterion is for the optimised excitation"):
        dynid.excite(planar2, family="slope", joint=1, criterion="cond")
    with pytest.raises(ValueError, match="exactly one of period"):
        dynid.average(t, {"q1": q[:, 0]})
    with pytest.raises(dynid.Error, match="cutoff_hz"):
        dynid.average(t, {"q1": q[:, 0]}, period=1.0, filter="butterworth:4")
    with pytest.raises(ValueError, match="friction_known replaces the friction columns"):
        dynid.identify(planar2, t, q, tau, friction_known=[{}], viscous=True)
    with pytest.raises(ValueError, match="outliers must be"):
        dynid.identify(planar2, t, q, tau, outliers="keep")
    with pytest.raises(ValueError, match="controller='computed-torque' needs params"):
        dynid.simulate(planar2, t, q, controller="computed-torque")


def test_an_interpreter_without_numpy_is_told_which_to_use():
    """The import itself names the interpreter to use (here: NumPy hidden from this one)."""
    package = os.path.dirname(os.path.dirname(dynid.__file__))
    env = dict(os.environ, PYTHONPATH=package)
    run = subprocess.run([os.sys.executable, "-c",
                          "import sys; sys.modules['numpy'] = None; import dynid"],
                         capture_output=True, text=True, env=env, check=False)
    assert run.returncode != 0
    last = run.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: dynid needs NumPy"), run.stderr
    assert "/usr/bin/python3" in last and "python3-numpy" in last and "_core.cpython" in last
