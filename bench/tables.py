#!/usr/bin/env python3
"""The generated tables of docs/benchmarks.md, rendered from the benchmarks' JSON.

A benchmark run with --json writes {"run": ..., "records": [...]}
(bench/json_figures.hpp). The figures a table shows are kept in
docs/figures/NAME.json; the table stands in docs/benchmarks.md between

    <!-- table NAME -->
    ...the table, and where its figures come from. <!-- /table -->

and this script writes it there, with a line naming the command, commit, date and
machine of each run behind it. So a figure cannot drift from its benchmark's
output, and a new run is one command away.

    bench/tables.py                         rewrite every table from docs/figures/
    bench/tables.py --check                 fail if a table differs from its figures (CI)
    bench/tables.py --print NAME F.json...  print table NAME from fresh runs' files
    bench/tables.py --store NAME F.json...  keep runs' files as docs/figures/NAME.json

Several files for one table (one body each, run side by side) are stored as one:
their records in order, each run's provenance kept.
"""
import datetime
import json
import math
import os
import re
import subprocess
import sys
from collections import OrderedDict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOC = os.path.join(ROOT, "docs", "benchmarks.md")
FIGURES = os.path.join(ROOT, "docs", "figures")
BLOCK = re.compile(r"(<!-- table ([a-z0-9_]+) -->\n)(.*?) ?(<!-- /table -->)", re.S)


def label(name):
    return name.replace("_", " ")


def signed(x, digits=1):
    """+1.2 or −1.2 (a minus sign, not a hyphen)."""
    return f"{x:+.{digits}f}".replace("-", "−")


# ---- provenance ---------------------------------------------------------------


def run_record():
    """A Python benchmark's run, as bench/json_figures.hpp records a C++ one's."""
    def git(*args):
        return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True, check=True).stdout.strip()
    try:
        commit = git("describe", "--always", "--abbrev=7")
        # Changes to docs/ (where the figures go) do not make a run's tree dirty.
        if git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)docs"):
            commit += "-dirty"
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    cpu = "unknown processor"
    try:
        cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    command = " ".join([os.path.relpath(sys.argv[0], ROOT)] + sys.argv[1:])
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    return {"command": command, "commit": commit, "date": date, "machine": {"cpu": cpu, "cores": os.cpu_count()}}


def load(paths):
    """The runs and records of one or more --json files (or a stored figures file)."""
    runs, records = [], []
    for p in paths:
        data = json.load(open(p))
        if "runs" in data:  # a stored figures file
            runs += data["runs"]
            records += data["records"]
        else:
            runs.append(data["run"])
            records += data["records"]
    return runs, records


def provenance(runs):
    """One line per distinct (commit, date, machine): which runs stand behind the table."""
    groups = OrderedDict()
    for r in runs:
        m = r["machine"]
        key = (r["commit"], r["date"], f"{m['cores']} cores, {m['cpu']}")
        groups.setdefault(key, []).append(r["command"])
    lines = []
    for (commit, date, machine), commands in groups.items():
        shown = commands[0] if len(commands) == 1 else f"{commands[0]} (and {len(commands) - 1} more like it)"
        lines.append(f"Measured {date} at commit {commit} on {machine}: `{shown}`.")
    return "\n".join(lines)


# ---- renderers: each takes the records and returns Markdown -------------------


def sphere(records):
    """Thesis Table 4.1: the defaults' RMS against the thesis's, per N and noise."""
    cells = {(r["points"], r["noise"]): r for r in records if "defaults" in r and "thesis_rms" in r}
    sizes = sorted({n for n, _ in cells}, reverse=True)
    noises = sorted({s for _, s in cells})
    out = ["| N | " + " | ".join(f"s = {s:.2f}" for s in noises) + " |",
           "|---:|" + "---:|" * len(noises)]
    ratios = []
    for n in sizes:
        row = []
        for s in noises:
            r = cells.get((n, s))
            if not r:
                row.append("—")
                continue
            ratio = r["defaults"]["rms"] / r["thesis_rms"]
            ratios.append(ratio)
            row.append(f"{r['defaults']['rms']:.6f} / {r['thesis_rms']:.6f} ({ratio:.2f})")
        out.append(f"| {n} | " + " | ".join(row) + " |")
    below = sum(x < 1 for x in ratios)
    gmean = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
    worst = max(ratios)
    out += ["", f"Defaults / thesis (ratio): {below} of {len(ratios)} cells below the thesis; "
                f"geometric mean ratio {gmean:.2f}, largest {worst:.2f}."]
    return "\n".join(out)


POSTURE_FAMILIES = ["heights", "torso girths", "limb and neck girths", "lengths"]


