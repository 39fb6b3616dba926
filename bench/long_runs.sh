#!/usr/bin/env bash
# Long runs: build time, bundle adjustment time and peak memory of
# `monomap build` over the sequence length, on one slow simulated hallway
# run (5,000 frames fit its 8.4 m path at 0.05 m/s and 30 Hz). Each length
# is the first N frames of that run, built in its own process; peak memory
# is the process's maximum RSS (/usr/bin/time -v). Prints a markdown table.
#
# usage: bench/long_runs.sh MONOMAP_BIN OUTDIR [FRAMES...]
#   FRAMES defaults to 500 1000 2000 5000. The dataset is simulated into
#   OUTDIR/hallway_slow once (about 0.8 GB, ~6 min) and reused.
set -euo pipefail

if [[ $# -lt 2 ]]; then
  echo "usage: $0 MONOMAP_BIN OUTDIR [FRAMES...]" >&2
  exit 2
fi
M=$(realpath "$1")
OUT=$2
shift 2
FRAMES=("$@")
[[ ${#FRAMES[@]} -gt 0 ]] || FRAMES=(500 1000 2000 5000)
[[ -x $M ]] || { echo "$M: not an executable" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "/usr/bin/time is needed (apt-get install time)" >&2; exit 2; }
mkdir -p "$OUT"
DATA=$OUT/hallway_slow
MAX=0
for n in "${FRAMES[@]}"; do ((n > MAX)) && MAX=$n; done

if [[ ! -f $DATA/rgb.txt ]] || (($(grep -vc '^#' "$DATA/rgb.txt") < MAX)); then
  echo "simulating $MAX frames into $DATA" >&2
  "$M" simulate hallway --frames "$MAX" --speed 0.05 -q -o "$DATA"
fi

echo "| frames | build (s) | bundle adjustment (s) | peak memory (MB) | keyframes | joint points | BA residuals | linear solver |"
echo "|---|---|---|---|---|---|---|---|"
for n in "${FRAMES[@]}"; do
  map=$OUT/map_$n
  /usr/bin/time -v "$M" build "$DATA" --frames "$n" -q -o "$map" \
    --report "$OUT/report_$n.json" 2>"$OUT/time_$n.txt" >/dev/null
  peak_kb=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$OUT/time_$n.txt")
  python3 - "$OUT/report_$n.json" "$n" "$peak_kb" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
ba = r["bundle_adjustment"]
t = r["timings_seconds"]
print(f"| {sys.argv[2]} | {r['total_seconds']:.1f} | {t.get('bundle_adjustment', 0):.1f} "
      f"| {int(sys.argv[3]) / 1024:.0f} | {ba['poses']} | {ba['points_joint']} "
      f"| {ba.get('residuals', '')} | {ba['linear_solver']} |")
PY
done
