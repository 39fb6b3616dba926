#!/usr/bin/env bash
# How well lens self-calibration's marginal standard deviations describe its
# error: simulated hallways (the true lens given, so the truth is known)
# over world seeds and run seeds (other image noise, exposure and odometry
# errors), each built with `build --refine-intrinsics --lens-no-halves-check`.
# Prints per run the whole-sequence candidate's fx, k1, k2, each with its
# error in marginal stds (z), then per world and over all runs the mean and
# rms of z: rms 1 means the stds are right, a mean far from 0 is a bias.
#
# usage: scripts/lens_std_check.sh MONOMAP [WORLD_SEEDS] [RUN_SEEDS]
#   e.g. scripts/lens_std_check.sh build/src/monomap/exe/monomap "1 2 3" "$(seq 101 108)"
set -euo pipefail

if [[ $# -lt 1 ]]; then
  echo "usage: $0 MONOMAP [WORLD_SEEDS] [RUN_SEEDS]" >&2
  exit 2
fi
BIN=$(realpath "$1")
WORLDS=${2:-1 2 3}
RUNS=${3:-$(seq 101 108)}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

for w in $WORLDS; do
  for r in $RUNS; do
    "$BIN" simulate hallway --seed "$w" --run-seed "$r" --frames 200 \
      -o "$TMP/data" > /dev/null
    "$BIN" build "$TMP/data" --refine-intrinsics --lens-no-halves-check -q \
      -o "$TMP/map" --report "$TMP/r_${w}_${r}.json" > /dev/null
    rm -rf "$TMP/data" "$TMP/map"
  done
done

python3 - "$TMP" <<'EOF'
import glob, json, math, os, sys

# The build was given the simulator's true lens: the report's "before".
KEYS = ("fx", "k1", "k2")
z = {}
print("| world | run | fx (z) | k1 (z) | k2 (z) |\n|---|---|---|---|---|")
for path in sorted(glob.glob(os.path.join(sys.argv[1], "r_*.json"))):
    w, r = os.path.basename(path)[2:-5].split("_")
    lens = json.load(open(path))["bundle_adjustment"]["intrinsics"]
    cells = []
    for k in KEYS:
        truth = lens["before"][k]
        value, std = lens["candidate"][k], lens["posterior_std"][k]
        z.setdefault((w, k), []).append((value - truth) / std)
        cells.append("%.4g (%+.2f)" % (value, z[(w, k)][-1]))
    print("| %s | %s | %s |" % (w, r, " | ".join(cells)))

def summary(values):
    return "mean %+.2f, rms %.2f" % (
        sum(values) / len(values),
        math.sqrt(sum(v * v for v in values) / len(values)))

print("\n| world | fx z | k1 z | k2 z |\n|---|---|---|---|")
worlds = sorted({w for w, _ in z})
for w in worlds + ["all"]:
    cols = [summary([v for (ww, kk), vs in z.items() for v in vs
                     if kk == k and (w == "all" or ww == w)]) for k in KEYS]
    print("| %s | %s |" % (w, " | ".join(cols)))
EOF
