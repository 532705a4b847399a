#!/usr/bin/env python3
"""Renders posture_benchmark's JSON (--json) as the tables in docs/benchmarks.md,
"Posture and placement": per posture or motion, the largest change per measurement
family over the bodies, and the landmarks' distances to their vertices.

    build/bench/posture_benchmark --json P.json >/dev/null && bench/posture_table.py P.json
"""
import json
import math
import sys
from collections import OrderedDict

FAMILIES = ["heights", "torso girths", "limb and neck girths", "lengths"]


def main(path):
    rows = json.load(open(path))
    by_variant = OrderedDict()
    for r in rows:
        by_variant.setdefault(r["variant"], []).append(r)
    bodies = sorted({r["body"] for r in rows})
    print(f"{len(bodies)} bodies: {', '.join(bodies)}. Each cell: the largest over the bodies (mm), and whose.\n")
    print("| posture or motion | heights | torso girths | limb and neck girths | lengths | unmoved skin: values within half the allowance | outer arm length less its points' own change | landmarks to their vertices: largest (median of the bodies' medians) | arms read − true (deg) | ankles read − true (mm) |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|---:|")
    for variant, rs in by_variant.items():
        ok = [r for r in rs if "error" not in r]
        failed = [r["body"] for r in rs if "error" in r]
        cells = []
        for f in FAMILIES:
            best = max(ok, key=lambda r: r["largest_change_mm"][f]["value"])
            v = best["largest_change_mm"][f]
            cells.append(f"{v['value']:.1f} ({best['body']}: {v['measurement']})" if v["value"] >= 0.05 else "0.0")
        unmoved = sum(r["unmoved_values"] for r in ok)
        within = sum(r["unmoved_within_half_allowance"] for r in ok)
        arm = [r["outer_arm_length_error_mm"] for r in ok if "outer_arm_length_error_mm" in r]
        worst = max(ok, key=lambda r: r["landmark_max_mm"])
        medians = sorted(r["landmark_median_mm"] for r in ok)
        arms = [abs(x) for r in ok for x in r["arm_abduction_error_deg"] if x is not None and not math.isnan(x)]
        ankles = [abs(r["ankle_distance_error_mm"]) for r in ok if r["ankle_distance_error_mm"] is not None]
        name = variant + (" (not measured: " + ", ".join(failed) + ")" if failed else "")
        arm_cell = f"{max(arm):.1f}" if arm else "-"
        print(f"| {name} | " + " | ".join(cells) + f" | {within} / {unmoved} | {arm_cell} |"
              f" {worst['landmark_max_mm']:.1f} ({worst['body']}: {worst['landmark_worst']}; {medians[len(medians) // 2]:.1f}) |"
              f" {max(arms):.1f} | {max(ankles):.0f} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/dev/stdin")
