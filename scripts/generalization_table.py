#!/usr/bin/env python3
"""Collects the generalization set's eval JSONs into one JSON and a markdown table.

usage: generalization_table.py OUTDIR CASE...   (CASE: "name world seed h pitch fps speed",
as in scripts/generalization_set.sh). Writes OUTDIR/generalization.{json,md}.
"""
import json
import os
import sys
from collections import Counter


def load(path):
    with open(path) as f:
        return json.load(f)


def structure_figures(e):
    """Plane and point figures of one `eval structure` JSON."""
    matched = [m for m in e["planes"]["matches"] if m["matched"]]
    per_true = Counter(m["true_id"] for m in matched)
    observed = [t for t in e["true_planes"] if t["observed"]]
    rel = e["point_error"]["all_landmarks"]["relative_percent"]
    return {
        "scale": e.get("alignment_scale", 1.0),
        "observed_true_planes": len(observed),
        "recovered_true_planes": sum(1 for t in observed if t["matched"]),
        "split_true_planes": sum(1 for c in per_true.values() if c > 1),
        "precision": e["planes"]["precision"],
        "median_error_percent": rel["median"],
        "p90_error_percent": rel["p90"],
        "area_recall": e["area"]["area_recall"],
        "large_planes_seen": e["area"]["large_planes_seen"],
        "large_planes_recovered": e["area"]["large_planes_recovered"],
        "area_precision": e["area"].get("area_precision"),
        "observable_recall": e["area"].get("observable_recall"),
        "observable_area_m2": e["area"].get("observable_area_m2"),
        "large_planes_observable": e["area"].get("large_planes_observable"),
        "large_planes_observable_recovered": e["area"].get("large_planes_observable_recovered"),
    }


def observable(a):
    """Observable area recovered (of m^2 observable) and its large planes ('-' from an older eval)."""
    if a.get("observable_recall") is None:
        return "- | -"
    return (f"{100 * a['observable_recall']:.0f} % ({a['observable_area_m2']:.0f}) |"
            f" {a['large_planes_observable_recovered']} / {a['large_planes_observable']}")


def sim_row(out, case):
    name, world, seed, h, pitch, fps, speed = case.split()
    e = load(os.path.join(out, f"eval_{name}.json"))
    sim3_path = os.path.join(out, f"eval_sim3_{name}.json")
    sim3 = structure_figures(load(sim3_path)) if os.path.exists(sim3_path) else None
    matched = [m for m in e["planes"]["matches"] if m["matched"]]
    # A true plane claimed by two or more matched map planes is split.
    per_true = Counter(m["true_id"] for m in matched)
    observed = [t for t in e["true_planes"] if t["observed"]]
    rel = e["point_error"]["all_landmarks"]["relative_percent"]
    return {
        "name": name, "world": world, "seed": int(seed), "camera_height_m": float(h),
        "pitch_deg": float(pitch), "fps": float(fps), "speed_mps": float(speed),
        "build_s": int(open(os.path.join(out, f"time_{name}.txt")).read()),
        "fitted_planes": e["counts"]["fitted_planes"],
        "observed_true_planes": len(observed),
        "recovered_true_planes": sum(1 for t in observed if t["matched"]),
        "split_true_planes": sum(1 for c in per_true.values() if c > 1),
        "precision": e["planes"]["precision"],
        "recall": e["planes"]["recall"],
        "points": rel["count"],
        "median_error_percent": rel["median"],
        "p90_error_percent": rel["p90"],
        "area_recall": e["area"]["area_recall"],
        "seen_area_m2": e["area"]["seen_area_m2"],
        "large_planes_seen": e["area"]["large_planes_seen"],
        "large_planes_recovered": e["area"]["large_planes_recovered"],
        "area_precision": e["area"].get("area_precision"),
        "map_area_m2": e["area"].get("map_area_m2"),
        "share_above_1cm": e["point_error"]["all_landmarks"].get("share_above_1cm"),
        "after_sim3": sim3,
    }


def real_row(out, name):
    e = load(os.path.join(out, f"eval_{name}.json"))
    row = {"name": name, "build_s": int(open(os.path.join(out, f"time_{name}.txt")).read()),
           "eval_points": e}
    for key, file in (("eval_planes", "evalplanes"), ("board", "evalboard"),
                      ("board_sim3", "evalboard_sim3")):
        p = os.path.join(out, f"{file}_{name}.json")
        if os.path.exists(p):
            row[key] = load(p)
    return row


