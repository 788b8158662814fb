#!/usr/bin/env bash
# Identifies the Staubli TX40 from the FIGAROH motor-side run shipped in dataset/ (SOURCE.md there;
# Apache-2.0, LICENSE and NOTICE beside it).
# Usage: examples/staubli-tx40/run.sh [OUT_DIR [DATASET_DIR]]
#   OUT_DIR defaults to tx40-out, DATASET_DIR to the copy next to this script; writes
#   OUT_DIR/result.json. Extra dynid identify options can be passed in DYNID_OPTIONS.
# The data set has positions and torques in two files with a header and no time column, sampled
# at 5 kHz (ts = 0.2 ms, config/T40X_config.yaml): they are joined into one motor-side run
# (qm1..qm6, taum1..taum6) and identified through the model's transmission (gear ratios and the
# coupled wrist).
set -euo pipefail
if [ $# -gt 2 ]; then
  echo "usage: $0 [OUT_DIR [DATASET_DIR]]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-tx40-out}
data=${2:-$here/dataset}
dynid=${DYNID:-$here/../../build/dynid}
[ -x "$dynid" ] || { echo "error: $dynid not found; build it first with ./scripts/build" >&2; exit 1; }
for f in "$data/data/pos_read_data.csv" "$data/data/curr_data.csv"; do
  [ -f "$f" ] || { echo "error: missing $f; give the staubli-tx40 data set folder" >&2; exit 1; }
done
mkdir -p "$out"
run="$out/tx40_run.csv"
{
  echo "qm1,qm2,qm3,qm4,qm5,qm6,taum1,taum2,taum3,taum4,taum5,taum6"
  paste -d, <(tail -n +2 "$data/data/pos_read_data.csv") <(tail -n +2 "$data/data/curr_data.csv")
} > "$run.tmp"
mv "$run.tmp" "$run"
# shellcheck disable=SC2086
"$dynid" identify --robot "$here/tx40.yaml" --data "$run" --rate 5000 --out "$out/result.json" \
  ${DYNID_OPTIONS:-}
