#!/usr/bin/env python3
"""Where the generalization set's unrecovered area lies, by kind of surface.

usage: observable_gap.py OUTDIR SIM_DIR
  OUTDIR: a scripts/generalization_set.sh output (its eval_sim3_*.json);
  SIM_DIR: the simulated datasets it used (data_<run>/structure/map.json).

Sums, per kind of true plane, the seen, observable and recovered-observable
area (m^2) of `eval structure --align sim3-poses` over the simulated runs.
The kind comes from the true plane's shape, as the simulator builds them:
normal up = floor, normal down and wider than 1 m both ways = ceiling (else a
lintel's underside), a side under 10 cm = jamb, 0.8-1.0 x 2.0-2.1 m = door
leaf, otherwise wall (furniture faces and whiteboards included).
"""
import glob
import json
import os
import sys


def kind(plane):
    n = plane["normal"]
    xs = [v[0] for v in plane["polygon"]]
    ys = [v[1] for v in plane["polygon"]]
    w, h = max(xs) - min(xs), max(ys) - min(ys)
    if abs(n[2]) > 0.9:
        if n[2] > 0:
            return "floor"
        return "ceiling" if w > 1 and h > 1 else "lintel"
    if min(w, h) < 0.1:
        return "jamb"
    if 0.8 < w < 1.0 and 2.0 < h < 2.1:
        return "door"
    return "wall"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    out_dir, sim_dir = sys.argv[1:]
    total = {}
    for path in sorted(glob.glob(os.path.join(out_dir, "eval_sim3_*.json"))):
        run = os.path.basename(path)[len("eval_sim3_"):-len(".json")]
        with open(path) as f:
            area = json.load(f)["area"]["planes"]
        with open(os.path.join(sim_dir, "data_" + run, "structure", "map.json")) as f:
            kinds = {p["id"]: kind(p) for p in json.load(f)["planes"]}
        for a in area:
            t = total.setdefault(kinds.get(a["true_id"], "?"), [0.0, 0.0, 0.0])
            t[0] += a["seen_area_m2"]
            t[1] += a["observable_area_m2"]
            t[2] += a["recovered_observable_area_m2"]
    print("| surface | seen m^2 | observable m^2 | observable recovered m^2 |")
    print("|---|---|---|---|")
    for k, (seen, obs, rec) in sorted(total.items(), key=lambda kv: -kv[1][1]):
        share = f" ({100 * rec / obs:.0f} %)" if obs > 0 else ""
        print(f"| {k} | {seen:.1f} | {obs:.1f} | {rec:.1f}{share} |")


if __name__ == "__main__":
    main()
