"""dynid.fleet (issue 31 item 2): the per-file map and exact merge on a Dask LocalCluster of 2
workers give the single-process result; dynid.compare flags a changed friction parameter. Data:
the closed-form planar 2R arm of test_dynid.py with viscous friction and noise."""
import numpy as np
import pytest

import dynid
from test_dynid import fourier_run, planar2_torques

distributed = pytest.importorskip("dask.distributed")

FV = np.array([0.5, 0.8])


def write_run(path, seed, fv=FV):
    t, q, dq, ddq = fourier_run(seed)
    rng = np.random.default_rng(100 + seed)
    tau = planar2_torques(q, dq, ddq) + fv * dq + rng.normal(0.0, 0.1, size=q.shape)
    header = "t,q1,q2,dq1,dq2,ddq1,ddq2,tau1,tau2"
    np.savetxt(path, np.column_stack([t, q, dq, ddq, tau]), delimiter=",", header=header,
               comments="", fmt="%.12g")
    return str(path)


OPTIONS = dict(armature=False, coulomb=False, offset=False, zero_velocity=[0.01])


def same_result(a, b):
    names = [p["name"] for p in a["parameters"]]
    assert names == [p["name"] for p in b["parameters"]]
    for p, r in zip(a["parameters"], b["parameters"]):
        scale = max(abs(p["value"]), p["std"])
        assert abs(p["value"] - r["value"]) <= 1e-10 * scale, p["name"]
        assert abs(p["std"] - r["std"]) <= 1e-10 * p["std"], p["name"]
    assert a["rows"] == b["rows"] and a["samples"] == b["samples"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fleet")
    return [write_run(folder / f"run{k}.csv", k) for k in range(5)]


def test_local_cluster_of_two_workers_equals_the_single_process_fit(runs):
    model = dynid.load_model("planar2")
    single = dynid.solve_partial(dynid.stream_partial(model, runs, robot="planar2", **OPTIONS))
    # The truth of the closed form is inside the intervals (white noise: white σ is right here).
    fv = {p["name"]: p for p in single["parameters"] if p["name"].startswith("Fv")}
    for j, value in enumerate(FV):
        assert fv[f"Fv{j + 1}"]["ci_low"] <= value <= fv[f"Fv{j + 1}"]["ci_high"]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        # split_every=2: a tree of merges (5 parts -> 3 -> 2 -> 1), not one big merge.
        fleet, part = dynid.fleet.identify(runs, "planar2", client=client, split_every=2,
                                           return_partial=True, **OPTIONS)
        assert len(client.scheduler_info()["workers"]) == 2
    same_result(single, fleet)
    assert sorted(fleet["options"]["data_runs"]) == sorted(runs)
    assert len(fleet["runs"]) == 5
    # The merged part is the .dpart format the command line reads.
    assert part[:8] == b"DYNIDPRT"


def test_default_local_cluster_and_refused_parts(runs):
    model = dynid.load_model("planar2")
    single = dynid.solve_partial(dynid.stream_partial(model, runs[:2], robot="planar2", **OPTIONS))
    same_result(single, dynid.fleet.identify(runs[:2], "planar2", **OPTIONS))
    other = dynid.stream_partial(model, runs[:1], robot="planar2", armature=False, coulomb=False,
                                 offset=False, zero_velocity=[0.02])
    mine = dynid.stream_partial(model, runs[1:2], robot="planar2", **OPTIONS)
    with pytest.raises(dynid.Error, match="zero_velocity_threshold"):
        dynid.merge_partials([mine, other])
    with pytest.raises(dynid.Error, match="truncated|corrupt"):
        dynid.solve_partial(mine[: len(mine) // 2])
    with pytest.raises(ValueError):
        dynid.fleet.identify([], "planar2")


def test_compare_flags_the_changed_viscous_friction(tmp_path):
    model = dynid.load_model("planar2")
    results = []
    for night, fv2 in enumerate([0.8, 0.8, 0.96]):
        path = write_run(tmp_path / f"night{night}.csv", 20 + night, np.array([0.5, fv2]))
        results.append(dynid.solve_partial(dynid.stream_partial(model, [path], **OPTIONS)))
    c = dynid.compare(results, alpha=0.01, labels=["mon", "tue", "wed"])
    assert [(f["name"], f["file"]) for f in c["flagged"]] == [("Fv2", "wed")]
    assert c["flagged_friction"] == ["Fv2"]
    with pytest.raises(dynid.Error):
        dynid.compare(results[:1])
