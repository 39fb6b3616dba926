#!/usr/bin/env bash
# The issue-18 generalization set: every change to a mapping default is judged
# over all of it, never over one sequence. Simulates corridors and rooms at
# several seeds, camera heights, pitches and frame rates, builds a map of each
# and scores it with `eval structure` (over ALL exported points); adds the real
# desk halves (frames 0-149 and 150-299, built separately; `eval points
# --plane` over all exported points and over the board, and `eval planes`)
# and castle_visp.
# Writes OUTDIR/generalization.json and OUTDIR/generalization.md.
#
# usage: scripts/generalization_set.sh MONOMAP OUTDIR [DATA_DIR] [-- BUILD_ARGS...]
#   BUILD_ARGS go to every `monomap build` (to compare an opt-in option).
#   FRAMES (default 150) caps the simulated frames per run, to keep the set at
#   minutes on a shared 2-core machine. SIM_DIR (default OUTDIR) holds the
#   simulated datasets, so that two binaries can be compared on the same data.
set -euo pipefail

if [[ $# -lt 2 ]]; then
  echo "usage: $0 MONOMAP OUTDIR [DATA_DIR] [-- BUILD_ARGS...]" >&2
  exit 2
fi
BIN=$(realpath "$1")
OUT=$2
shift 2
DATA=/work/shared/data
if [[ $# -gt 0 && $1 != -- ]]; then DATA=$1; shift; fi
[[ $# -gt 0 && $1 == -- ]] && shift
BUILD_ARGS=("$@")
FRAMES=${FRAMES:-100}
SIM_DIR=${SIM_DIR:-}
# SIM_ARGS: more `monomap simulate` options for every world (e.g.
# "--floor-tilt 0.3" for an uneven floor); use another SIM_DIR with them.
read -r -a SIM_ARGS <<<"${SIM_ARGS:-}"
[[ -x $BIN ]] || { echo "$BIN: not an executable" >&2; exit 2; }
mkdir -p "$OUT"
OUT=$(realpath "$OUT")

# name world seed camera_height_m tilt_deg fps speed_mps
# office: L-shaped corridor with a turn, recessed doors, skirting boards,
# plain stretches; room: boxes as furniture; lab-corner: whiteboard off a wall.
SIM_CASES=(
  "office_s1_h0.4_p10_f10 office 1 0.4 10 10 0.3"
  "office_s2_h0.4_p10_f10 office 2 0.4 10 10 0.3"
  "office_s3_h0.3_p20_f15 office 3 0.3 20 15 0.3"
  "office_s4_h1.5_p0_f30  office 4 1.5 0 30 0.6"
  "room_s1_h0.8_p5_f10    room 1 0.8 5 10 0.3"
  "room_s2_h1.2_p15_f20   room 2 1.2 15 20 0.4"
  "room_s3_h0.4_p0_f15    room 3 0.4 0 15 0.3"
  "labcorner_s3_h0.5_p10_f10 lab-corner 3 0.5 10 10 0.3"
)

t_start=$SECONDS
for c in "${SIM_CASES[@]}"; do
  read -r name world seed h p fps speed <<<"$c"
  d=${SIM_DIR:-$OUT}/data_$name
  if [[ ! -f $d/.done ]]; then
    rm -rf "$d"
    "$BIN" simulate "$world" --seed "$seed" --camera-height "$h" \
      --camera-tilt "$p" --fps "$fps" --speed "$speed" --frames "$FRAMES" \
      "${SIM_ARGS[@]}" -q -o "$d"
    touch "$d/.done"
  fi
  rm -rf "$OUT/map_$name"
  t0=$SECONDS
  "$BIN" build -q "$d" -o "$OUT/map_$name" --report "$OUT/report_$name.json" \
    "${BUILD_ARGS[@]}"
  echo $((SECONDS - t0)) >"$OUT/time_$name.txt"
  "$BIN" eval structure "$OUT/map_$name" --structure "$d/structure" \
    --json "$OUT/eval_$name.json" >/dev/null
  # The map's own geometry: its scale and frame are the odometry's (a
  # wheel-radius error scales the whole map), so also score it after the
  # similarity that best fits its trajectory to the truth.
  "$BIN" eval structure "$OUT/map_$name" --structure "$d/structure" \
    --align sim3-poses --groundtruth "$d/groundtruth.txt" \
    --json "$OUT/eval_sim3_$name.json" >/dev/null
  echo "  $name: $((SECONDS - t0)) s" >&2
done

DESK=$DATA/desk_vamr_a
for half in "0 a" "150 b"; do
  read -r first tag <<<"$half"
  name=desk_$tag
  rm -rf "$OUT/map_$name"
  t0=$SECONDS
  "$BIN" build -q "$DESK" --first-frame "$first" --frames 150 \
    -o "$OUT/map_$name" --report "$OUT/report_$name.json" "${BUILD_ARGS[@]}"
  echo $((SECONDS - t0)) >"$OUT/time_$name.txt"
  "$BIN" eval points "$OUT/map_$name" --plane "$DESK/groundtruth_structure.yaml" \
    --json "$OUT/eval_$name.json" >/dev/null
  "$BIN" eval planes "$OUT/map_$name" --plane "$DESK/groundtruth_structure.yaml" \
    --json "$OUT/evalplanes_$name.json" >/dev/null
  # Issue 18's protocol: the points over the board, also in the ground
  # truth's frame (the map's is the odometry's).
  "$BIN" eval points "$OUT/map_$name" --plane "$DESK/groundtruth_structure.yaml" \
    --over-board --json "$OUT/evalboard_$name.json" >/dev/null
  "$BIN" eval points "$OUT/map_$name" --plane "$DESK/groundtruth_structure.yaml" \
    --over-board --align sim3-poses --groundtruth "$DESK/groundtruth.txt" \
    --json "$OUT/evalboard_sim3_$name.json" >/dev/null
  echo "  $name: $((SECONDS - t0)) s" >&2
done
CASTLE=$DATA/castle_visp
rm -rf "$OUT/map_castle"
t0=$SECONDS
"$BIN" build -q "$CASTLE" -o "$OUT/map_castle" --report "$OUT/report_castle.json" \
  "${BUILD_ARGS[@]}"
echo $((SECONDS - t0)) >"$OUT/time_castle.txt"
"$BIN" eval points "$OUT/map_castle" --surface "$CASTLE/groundtruth_surface.ply" \
  --json "$OUT/eval_castle.json" >/dev/null
"$BIN" eval planes "$OUT/map_castle" --surface "$CASTLE/groundtruth_surface.ply" \
  --json "$OUT/evalplanes_castle.json" >/dev/null
echo "generalization set: $((SECONDS - t_start)) s in all" >&2

python3 "$(dirname "$0")/generalization_table.py" "$OUT" "${SIM_CASES[@]}"
