"""Issue 31 item 4: dynid.fleet.identify through a Dask LocalCluster on this machine.

Writes FILES runs of SAMPLES puma560 samples each (multi-sine motion, torques from dynid's RNEA
plus noise), then measures: one single-process stream over all files (dynid.stream_partial, one
thread), the LocalCluster map + tree merge (2 single-threaded worker processes), the per-file
step alone, the merge of all parts, and each worker's resident memory. Usage:

    PYTHONPATH=build/python /usr/bin/python3 bench/identification/fleet_bench.py FILES SAMPLES [FOLDER]

Prints one JSON object; docs/performance.md records a run with the machine and its load."""
import json
import os
import sys
import time

import numpy as np

import dynid

OPTIONS = dict(zero_velocity=[0.01])


def write_runs(folder, files, samples, model):
    paths = []
    n = model.dof
    header = ",".join(["t"] + [f"{p}{j + 1}" for p in ("q", "dq", "ddq", "tau")
                               for j in range(n)])
    for k in range(files):
        path = os.path.join(folder, f"fleet_run{k}.csv")
        paths.append(path)
        if os.path.exists(path):
            continue
        rng = np.random.default_rng(k)
        t = np.arange(samples) * 0.001
        w = 0.5 + 0.3 * np.arange(n) + 0.05 * k
        arg = w * t[:, None] + np.arange(n)
        q = np.sin(arg) + 0.3 * np.sin(3 * w * t[:, None])
        dq = w * np.cos(arg) + 0.9 * w * np.cos(3 * w * t[:, None])
        ddq = -w * w * np.sin(arg) - 2.7 * w * w * np.sin(3 * w * t[:, None])
        tau = dynid.inverse_dynamics(model, q, dq, ddq) + 3.0 * dq
        tau += rng.normal(0.0, 0.3, size=tau.shape)
        np.savetxt(path, np.column_stack([t, q, dq, ddq, tau]), delimiter=",", header=header,
                   comments="", fmt="%.9g")
    return paths


def main():
    files, samples = int(sys.argv[1]), int(sys.argv[2])
    folder = sys.argv[3] if len(sys.argv) > 3 else "/tmp/dynid_fleet_bench"
    os.makedirs(folder, exist_ok=True)
    model = dynid.load_model("puma560")
    paths = write_runs(folder, files, samples, model)
    out = {"files": files, "samples_per_file": samples, "csv_bytes": sum(map(os.path.getsize, paths))}

    start = time.perf_counter()
    single = dynid.solve_partial(dynid.stream_partial(model, paths, robot="puma560", threads=1,
                                                      **OPTIONS))
    out["single_process_s"] = time.perf_counter() - start

    start = time.perf_counter()
    part = dynid.stream_partial(model, paths[:1], robot="puma560", threads=1, **OPTIONS)
    out["per_file_s"] = time.perf_counter() - start
    out["part_bytes"] = len(part)
    parts = [part] * files
    start = time.perf_counter()
    merged = dynid.merge_partials(parts)
    out["merge_all_s"] = time.perf_counter() - start
    start = time.perf_counter()
    dynid.solve_partial(merged)
    out["solve_s"] = time.perf_counter() - start

    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.run(lambda: dynid.__version__)  # workers up and the module imported
        start = time.perf_counter()
        fleet = dynid.fleet.identify(paths, "puma560", client=client, threads=1, **OPTIONS)
        out["local_cluster_s"] = time.perf_counter() - start
        import psutil
        rss = client.run(lambda: psutil.Process().memory_info().rss)
        out["worker_rss_mb"] = sorted(round(v / 2**20, 1) for v in rss.values())
    worst = max(abs(a["value"] - b["value"]) / max(abs(a["value"]), a["std"])
                for a, b in zip(single["parameters"], fleet["parameters"]))
    out["max_difference_over_max_value_std"] = worst
    total = files * samples
    out["cluster_samples_per_s"] = total / out["local_cluster_s"]
    out["single_samples_per_s"] = total / out["single_process_s"]
    out["load_average"] = os.getloadavg()
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
