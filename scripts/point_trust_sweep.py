#!/usr/bin/env python3
"""Scores trust-filter thresholds over a generalization-set run made with
--keep-all-points, without rebuilding: for each threshold triple it writes a
copy of every map keeping only the points.ply vertices that pass (the
quality properties are in the file), and runs the same `eval` as
scripts/generalization_set.sh on it. Accuracy is over all exported points.

usage: point_trust_sweep.py MONOMAP KEEP_ALL_OUTDIR SIM_DIR [DATA_DIR]
  THRESHOLDS env: "track:error_px:angle_deg,..." (default: a small grid).
Prints one line per (thresholds, run) and writes KEEP_ALL_OUTDIR/sweep.json.
"""
import json
import os
import re
import struct
import subprocess
import sys
import tempfile

DEFAULT = ("3:2:1.5,3:2:2,3:2:3,3:2:4,3:2:5,3:1:1.5,3:0.7:1.5,3:0.5:1.5,"
           "5:2:1.5,8:2:1.5,12:2:1.5,5:1:3,8:1:3,5:0.7:2")
RECORD = struct.Struct("<fffBBBiiiff")  # the points.ply vertex (35 bytes)


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    assert "property float triangulation_angle_deg" in header, path
    n = int(re.search(r"element vertex (\d+)", header).group(1))
    return header, [data[end + i * RECORD.size:end + (i + 1) * RECORD.size]
                    for i in range(n)]


def filtered_map(src, dst, track, error, angle):
    os.makedirs(dst)
    for f in os.listdir(src):
        if f not in ("points.ply", "map.json"):
            os.symlink(os.path.join(src, f), os.path.join(dst, f))
    header, rows = read_ply(os.path.join(src, "points.ply"))
    kept = [r for r in rows if (lambda v: v[8] >= track and v[9] <= error and
                                v[10] >= angle)(RECORD.unpack(r))]
    header = re.sub(r"element vertex \d+", f"element vertex {len(kept)}", header)
    with open(os.path.join(dst, "points.ply"), "wb") as f:
        f.write(header.encode() + b"".join(kept))
    j = json.load(open(os.path.join(src, "map.json")))
    j["num_landmarks"] = len(kept)
    json.dump(j, open(os.path.join(dst, "map.json"), "w"))


def evaluate(binary, map_dir, name, sim_dir, data, tmp):
    out = os.path.join(tmp, "eval.json")
    if name == "castle":
        args = ["points", map_dir, "--surface",
                os.path.join(data, "castle_visp/groundtruth_surface.ply")]
    elif name.startswith("desk"):
        args = ["points", map_dir, "--plane",
                os.path.join(data, "desk_vamr_a/groundtruth_structure.yaml")]
    else:
        args = ["structure", map_dir, "--structure",
                os.path.join(sim_dir, f"data_{name}", "structure")]
    subprocess.run([binary, "eval"] + args + ["--json", out], check=True,
                   stdout=subprocess.DEVNULL)
    e = json.load(open(out))
    acc = e["point_error"]["all_landmarks"] if "point_error" in e else e
    if "relative_percent" not in acc:  # eval points nests under its mode
        acc = next(v for v in e.values()
                   if isinstance(v, dict) and "relative_percent" in v)
    return {"points": acc["relative_percent"]["count"],
            "median_percent": acc["relative_percent"]["median"],
            "share_above_1cm": acc["share_above_1cm"]}


def main():
    binary, out, sim_dir = sys.argv[1:4]
    data = sys.argv[4] if len(sys.argv) > 4 else "/work/shared/data"
    names = sorted(d[4:] for d in os.listdir(out) if d.startswith("map_"))
    results = []
    for t in os.environ.get("THRESHOLDS", DEFAULT).split(","):
        track, error, angle = (float(x) for x in t.split(":"))
        for name in names:
            with tempfile.TemporaryDirectory() as tmp:
                m = os.path.join(tmp, "map")
                filtered_map(os.path.join(out, f"map_{name}"), m, track, error,
                             angle)
                r = evaluate(binary, m, name, sim_dir, data, tmp)
            r.update({"thresholds": t, "run": name})
            results.append(r)
            print(f"{t:12s} {name:28s} {r['points']:6d} "
                  f"{r['median_percent']:.3f} {100 * r['share_above_1cm']:.1f}",
                  flush=True)
    json.dump(results, open(os.path.join(out, "sweep.json"), "w"), indent=1)


if __name__ == "__main__":
    main()
