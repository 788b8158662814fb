#!/usr/bin/env bash
# The experiments of B. Bona, A. Curatella, "Closed-loop rigid model identification of an
# industrial robot" (2005), Section 3, replayed in simulation on the built-in comau-s2 (a 6-joint
# arm of the size of their COMAU Smart-3 S2, friction of their Table 2; examples/robots/comau-s2.yaml)
# under a plain PID (the loop feeds the sensor noise back into the torque):
#   1. gravity of joints 2 and 3 from two constant-velocity slopes (Table 1);
#   2. friction of every joint from bang-bang moves, inertia and gravity compensated (Table 2);
#   3. a 5-harmonic Fourier reference at f0 = 0.1 Hz, ONE JOINT AT A TIME (the others held),
#      PERIODS periods each, averaged into one period, low-passed by an 8th-order Chebyshev at
#      80 Hz and resampled at 200 Hz (dynid average --filter --cutoff --decimate), then the
#      spectral projection (lines of f0 up to the band, analytic derivatives) and least squares
#      on the union of the six runs with the friction of step 2 subtracted (Table 3);
#   4. validation by simulation on trapezoidal references, one joint at a time (Fig. 8);
#   5. the computed-torque controller built from the identified model against the PID (Fig. 9).
# Prints Tables 1-3 with the truth beside them, what the one-joint runs cannot determine, and the
# tracking errors; writes summary.json (truth and interval of every estimate) for the test.
#
# Usage: examples/comau-s2/run.sh [OUT_DIR]   (default comau-s2-out; DYNID=path/to/dynid)
# Environment: PERIODS (25, as in the paper), RATE (control and logging rate, 1000 Hz as in the
#   paper; a multiple of 200, the rate the averaged periods are resampled to), SEED (1). Runtime
#   measured 2026-12-02 on a 2-core Intel Xeon VM shared with other builds (load average 3-6):
#   17-21 s wall clock (17-21 s of CPU) with the defaults; PERIODS=3 RATE=200 (the test's
#   setting) 5 s wall clock.
set -euo pipefail
if [ $# -gt 1 ]; then
  echo "usage: $0 [OUT_DIR]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-comau-s2-out}
dynid=${DYNID:-$here/../../build/dynid}
periods=${PERIODS:-25}
rate=${RATE:-1000}
seed=${SEED:-1}
# simulate logs the torque computed at t, held over the next step: it acts half a step later.
offset=(--torque-offset "$(awk -v r="$rate" 'BEGIN { print 0.5 / r }')")
[ -x "$dynid" ] || { echo "error: $dynid not found; build it first with ./scripts/build" >&2; exit 1; }
command -v python3 >/dev/null || { echo "error: python3 is needed to print the tables" >&2; exit 1; }
[ "$periods" -ge 2 ] || { echo "error: PERIODS must be >= 2 (the first is a transient)" >&2; exit 2; }
[ $((rate % 200)) -eq 0 ] && [ "$rate" -gt 0 ] ||
  { echo "error: RATE must be a positive multiple of 200 Hz (the averaged periods are resampled to 200 Hz)" >&2; exit 2; }
mkdir -p "$out"
robot=comau-s2
f0=0.1
# Sensors: encoder noise (rad) much smaller than torque noise (N m), as in the paper's Fig. 5.
noise=(--position-noise 2e-5 --torque-noise 0.5)
sim() {  # sim REFERENCE RUN PERIODS SEED
  "$dynid" simulate --robot $robot --engine native --controller pid --trajectory "$1" \
    --out "$2" --periods "$3" --seed "$4" "${noise[@]}" > "$2.log"
}
"$dynid" model --robot $robot --base --json "$out/model.json" > "$out/model.txt"

# 1. Gravity slopes (Table 1): joint J from -R to R and back at 0.3 rad/s, the others at 0.
for j in 2 3; do
  "$dynid" excite --robot $robot --family slope --joint $j --range -0.6:0.6 --velocity 0.3 \
    --acceleration 1 --rate "$rate" --out "$out/slope_$j.csv" > /dev/null
  sim "$out/slope_$j.csv" "$out/slope_run_$j.csv" 1 $((seed + j))
  "$dynid" identify --robot $robot --model gravity --joint $j --data "$out/slope_run_$j.csv" "${offset[@]}" \
    --out "$out/gravity_$j.json" > "$out/gravity_$j.log" 2>&1
done

# The truth of Table 1 (for the printout only): the gravity torques at q2 = pi/2, at 0 and at
# q3 = pi/2, the other joints at 0.
{
  printf 't,q1,q2,q3,q4,q5,q6,dq1,dq2,dq3,dq4,dq5,dq6,ddq1,ddq2,ddq3,ddq4,ddq5,ddq6\n'
  printf '0,0,1.5707963267948966,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n'
  printf '1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n'
  printf '2,0,0,1.5707963267948966,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n'
} > "$out/gravity_states.csv"
"$dynid" inverse-dynamics --robot $robot --no-friction --in "$out/gravity_states.csv" \
  --out "$out/gravity_truth.csv"

# 2. Bang-bang friction (Table 2), every joint, compensated with the nominal model.
for j in 1 2 3 4 5 6; do
  "$dynid" excite --robot $robot --family bang-bang --joint $j --range -0.6:0.6 --acceleration 2 \
    --cycles 2 --rate "$rate" --out "$out/bang_$j.csv" > /dev/null
  sim "$out/bang_$j.csv" "$out/bang_run_$j.csv" 1 $((seed + 10 + j))
  "$dynid" identify --robot $robot --model friction --joint $j --data "$out/bang_run_$j.csv" "${offset[@]}" \
    --out "$out/friction_$j.json" > "$out/friction_$j.log" 2>&1
done

# 3. Fourier, one joint at a time: one period of q_J(t) = c + g*sum_k sin(2 pi k f0 t + phi_k)/k,
# k = 1..5, Schroeder phases phi_k = -pi k (k-1)/5 (low crest factor), scaled to the range LO:HI,
# the other joints at 0; velocities and accelerations analytic (dynid excite --family fourier
# --joint J). --no-rest: the reference is repeated PERIODS times and its first period dropped, so
# it need not start at rest.
fourier() {  # fourier J LO:HI OUT
  "$dynid" excite --robot $robot --family fourier --joint "$1" --range "$2" --harmonics 5 \
    --f0 $f0 --no-rest --rate "$rate" --out "$3" > /dev/null
}
ranges=(-1.2:1.2 -0.8:0.6 -0.9:0.9 -1.5:1.5 -1.2:1.2 -1.5:1.5)
data=()
for j in 1 2 3 4 5 6; do
  fourier $j "${ranges[$((j - 1))]}" "$out/fourier_$j.csv"
  sim "$out/fourier_$j.csv" "$out/fourier_run_$j.csv" "$periods" $((seed + 20 + j))
  # The first period is the loop's transient; the others are averaged into one, which is then
  # low-passed (Chebyshev 8 at 80 Hz, zero phase, circular: it is one period of a periodic
  # signal) and resampled at 200 Hz, as in the paper's section 3.4. The reference columns are
  # left as logged.
  "$dynid" average --data "$out/fourier_run_$j.csv" --f0 $f0 --skip-periods 1 \
    --filter chebyshev:8 --cutoff 80 --decimate $((rate / 200)) \
    --out "$out/avg_$j.tmp.csv" --json "$out/noise_$j.json" > "$out/average_$j.log" 2>&1
  # The averaged period starts at a reference period's start: the reference's analytic derivatives
  # join it as dqr*, ddqr* (they tell the spectral projection that this one period is periodic),
  # at the kept samples (every RATE/200-th).
  rows=$(($(wc -l < "$out/avg_$j.tmp.csv") - 1))
  awk -F, -v rows="$rows" -v dec=$((rate / 200)) 'NR == 1 { h = "dqr1"; for (j = 2; j <= 6; ++j) h = h ",dqr" j;
      for (j = 1; j <= 6; ++j) h = h ",ddqr" j; print h; next }
    (NR - 2) % dec == 0 && (NR - 2) / dec < rows { s = $8; for (c = 9; c <= 19; ++c) s = s "," $c; print s }' \
    "$out/fourier_$j.csv" | paste -d, "$out/avg_$j.tmp.csv" - > "$out/avg_$j.csv"
  rm "$out/avg_$j.tmp.csv"
  data+=(--data "$out/avg_$j.csv")