def posture(records):
    """Per posture or motion, the largest change per family over the bodies, and the landmarks."""
    by_variant = OrderedDict()
    for r in records:
        by_variant.setdefault(r["variant"], []).append(r)
    bodies = sorted({r["body"] for r in records})
    out = [f"{len(bodies)} bodies: {', '.join(bodies)}. Each cell: the largest over the bodies (mm), and whose.", "",
           "| posture or motion | heights | torso girths | limb and neck girths | lengths | unmoved skin: values "
           "within half the allowance | outer arm length less its points' own change | landmarks to their vertices: "
           "largest (median of the bodies' medians) | arms read − true (deg) | ankles read − true (mm) |",
           "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"]
    for variant, rs in by_variant.items():
        ok = [r for r in rs if "error" not in r]
        failed = [r["body"] for r in rs if "error" in r]
        name = variant + (" (not measured: " + ", ".join(failed) + ")" if failed else "")
        if not ok:
            out.append(f"| {name} |" + " |" * 9)
            continue
        cells = []
        for f in POSTURE_FAMILIES:
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
        arm_cell = f"{max(arm):.1f}" if arm else "-"
        out.append(f"| {name} | " + " | ".join(cells) + f" | {within} / {unmoved} | {arm_cell} |"
                   f" {worst['landmark_max_mm']:.1f} ({worst['body']}: {worst['landmark_worst']};"
                   f" {medians[len(medians) // 2]:.1f}) | {max(arms) if arms else math.nan:.1f} |"
                   f" {max(ankles) if ankles else math.nan:.0f} |")
    return "\n".join(out)


def posed(r):
    p = r.get("posed")
    if not p:
        return ""
    return f", arms {p['arms_deg']:g}°, ankles {p['ankles_mm']:g} mm, turned {signed(p['turn_deg'])}°"


def differences(r):
    """(measurement, scan − truth, allowance) for each value both sets have."""
    return [(m, m["scan_mm"] - m["truth_mm"], m["allowance_mm"]) for m in r["measurements"]
            if m.get("scan_mm") is not None]


def measure_accuracy(records):
    """Per scan: how many values lie within the allowance (half, a sixth), which lie outside."""
    pairs = any("repeat" in r for r in records)  # the repeat pair's column only where one was scanned
    out = ["| scan | values | within the allowance | within half | within a sixth | fixed planes: largest (mm) "
           "| over the allowance (scan − truth, mm) |" + (" repeat pair: median, largest (mm) |" if pairs else ""),
           "|---|---:|---:|---:|---:|---:|---|" + ("---|" if pairs else "")]
    for r in records:
        d = differences(r)
        over = [f"{label(m['name'])} {signed(x)}" for m, x, a in d if abs(x) > a]
        missing = [label(m["name"]) for m in r["measurements"] if m.get("scan_mm") is None]
        pair = r.get("repeat")
        pair_cell = f"{pair['median_mm']:.2f}, {label(pair['largest'])} {pair['largest_mm']:.2f}" if pair else "—"
        out.append(f"| {r['body']}{posed(r)} | {len(d)} | {sum(abs(x) <= a for _, x, a in d)} "
                   f"| {sum(abs(x) <= a / 2 for _, x, a in d)} | {sum(abs(x) <= a / 6 for _, x, a in d)} "
                   f"| {r['fixed_planes_largest_mm']:.2f} | {'; '.join(over + [n + ' missing' for n in missing]) or '—'} |"
                   + (f" {pair_cell} |" if pairs else ""))
    return "\n".join(out)


def measure_fill(records):
    """Per scan: what the marks for filled-in skin (≈) say against the truth."""
    out = ["| scan | values over filled skin | marked ≈: scan − truth (its bound), mm | marked, off by more than "
           "the bound and half the allowance | unmarked, outside the allowance | unmarked over filled skin: "
           "largest off (mm) |",
           "|---|---:|---|---|---|---:|"]
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
        out.append(f"| {r['body']}{posed(r)} | {sum(m['crosses_fill'] for m, _, _ in d)} | {marked_cell} "
                   f"| {'; '.join(past) or 'none'} | {'; '.join(unmarked_over) or 'none'} | {quiet_cell} |")
    return "\n".join(out)


def gap_cylinder(records):
    """Per case: the strip's radius off (first seed) and the tape's error per seed."""
    cases = OrderedDict()
    for r in records:
        key = (r["strip_deg"], r["noise_mm"], r["stray"], r["quiet_strays"], r["true_normals"])
        cases.setdefault(key, []).append(r)
    seeds = sorted({r["seed"] for r in records})
    out = [f"| strip | noise (mm RMS) | stray points in it | normals | strip's radius off, mean / largest (mm), "
           f"seed {seeds[0]} | girth off (mm), seeds {seeds[0]}-{seeds[-1]} | spread |",
           "|---|---:|---|---|---|---|---:|"]
    for (strip, noise, stray, quiet, given), rs in cases.items():
        rs = sorted(rs, key=lambda r: r["seed"])
        errors = [r["girth_error_mm"] for r in rs]
        same = max(errors) - min(errors) < 0.005
        girth = signed(errors[0], 2) if same else ", ".join(signed(e, 2) for e in errors)
        spread = "" if same else f"{max(errors) - min(errors):.2f}"
        strays = "" if not strip else ("none" if not stray else "the same, themselves without noise" if quiet
                                       else "one per 16 × 6 mm")
        normals = "**true**" if given else "estimated"
        out.append(f"| {f'{strip:g}°' if strip else 'none'} | {noise:g} | {strays} | {normals} "
                   f"| {signed(rs[0]['strip_mean_mm'], 2)} / {signed(rs[0]['strip_largest_mm'], 2)} | {girth} "
                   f"| {spread} |")
    return "\n".join(out)