def board_cell(e):
    """Median (p90) % of distance and count of the points over the board."""
    rel, ab = e["relative_percent"], e["absolute_m"]
    return (f"{rel['median']:.2f} ({rel['p90']:.2f}); {1000 * ab['median']:.2f} mm;"
            f" {rel['count']}")


def find_stat(obj, want):
    """First dict under obj holding 'median' and 'count' whose key path contains want."""
    stack = [("", obj)]
    while stack:
        path, o = stack.pop(0)
        if isinstance(o, dict):
            if "median" in o and "count" in o and want in path:
                return o
            stack.extend((path + "." + k, v) for k, v in o.items())
    return None


def share(fraction):
    """Percent of points off by more than 1 cm ('-' from an older eval)."""
    return "-" if fraction is None else f"{100 * fraction:.1f} %"


def pct(fraction):
    """A fraction in percent ('-' from an older eval)."""
    return "-" if fraction is None else f"{100 * fraction:.0f} %"


def main():
    out, cases = sys.argv[1], sys.argv[2:]
    sims = [sim_row(out, c) for c in cases]
    reals = [real_row(out, n) for n in ("desk_a", "desk_b", "castle")]
    with open(os.path.join(out, "generalization.json"), "w") as f:
        json.dump({"simulated": sims, "real": reals}, f, indent=1)
    lines = ["| run | h m / pitch deg / fps | build s | map planes | true planes seen / recovered / split"
             " | precision | area recovered (of m^2 seen) | map area on the truth"
             " | planes >= 1 m^2 recovered | points | median error % of distance (p90) | > 1 cm |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in sims:
        lines.append(
            f"| {r['name'].split('_')[0]} seed {r['seed']} | {r['camera_height_m']:g} / {r['pitch_deg']:g} /"
            f" {r['fps']:g} | {r['build_s']} | {r['fitted_planes']} | {r['observed_true_planes']} /"
            f" {r['recovered_true_planes']} / {r['split_true_planes']} | {r['precision']:.2f} |"
            f" {100 * r['area_recall']:.0f} % ({r['seen_area_m2']:.0f}) | {pct(r['area_precision'])} |"
            f" {r['large_planes_recovered']} / {r['large_planes_seen']} | {r['points']} | {r['median_error_percent']:.2f} ({r['p90_error_percent']:.2f}) |"
            f" {share(r['share_above_1cm'])} |")
    for r in reals:
        rel = find_stat(r["eval_points"], "relative") or {}
        ab = find_stat(r["eval_points"], "abs") or {}
        med_mm = ab.get("median", float("nan")) * 1000
        lines.append(
            f"| {r['name']} | real | {r['build_s']} | - | - | - | - | - | - | {rel.get('count', '-')} |"
            f" {rel.get('median', float('nan')):.2f} ({rel.get('p90', float('nan')):.2f}); {med_mm:.2f} mm |"
            f" {share(r['eval_points'].get('share_above_1cm'))} |")
    aligned = [r for r in sims if r["after_sim3"]]
    if aligned:
        lines += ["", "After the similarity that best fits the map's trajectory to the truth"
                  " (`eval structure --align sim3-poses`): the map's own geometry, without the"
                  " odometry's scale and frame. Observable: seen by two views within 80 deg of"
                  " the normal whose rays part by >= 2 deg (eval/area_coverage.h).", "",
                  "| run | map scale | true planes seen / recovered / split | precision"
                  " | area recovered | map area on the truth | planes >= 1 m^2 recovered"
                  " | observable area recovered (of m^2) | observable planes >= 1 m^2 recovered"
                  " | median error % of distance (p90) |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for r in aligned:
            a = r["after_sim3"]
            lines.append(
                f"| {r['name'].split('_')[0]} seed {r['seed']} | {a['scale']:.4f} |"
                f" {a['observed_true_planes']} / {a['recovered_true_planes']} / {a['split_true_planes']} |"
                f" {a['precision']:.2f} | {100 * a['area_recall']:.0f} % | {pct(a['area_precision'])} |"
                f" {a['large_planes_recovered']} / {a['large_planes_seen']} | {observable(a)} |"
                f" {a['median_error_percent']:.2f} ({a['p90_error_percent']:.2f}) |")
    boards = [r for r in reals if "board" in r and "board_sim3" in r]
    if boards:
        lines += ["", "Desk halves, the points over the board (issue 18's protocol:"
                  " `eval points --over-board`): median % of distance (p90); mm; points.", "",
                  "| run | absolute | after `--align sim3-poses` |", "|---|---|---|"]
        for r in boards:
            lines.append(f"| {r['name']} | {board_cell(r['board'])} | {board_cell(r['board_sim3'])} |")
    with open(os.path.join(out, "generalization.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
