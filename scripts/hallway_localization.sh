#!/usr/bin/env bash
# MCC localization on the simulated hallway's maps, compared between build
# options: for each world seed, `monomap demo` makes the mapping run and a
# second traversal (60 frames); each configuration builds a map of the first
# and localizes the second from a global start (planar, 1500 particles) with
# several filter seeds. Prints the mean errors after convergence with one
# rigid offset removed (the map's frame is its odometry's) and absolute.
#
#   scripts/hallway_localization.sh MONOMAP OUT_DIR "WORLD_SEEDS" "FILTER_SEEDS" \
#       LABEL="BUILD ARGS" [LABEL="BUILD ARGS" ...]
#   e.g. ... /tmp/hl "1 2 3" "3 4 5" huber="" cauchy="--ba-loss cauchy"
set -euo pipefail
if [[ $# -lt 5 ]]; then
  sed -n '9,11p' "$0" >&2
  exit 2
fi
M=$(realpath "$1")
OUT=$2
WORLDS=$3
SEEDS=$4
shift 4
mkdir -p "$OUT"
echo "| world | configuration | rotation, rigid (deg) | translation, rigid (mm) | rotation, absolute (deg) |"
echo "|---|---|---|---|---|"
for w in $WORLDS; do
  d=$OUT/world_$w
  if [[ ! -f $d/.done ]]; then
    "$M" demo --seed "$w" --frames 200 --localization-frames 60 \
      --particles 500 -q -o "$d" > /dev/null
    touch "$d/.done"
  fi
  for config in "$@"; do
    label=${config%%=*}
    read -r -a args <<< "${config#*=}"
    rm -rf "$d/map_$label"
    "$M" build -q "$d/dataset" -o "$d/map_$label" ${args[@]+"${args[@]}"}
    for s in $SEEDS; do
      "$M" localize "$d/map_$label" "$d/localization_dataset" \
        -o "$d/${label}_$s.tum" --method mcc --init global --state planar \
        --particles 1500 --seed "$s" --report "$d/${label}_$s.json" 2> /dev/null
    done
    python3 - "$d" "$label" $SEEDS <<'PY'
import json, sys
d, label, seeds = sys.argv[1], sys.argv[2], sys.argv[3:]
runs = [json.load(open(f'{d}/{label}_{s}.json')) for s in seeds]
def span(key, f):
    v = [f * r[key] if r.get(key) is not None else float('nan') for r in runs]
    return f'{sum(v) / len(v):.4g} ({min(v):.4g}-{max(v):.4g})'
w = d.rsplit('_', 1)[1]
print(f"| {w} | {label} | {span('mean_rotation_error_rigid_deg', 1)} | "
      f"{span('mean_translation_error_rigid_m', 1000)} | "
      f"{span('mean_rotation_error_deg', 1)} |")
PY
  done
done