def rig_coverage(records):
    """Per body: the share each layout covers, overall and in the zones measurements hang from."""
    rigs = list(OrderedDict.fromkeys(r["rig"] for r in records))
    bodies = sorted({r["body"] for r in records})
    by = {(r["body"], r["rig"]): r for r in records}
    zones = ["crotch", "shoulder tops", "forearms"]

    def cell(body, value):
        values = [value(by[(body, rig)]) if (body, rig) in by else None for rig in rigs]
        best = max(v for v in values if v is not None)
        return " / ".join("—" if v is None else f"**{v:.1f} %**" if v == best else f"{v:.1f} %" for v in values)

    out = [f"| body | covered: {' / '.join(rigs)} | " + " | ".join(zones) + " |", "|---|---|---|---|---|"]
    for b in bodies:
        out.append(f"| {b} | {cell(b, lambda r: r['covered_percent'])} | "
                   + " | ".join(cell(b, lambda r, z=z: r["zones_covered_percent"][z]) for z in zones) + " |")
    views = sorted({r["max_view_deg"] for r in records})
    clear = min(r["light_clearance_mm"] for r in records)
    out += ["", f"Views within {', '.join(f'{v:g}' for v in views)}° of the normal; every frame light at least "
                f"{clear:.0f} mm clear of the body for every camera."]
    return "\n".join(out)


def stripe_fidelity(records):
    """The renderer's stripe against the reference's (or the delivered frame's), by view angle."""
    out = []
    for r in records:
        other = "frame" if r["noisy"] else "reference"
        out += [f"| view (°) | samples | renderer: signed mean / median (mm) | {other}: signed mean / median (mm) "
                f"| renderer \\|err\\| p50 (mm) |", "|---|---:|---|---|---:|"]
        ref = {(b["view_from_deg"], b["view_to_deg"]): b for b in r["reference"]}
        for b in r["renderer"]:
            o = ref.get((b["view_from_deg"], b["view_to_deg"]))
            other_cell = f"{signed(o['signed_mean_mm'], 3)} / {signed(o['median_mm'], 3)}" if o else "—"
            out.append(f"| {b['view_from_deg']:g}-{b['view_to_deg']:g} | {b['samples']:,} "
                       f"| {signed(b['signed_mean_mm'], 3)} / {signed(b['median_mm'], 3)} | {other_cell} "
                       f"| {b['abs_p50_mm']:.3f} |")
    return "\n".join(out)


# A table's name: (its renderer, the figures file it reads, by name in docs/figures).
TABLES = {
    "sphere": (sphere, "sphere"),
    "posture": (posture, "posture"),
    "measure_accuracy": (measure_accuracy, "measure"),
    "measure_fill": (measure_fill, "measure"),
    "measure_posed": (measure_accuracy, "measure_posed"),
    "gap_cylinder": (gap_cylinder, "gap_cylinder"),
    "rig_coverage": (rig_coverage, "rig_coverage"),
    "stripe_fidelity": (stripe_fidelity, "stripe_fidelity"),
}


def figures_path(name):
    return os.path.join(FIGURES, name + ".json")


def rendered(table):
    render, figures = TABLES[table]
    runs, records = load([figures_path(figures)])
    return render(records) + "\n\n" + provenance(runs)


def rewrite(doc_text):
    """The document with every table block rendered afresh; unknown names fail."""
    def block(m):
        name = m.group(2)
        if name not in TABLES:
            sys.exit(f"tables: {DOC} names a table '{name}' this script does not know")
        return m.group(1) + rendered(name) + " " + m.group(4)
    return BLOCK.sub(block, doc_text)


def main(argv):
    if argv[:1] == ["--print"] and len(argv) >= 3 and argv[1] in TABLES:
        runs, records = load(argv[2:])
        print(TABLES[argv[1]][0](records) + "\n\n" + provenance(runs))
        return 0
    if argv[:1] == ["--store"] and len(argv) >= 3:
        runs, records = load(argv[2:])
        os.makedirs(FIGURES, exist_ok=True)
        with open(figures_path(argv[1]), "w") as f:
            json.dump({"runs": runs, "records": records}, f, indent=1, ensure_ascii=False)
            f.write("\n")
        print(f"tables: stored {len(records)} records of {len(runs)} runs as {figures_path(argv[1])}")
        return 0
    if argv not in ([], ["--check"]):
        print(__doc__, file=sys.stderr)
        return 2
    text = open(DOC).read()
    new = rewrite(text)
    count = len(BLOCK.findall(text))
    if argv == ["--check"]:
        if new != text:
            print(f"tables: {DOC} differs from its figures (docs/figures); run bench/tables.py", file=sys.stderr)
            return 1
        print(f"tables: {count} tables match their figures")
        return 0
    if new != text:
        open(DOC, "w").write(new)
    print(f"tables: {count} tables rendered into {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
