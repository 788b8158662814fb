"""Tables 1-3 of B. Bona, A. Curatella (2005) from the results of run.sh, with the truth beside them.

The truth comes from the model file alone (dynid model --json: standard parameters, actuator
inertias, friction; dynid inverse-dynamics: the gravity torques of joints 2 and 3), never from an
estimate. Writes OUT/summary.json: every estimate with its truth and interval, and the tracking
errors of the two controllers.
Usage: python3 tables.py OUT_DIR
"""
import csv
import json
import math
import os
import re
import sys

out = sys.argv[1]


def load(name):
    with open(os.path.join(out, name)) as f:
        return json.load(f)


model = load("model.json")
truth = {p["name"]: p["value"] for p in model["standard_parameters"]}
for j, f in enumerate(model["friction"], start=1):
    truth[f"Ia{j}"] = f["Ia"]
    # Asymmetric form of the plant's friction (docs/design.md section 3): Fvp = Fvn = Fv,
    # Fcp = Fc + Fo, Fcn = Fc - Fo.
    truth[f"Fvp{j}"] = truth[f"Fvn{j}"] = f["Fv"]
    truth[f"Fcp{j}"] = f["Fc"] + f.get("Fo", 0.0)
    truth[f"Fcn{j}"] = f["Fc"] - f.get("Fo", 0.0)


def evaluate(expression, values):
    """Value of 'NAME = c*A + B - c*C ...' (a result's or the model's base-parameter expression)."""
    rhs = expression.split("=", 1)[1].replace("(on these data)", "")
    total = 0.0
    for term in rhs.replace(" - ", " + -").split(" + "):
        term = term.strip()
        if not term:
            continue
        sign = -1.0 if term.startswith("-") else 1.0
        term = term.lstrip("-").strip()
        coefficient, _, name = term.rpartition("*")
        total += sign * (float(coefficient) if coefficient else 1.0) * values[name]
    return total


base = dict(truth)
for b in model["base_parameters"]:
    base.setdefault(b["name"], evaluate(b["expression"], truth))

rows = []  # (table, name, estimate, std, ci_low, ci_high, truth)


def add(table, p, value_truth):
    rows.append({"table": table, "name": p["name"], "value": p["value"], "std": p["std"],
                 "ci_low": p["ci_low"], "ci_high": p["ci_high"], "truth": value_truth})


# Table 1: gravity k*sin(q + q_off); truth from RNEA's gravity torque at q_J = pi/2 and 0
# (a = k cos q_off, b = k sin q_off), folded as identify folds it: q_off in (-pi/2, pi/2].
with open(os.path.join(out, "gravity_truth.csv")) as f:
    g = list(csv.DictReader(f))
for j in (2, 3):
    a, b = float(g[0 if j == 2 else 2][f"tau{j}"]), float(g[1][f"tau{j}"])
    k, qoff = math.hypot(a, b), math.atan2(b, a)
    if qoff > math.pi / 2:
        k, qoff = -k, qoff - math.pi
    elif qoff <= -math.pi / 2:
        k, qoff = -k, qoff + math.pi
    for p in load(f"gravity_{j}.json")["parameters"]:
        add("1", p, {f"k{j}": k, f"qoff{j}": qoff}[p["name"]])
for j in range(1, 7):
    for p in load(f"friction_{j}.json")["parameters"]:
        add("2", p, truth[p["name"]])
result = load("result.json")
values = dict(base)
for p in result["parameters"]:
    add("3", p, evaluate(p["expression"], values))


def show(table, title):
    print(f"\n{title}")
    print(f"{'parameter':<10} {'estimate':>12} {'sigma':>10} {'99.9% interval':>28} {'truth':>12}  in")
    for r in rows:
        if r["table"] != table:
            continue
        inside = r["ci_low"] <= r["truth"] <= r["ci_high"]
        r["inside"] = inside
        interval = f"[{r['ci_low']:.5g}, {r['ci_high']:.5g}]"
        print(f"{r['name']:<10} {r['value']:>12.5g} {r['std']:>10.3g} {interval:>28} "
              f"{r['truth']:>12.5g}  {'yes' if inside else 'NO'}")


show("1", "Table 1. Gravity, joints 2 and 3 (k [N m], q_off [rad]), from the slopes")
show("2", "Table 2. Friction (Fv [N m s/rad], Fc [N m]), from bang-bang moves")
show("3", "Table 3. Rigid-body base parameters [kg m^2, kg m], six one-joint Fourier runs "
     "averaged, Chebyshev 8 at 80 Hz, 200 Hz, friction of Table 2 subtracted, spectral projection")
widened = [w for w in load("result.json")["warnings"] if "disagree" in w]
if widened:
    print("Model error shown by the intervals: " + "; ".join(widened))
poor = [r["name"] for r in rows if r["table"] == "3" and r["std"] > abs(r["value"])]
print(f"\nWhat the one-joint runs determine: data rank {result['data_rank']} of "
      f"{result['rank']} base parameters; not excited: {', '.join(result['not_excited']) or 'none'}")
print("Estimated but undetermined in practice (sigma above the estimate: the held joints never "
      f"change the configuration these depend on): {', '.join(poor) or 'none'}")

print("\nValidation by simulation on trapezoids (identified model under the same PID):")
print(f"{'joint':<7} {'max |q error| [deg]':>20} {'RMS torque error [N m]':>24}")
for j in range(1, 7):
    if not os.path.exists(os.path.join(out, f"validation_{j}.json")):
        with open(os.path.join(out, f"validation_{j}.log")) as f:
            print(f"{j:<7} not simulated: {f.read().strip().splitlines()[-1]}")
        continue
    v = load(f"validation_{j}.json")["joints"][j - 1]
    print(f"{j:<7} {math.degrees(v['position']['max']):>20.4g} {v['torque']['rms']:>24.4g}")

summary_control = {}
if not os.path.exists(os.path.join(out, "control.json")):
    with open(os.path.join(out, "control.log")) as f:
        print("\nComputed torque from the identified model: not run: " +
              f.read().strip().splitlines()[-1])
    control = {"controllers": []}
else:
    control = load("control.json")
if control["controllers"]:
    print("\nTracking error on joint 1's Fourier reference (paper's Fig. 9), max over the joints "
          "[deg]:")
for c in control["controllers"]:
    peak = max(jt["max"] for jt in c["joints"])
    summary_control[c["name"]] = peak
    print(f"  {c['name']:<16} max {math.degrees(peak):.4g}, joint 1 RMS "
          f"{math.degrees(c['joints'][0]['rms']):.4g}, joint 1 max at reversals "
          f"{math.degrees(c['joints'][0]['max_at_reversal']):.4g}")
with open(os.path.join(out, "summary.json"), "w") as f:
    json.dump({"parameters": rows, "data_rank": result["data_rank"], "rank": result["rank"],
               "not_excited": result["not_excited"], "max_tracking_error": summary_control}, f,
              indent=1)
print(f"\nwrote {os.path.join(out, 'summary.json')}")
