#!/usr/bin/env bash
# Checks that two monomap binaries localize identically: the trajectory
# (-o) and the particle sets (--particles-out) byte for byte, and the report
# (--report) value for value except its timings (see same_report). Cases: a simulated
# hallway (planar and 6-DoF, MCL and MCC, pose and global init) and, when
# the dataset is there, the real desk_vamr_a (6-DoF, frames 151-300).
# Datasets and maps are made once with REF_BIN and reused from OUTDIR.
#
#   scripts/check_same_localization.sh REF_BIN NEW_BIN OUTDIR [DESK_DATASET]
#   DESK_DATASET defaults to /work/shared/data/desk_vamr_a (skipped if absent)
#
# Prints one line per case, IDENTICAL or DIFFERENT (naming what differs);
# exits 1 if any case differs, 2 on a usage or run error.
set -uo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 REF_BIN NEW_BIN OUTDIR [DESK_DATASET]" >&2
  exit 2
fi
REF=$(realpath "$1")
NEW=$(realpath "$2")
OUT=$3
DESK=${4:-/work/shared/data/desk_vamr_a}
for b in "$REF" "$NEW"; do
  [ -x "$b" ] || { echo "$0: $b: not an executable" >&2; exit 2; }
done
mkdir -p "$OUT"

run() {  # run LOG CMD...: runs CMD, exits 2 with its log if it fails
  local log=$1
  shift
  if ! "$@" > "$log" 2>&1; then
    echo "$0: failed: $*" >&2
    tail -5 "$log" >&2
    exit 2
  fi
}

# The data, made once.
HALL=$OUT/hall
if [ ! -f "$OUT/hallmap/map.json" ]; then
  run "$OUT/simulate.log" "$REF" simulate hallway -o "$HALL" --frames 200
  run "$OUT/build_hall.log" "$REF" build "$HALL" -o "$OUT/hallmap" -q
fi
if [ -d "$DESK" ] && [ ! -f "$OUT/deskmap/map.json" ]; then
  run "$OUT/build_desk.log" "$REF" build "$DESK" -o "$OUT/deskmap" \
    --frames 150 -q
fi

# Compares two reports without their wall-clock and CPU times. Keys, counts and
# flags must be equal; numbers equal or within 1e-12 relative (the rotation
# errors come from eval/localization_accuracy, which converts radians to
# degrees as x * (180 / pi) where the old localizer used x / (pi / 180): a
# last-bit difference). Prints the keys that differ (exit 1), or those that
# differ in the last bits only (exit 0).
same_report() {
  python3 - "$1" "$2" <<'PY'
import json, math, sys
timing = {"seconds", "mean_step_seconds", "weigh_seconds", "mcc_seconds",
          "cpu_seconds"}
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in timing}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
def close(x, y):
    if type(x) != type(y):
        return False
    if isinstance(x, dict):
        return x.keys() == y.keys() and all(close(x[k], y[k]) for k in x)
    if isinstance(x, list):
        return len(x) == len(y) and all(map(close, x, y))
    if isinstance(x, float):
        return math.isclose(x, y, rel_tol=1e-12, abs_tol=1e-15)
    return x == y
a, b = (strip(json.load(open(p))) for p in sys.argv[1:3])
keys = sorted(set(a) | set(b))
differ = [k for k in keys if not close(a.get(k), b.get(k))]
if differ:
    print(",".join(differ))
    sys.exit(1)
print(",".join(k for k in keys if a.get(k) != b.get(k)))
PY
}

status=0
check() {  # check NAME MAP DATASET ARGS...
  local name=$1 map=$2 data=$3
  shift 3
  local d=$OUT/cases/$name
  mkdir -p "$d"
  for which in ref new; do
    local bin=$REF
    [ "$which" = new ] && bin=$NEW
    run "$d/$which.log" "$bin" localize "$map" "$data" "$@" \
      -o "$d/$which.txt" --particles-out "$d/$which.csv" \
      --report "$d/$which.json"
  done
  local what=""
  cmp -s "$d/ref.txt" "$d/new.txt" || what+=" trajectory"
  cmp -s "$d/ref.csv" "$d/new.csv" || what+=" particles"
  local fields
  fields=$(same_report "$d/ref.json" "$d/new.json") || what+=" report($fields)"
  if [ -z "$what" ]; then
    local note=""
    [ -n "$fields" ] && note="; report $fields equal to 1e-12"
    printf '%-26s IDENTICAL (%d poses, %d particle rows%s)\n' "$name" \
      "$(grep -vc '^#' "$d/ref.txt")" "$(($(wc -l < "$d/ref.csv") - 1))" \
      "$note"
  else
    printf '%-26s DIFFERENT:%s\n' "$name" "$what"
    status=1
  fi
}

H="--first-frame 100 --frames 30 --particles 500"
check hall_planar_mcl_pose "$OUT/hallmap" "$HALL" $H --method mcl --init pose
check hall_planar_mcc_pose "$OUT/hallmap" "$HALL" $H --method mcc --init pose
check hall_planar_mcl_global "$OUT/hallmap" "$HALL" $H --method mcl \
  --init global --seed 3
check hall_planar_mcc_global "$OUT/hallmap" "$HALL" $H --method mcc \
  --init global --seed 3
check hall_6dof_mcl_pose "$OUT/hallmap" "$HALL" $H --method mcl --init pose \
  --state 6dof
check hall_6dof_mcc_pose "$OUT/hallmap" "$HALL" $H --method mcc --init pose \
  --state 6dof
check hall_6dof_mcc_global "$OUT/hallmap" "$HALL" $H --method mcc \
  --init global --state 6dof --seed 2
if [ -d "$DESK" ]; then
  D="--first-frame 150 --state 6dof --init pose"
  check desk_6dof_mcc_pose "$OUT/deskmap" "$DESK" $D --method mcc
  check desk_6dof_mcl_pose "$OUT/deskmap" "$DESK" $D --method mcl \
    --frames 60 --particles 500
else
  echo "desk: $DESK not found, skipped"
fi
exit $status
