#!/usr/bin/env bash
# The desk_vamr_a localization benchmark of issue 5, end to end: map frames
# 1-150, localize frames 151-300 (6-DoF, pose init), in three
# configurations, over seeds; median errors against groundtruth.txt and
# against board poses under a lens refitted on frames 151-300 (held out
# from the mapping frames). Figures and their discussion:
# docs/benchmarks.md ("Desk localization" and "Desk orientation: the
# ground truth's own error").
#
#   scripts/desk_localization.sh [DATASET] [OUT_DIR] [SEEDS]
#   defaults: ../shared/data/desk_vamr_a /tmp/desk_localization 5
set -euo pipefail
cd "$(dirname "$0")/.."
M=build/src/monomap/exe/monomap
D=${1:-../shared/data/desk_vamr_a}
OUT=${2:-/tmp/desk_localization}
SEEDS=${3:-5}
S=$D/groundtruth_structure.yaml
[ -x "$M" ] || { echo "desk_localization: build first (make build)" >&2; exit 1; }
[ -f "$S" ] || { echo "desk_localization: $S: no such file" >&2; exit 1; }
mkdir -p "$OUT"

# Median rotation (deg) and translation (mm) of the absolute error.
medians() {
  "$M" eval trajectory "$1" "$2" --align none |
    awk '/^translation/ && !t {t = $5} /^rotation/ && !r {r = $5}
         END {printf "%s mm / %s deg", t, r}'
}

"$M" calibrate "$D" --frames 150 -o "$OUT/cal_f1.yaml" > /dev/null
"$M" calibrate "$D" --first-frame 150 -o "$OUT/cal_f2.yaml" > /dev/null
"$M" eval board-poses "$D" --structure "$S" --camera "$OUT/cal_f2.yaml" \
  --anchor "$D/odometry.txt" -o "$OUT/ref_f2.txt" > /dev/null
grep -v '^#' "$D/odometry.txt" | tail -n +151 > "$OUT/odometry_151.txt"
echo "odometry, frames 151-300: vs ground truth $(medians "$OUT/odometry_151.txt" "$D/groundtruth.txt"), vs board poses $(medians "$OUT/odometry_151.txt" "$OUT/ref_f2.txt")"

SPAN="--odometry-rotation-sigma-deg 0.1 --odometry-span 10"
LENS="--camera $OUT/cal_f1.yaml"
# The refitted lens' maps leave bundle adjustment's outlier solve and the
# tracker's track splitting out: with this lens each costs orientation
# (docs/benchmarks.md, "Desk localization").
BUILD_LENS="$LENS --ba-outlier-threshold 0 --no-split-tracks"
# The estimate's refinement pays only with the refitted lens (MccCorrection-
# Options::refine_estimate), so the refitted configurations turn it on.
REFINE="--refine-width 1024"
configs=(
  "defaults||"
  "refitted lens, 320 px, refinement|$BUILD_LENS --max-image-radius 320|$LENS $REFINE"
  "refitted lens, 320 px, span priors, refinement|$BUILD_LENS --max-image-radius 320 $SPAN|$LENS $REFINE"
)
for i in "${!configs[@]}"; do
  IFS='|' read -r name build_opts loc_opts <<< "${configs[$i]}"
  map="$OUT/map_$i"
  # shellcheck disable=SC2086  # the option strings are word lists
  "$M" build "$D" -o "$map" --frames 150 -q $build_opts
  for seed in $(seq 1 "$SEEDS"); do
    traj="$OUT/loc_${i}_$seed.txt"
    # shellcheck disable=SC2086
    "$M" localize "$map" "$D" $loc_opts --first-frame 150 --state 6dof \
      --init pose --method mcc --particles 1000 --seed "$seed" -o "$traj" \
      > /dev/null 2>&1
    echo "$name, MCC seed $seed: vs ground truth $(medians "$traj" "$D/groundtruth.txt"), vs board poses $(medians "$traj" "$OUT/ref_f2.txt")"
  done
done
