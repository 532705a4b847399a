#!/usr/bin/env python3
"""Renders measure_benchmark's JSON (--json) as the tables in docs/benchmarks.md,
"Measurements from a scan against the same on the true body": per scan, how many of
the automatic set lie within the ISO 20685-1 allowance of the truth's value (and
within half and a sixth of it), which lie outside, the repeat pair where there is
one; then what the marks for filled-in skin say against the truth.

    build/bench/measure_benchmark --rig hw/rigs/tiered.json --body B.ply --json B.json
    bench/measure_table.py B.json [C.json ...]
"""
import json
import sys


def label(name):
    return name.replace("_", " ")


def signed(x):
    """+1.2 or −1.2 (a minus sign, not a hyphen)."""
    return f"{x:+.1f}".replace("-", "−")


def posed(r):
    p = r.get("posed")
    if not p:
        return ""
    return f", arms {p['arms_deg']:g}°, ankles {p['ankles_mm']:g} mm, turned {signed(p['turn_deg'])}°"


def differences(r):
    """(measurement, scan − truth, allowance) for each value both sets have."""
    return [(m, m["scan_mm"] - m["truth_mm"], m["allowance_mm"]) for m in r["measurements"]
            if m.get("scan_mm") is not None]


def accuracy_table(records):
    pairs = any("repeat" in r for r in records)  # the repeat pair's column only where one was scanned
    print("| scan | values | within the allowance | within half | within a sixth | fixed planes: largest (mm) "
          "| over the allowance (scan − truth, mm) |" + (" repeat pair: median, largest (mm) |" if pairs else ""))
    print("|---|---:|---:|---:|---:|---:|---|" + ("---|" if pairs else ""))
    for r in records:
        d = differences(r)
        over = [f"{label(m['name'])} {signed(x)}" for m, x, a in d if abs(x) > a]
        missing = [label(m["name"]) for m in r["measurements"] if m.get("scan_mm") is None]
        pair = r.get("repeat")
        pair_cell = f"{pair['median_mm']:.2f}, {label(pair['largest'])} {pair['largest_mm']:.2f}" if pair else "—"
        print(f"| {r['body']}{posed(r)} | {len(d)} | {sum(abs(x) <= a for _, x, a in d)} "
              f"| {sum(abs(x) <= a / 2 for _, x, a in d)} | {sum(abs(x) <= a / 6 for _, x, a in d)} "
              f"| {r['fixed_planes_largest_mm']:.2f} | {'; '.join(over + [n + ' missing' for n in missing]) or '—'} |"
              + (f" {pair_cell} |" if pairs else ""))


def fill_table(records):
    print("| scan | values over filled skin | marked ≈: scan − truth (its bound), mm | marked, off by more than "
          "the bound and half the allowance | unmarked, outside the allowance | unmarked over filled skin: "
          "largest off (mm) |")
    print("|---|---:|---|---|---|---:|")
    for r in records:
        d = differences(r)
        marked = [(m, x, a) for m, x, a in d if m["estimated"]]

        def bound(m):
            return "not known" if m["fill_bound_mm"] is None else f"±{m['fill_bound_mm']:.1f}"

        marked_cell = "; ".join(f"{label(m['name'])} {signed(x)} ({bound(m)})" for m, x, _ in marked) or "none"
        past = [label(m["name"]) for m, x, a in marked
                if m["fill_bound_mm"] is not None and abs(x) > m["fill_bound_mm"] + a / 2]
        unmarked_over = [f"{label(m['name'])} {signed(x)}" for m, x, a in d if not m["estimated"] and abs(x) > a]
        quiet = [abs(x) for m, x, _ in d if m["crosses_fill"] and not m["estimated"]]
        quiet_cell = f"{max(quiet):.2f}" if quiet else "—"
        print(f"| {r['body']}{posed(r)} | {sum(m['crosses_fill'] for m, _, _ in d)} | {marked_cell} "
              f"| {'; '.join(past) or 'none'} | {'; '.join(unmarked_over) or 'none'} | {quiet_cell} |")


def main(paths):
    records = [r for p in paths for r in json.load(open(p))]
    accuracy_table(records)
    print()
    fill_table(records)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