done
known=()
for j in 1 2 3 4 5 6; do known+=(--friction-known "$out/friction_$j.json"); done
"$dynid" identify --robot $robot "${data[@]}" --closed-loop spectral "${known[@]}" "${offset[@]}" \
  --out "$out/result.json" > "$out/identify.log" 2>&1

# 4. Validation by simulation on trapezoids, one joint at a time (the identified model, friction
# of step 2 included, simulated under the same PID and compared with the plant's run).
for j in 1 2 3 4 5 6; do
  "$dynid" excite --robot $robot --family trapezoid --joint $j --range -0.5:0.5 --velocity 0.5 \
    --acceleration 2 --rate "$rate" --out "$out/trapezoid_$j.csv" > /dev/null
  sim "$out/trapezoid_$j.csv" "$out/trapezoid_run_$j.csv" 2 $((seed + 30 + j))
  # The one-joint runs leave parameters badly determined (see Table 3); validate fills them with
  # the nominal model's values and says which (parameter_sources in the JSON, warnings in the log).
  "$dynid" validate --mode simulation --robot $robot --params "$out/result.json" \
    --data "$out/trapezoid_run_$j.csv" --trajectory "$out/trapezoid_$j.csv" --engine native \
    --controller pid --json "$out/validation_$j.json" > "$out/validation_$j.log" 2>&1
done

# 5. Computed torque from the identified model against the PID, on joint 1's Fourier reference
# (the paper's Fig. 9 is axis 1).
"$dynid" compare-control --robot $robot --params "$out/result.json" \
  --trajectory "$out/fourier_1.csv" --engine native --periods 2 --json "$out/control.json" \
  > "$out/control.log" 2>&1

python3 "$here/tables.py" "$out"
