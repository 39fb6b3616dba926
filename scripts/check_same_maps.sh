#!/usr/bin/env bash
# Proves a refactor changes no output: builds maps with two monomap binaries
# (e.g. one from main, one from a branch) on a simulated hallway and the real
# datasets, and compares the map files (points.ply, map.json, textures,
# trajectory, features) and the output of several `eval` subcommands byte for
# byte. Prints IDENTICAL or DIFFERENT per case; exits 1 on any difference.
#
# usage: scripts/check_same_maps.sh REF_BIN NEW_BIN OUTDIR [DATA_DIR]
#   DATA_DIR defaults to /work/shared/data (desk_vamr_a, castle_visp).
# Set SKIP_SECOND_HALF=1 to leave out desk frames 150-299.
set -euo pipefail

if [[ $# -lt 3 ]]; then
  echo "usage: $0 REF_BIN NEW_BIN OUTDIR [DATA_DIR]" >&2
  exit 2
fi
REF=$(realpath "$1")
NEW=$(realpath "$2")
OUT=$3
DATA=${4:-/work/shared/data}
for b in "$REF" "$NEW"; do
  [[ -x $b ]] || { echo "$b: not an executable" >&2; exit 2; }
done
mkdir -p "$OUT"
OUT=$(realpath "$OUT")

status=0
declare -a TABLE

# Records one case: IDENTICAL if every listed file pair is byte-identical.
# $1: case name; $2, $3: the two directories; the rest: files relative to them.
compare_files() {
  local name=$1 a=$2 b=$3
  shift 3
  local result=IDENTICAL detail=""
  for f in "$@"; do
    if [[ ! -e $a/$f || ! -e $b/$f ]]; then
      result=DIFFERENT
      detail+=" missing:$f"
    elif ! cmp -s "$a/$f" "$b/$f"; then
      result=DIFFERENT
      detail+=" $f"
    fi
  done
  [[ $result == IDENTICAL ]] || status=1
  TABLE+=("$(printf '%-44s %-9s %s' "$name" "$result" "$detail")")
}

# Every file of a map directory, sorted (so a missing or extra file counts),
# but the output-kind marker that -o checks (older binaries write none).
map_files() {
  (cd "$1" && find . -type f ! -name .monomap-output | sed 's|^\./||' | sort)
}

compare_maps() {
  local name=$1 a=$2 b=$3
  if [[ "$(map_files "$a")" != "$(map_files "$b")" ]]; then
    status=1
    TABLE+=("$(printf '%-44s %-9s %s' "$name" DIFFERENT "file lists differ")")
    return
  fi
  # shellcheck disable=SC2046
  compare_files "$name ($(map_files "$a" | wc -l) files)" "$a" "$b" \
    $(map_files "$a")
}

# Runs `monomap ARGS...` with both binaries; stdout, stderr and the exit
# status go to OUT/<tag>.{ref,new}.*; the first argument is the tag.
run_both() {
  local tag=$1
  shift
  local which bin
  for which in ref new; do
    bin=$REF
    [[ $which == new ]] && bin=$NEW
    local args=("${@//@WHICH@/$which}")
    set +e
    "$bin" "${args[@]}" >"$OUT/$tag.$which.out" 2>"$OUT/$tag.$which.err"
    echo $? >"$OUT/$tag.$which.rc"
    set -e
  done
}

# An `eval` subcommand on both maps: stdout, its JSON and the exit status.
compare_eval() {
  local name=$1 tag=$2
  shift 2
  run_both "$tag" "$@" --json "$OUT/$tag.@WHICH@.json"
  local f result=IDENTICAL detail=""
  # Output paths in stdout name the run (.ref. / .new.): compare without.
  if ! cmp -s <(sed 's/\.ref\././g' "$OUT/$tag.ref.out") \
    <(sed 's/\.new\././g' "$OUT/$tag.new.out"); then
    result=DIFFERENT
    detail+=" out"
  fi
  for f in rc json; do
    if ! cmp -s "$OUT/$tag.ref.$f" "$OUT/$tag.new.$f"; then
      result=DIFFERENT
      detail+=" $f"
    fi
  done
  [[ $(cat "$OUT/$tag.ref.rc") == 0 ]] || detail+=" (exit $(cat "$OUT/$tag.ref.rc"))"
  [[ $result == IDENTICAL ]] || status=1
  TABLE+=("$(printf '%-44s %-9s %s' "$name" "$result" "$detail")")
}

# Builds a map with both binaries into OUT/<tag>.{ref,new}.
build_both() {
  local tag=$1
  shift
  rm -rf "$OUT/$tag.ref" "$OUT/$tag.new"
  local t0=$SECONDS
  "$REF" build -q "$@" -o "$OUT/$tag.ref"
  local t1=$SECONDS
  "$NEW" build -q "$@" -o "$OUT/$tag.new"
  echo "  $tag: built in $((t1 - t0)) s (ref), $((SECONDS - t1)) s (new)" >&2
}

echo "check_same_maps: ref $REF" >&2
echo "                 new $NEW" >&2

# (a) Simulated hallway: the datasets themselves, then the maps.
echo "hallway: simulating" >&2
rm -rf "$OUT/hallway_data.ref" "$OUT/hallway_data.new"
"$REF" simulate hallway --frames 200 -q -o "$OUT/hallway_data.ref"
"$NEW" simulate hallway --frames 200 -q -o "$OUT/hallway_data.new"
compare_maps "hallway: simulated dataset" "$OUT/hallway_data.ref" \
  "$OUT/hallway_data.new"
HALL=$OUT/hallway_data.ref
build_both hallway "$HALL"
compare_maps "hallway: map" "$OUT/hallway.ref" "$OUT/hallway.new"
compare_eval "hallway: eval structure" hall_structure \
  eval structure "$OUT/hallway.@WHICH@" --structure "$HALL/structure"
compare_eval "hallway: eval trajectory (se3)" hall_traj \
  eval trajectory "$OUT/hallway.@WHICH@/trajectory.txt" "$HALL/groundtruth.txt"
compare_eval "hallway: eval render" hall_render \
  eval render "$OUT/hallway.@WHICH@" "$HALL" --stride 20 --width 160

# (b) desk_vamr_a, first half, and the second half separately.
DESK=$DATA/desk_vamr_a
build_both desk_a "$DESK" --first-frame 0 --frames 150
compare_maps "desk_vamr_a 0-149: map" "$OUT/desk_a.ref" "$OUT/desk_a.new"
compare_eval "desk_vamr_a 0-149: eval points --plane" desk_points \
  eval points "$OUT/desk_a.@WHICH@" --plane "$DESK/groundtruth_structure.yaml"
compare_eval "desk_vamr_a 0-149: eval planes" desk_planes \
  eval planes "$OUT/desk_a.@WHICH@" --plane "$DESK/groundtruth_structure.yaml"
compare_eval "desk_vamr_a 0-149: eval checkerboard" desk_board \
  eval checkerboard "$OUT/desk_a.@WHICH@" \
  --structure "$DESK/groundtruth_structure.yaml"
compare_eval "desk_vamr_a 0-149: eval lens" desk_lens \
  eval lens "$OUT/desk_a.@WHICH@"
compare_eval "desk_vamr_a 0-149: eval trajectory (first)" desk_traj \
  eval trajectory "$OUT/desk_a.@WHICH@/trajectory.txt" \
  "$DESK/groundtruth.txt" --align first
compare_eval "desk_vamr_a: eval board-poses (0-59)" desk_board_poses \
  eval board-poses "$DESK" --structure "$DESK/groundtruth_structure.yaml" \
  --frames 60 -o "$OUT/desk_board_poses.@WHICH@.txt"
if cmp -s "$OUT/desk_board_poses.ref.txt" "$OUT/desk_board_poses.new.txt"; then
  TABLE+=("$(printf '%-44s %-9s' "desk_vamr_a: board-poses trajectory" IDENTICAL)")
else
  status=1
  TABLE+=("$(printf '%-44s %-9s' "desk_vamr_a: board-poses trajectory" DIFFERENT)")
fi
if [[ ${SKIP_SECOND_HALF:-0} != 1 ]]; then
  build_both desk_b "$DESK" --first-frame 150 --frames 150
  compare_maps "desk_vamr_a 150-299: map" "$OUT/desk_b.ref" "$OUT/desk_b.new"
fi

# (c) castle_visp.
CASTLE=$DATA/castle_visp
build_both castle "$CASTLE"
compare_maps "castle_visp: map" "$OUT/castle.ref" "$OUT/castle.new"
compare_eval "castle_visp: eval points --surface" castle_points \
  eval points "$OUT/castle.@WHICH@" --surface "$CASTLE/groundtruth_surface.ply"
compare_eval "castle_visp: eval planes --surface" castle_planes \
  eval planes "$OUT/castle.@WHICH@" --surface "$CASTLE/groundtruth_surface.ply"

echo
printf '%-44s %-9s %s\n' "case" "result" "differing files"
for row in "${TABLE[@]}"; do echo "$row"; done
if [[ $status == 0 ]]; then
  echo "ALL IDENTICAL"
else
  echo "SOME DIFFERENT"
fi
exit $status
