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
    bench/tables.py --check                 fail if a table differs from its figures, or stands
                                            outside a table block (CI)
    bench/tables.py --print NAME F.json...  print table NAME from fresh runs' files
    bench/tables.py --store NAME F.json...  keep runs' files as docs/figures/NAME.json
    bench/tables.py --wrap OUT.json COMMAND <RECORDS.json
                                            a script benchmark's records (a JSON array)
                                            with this tree's provenance, as OUT.json

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


def run_record(command=None):
    """A Python or script benchmark's run, as bench/json_figures.hpp records a C++ one's:
    the command (this process's own unless given), commit, date and machine."""
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
    if command is None:
        command = " ".join([os.path.relpath(sys.argv[0], ROOT)] + sys.argv[1:])
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    run = {"command": command, "commit": commit, "date": date, "machine": {"cpu": cpu, "cores": os.cpu_count()}}
    try:  # the build the script drove (bodyscan and the C++ benchmarks in build/)
        cache = open(os.path.join(ROOT, "build", "CMakeCache.txt")).read()
        run["build"] = re.search(r"^CMAKE_BUILD_TYPE:STRING=(.*)$", cache, re.M)[1]
    except (OSError, TypeError):
        pass
    return run


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
        build = f", {r['build']} build" if r.get("build") else ""
        key = (r["commit"], r["date"], f"{m['cores']} cores, {m['cpu']}{build}")
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


def ordinal_steps(every):
    """'every step', 'every 2nd step', 'every 8th step'."""
    if every == 1:
        return "every step"
    suffix = {1: "st", 2: "nd", 3: "rd"}.get(every % 10 if every % 100 not in (11, 12, 13) else 0, "th")
    return f"every {every}{suffix} step"


def mb(nbytes, digits=2):
    return f"{nbytes / 1e6:.{digits}f}"


def seconds(x):
    return f"{x:.2f}" if x < 10 else f"{x:.1f}"


SCAN_DEFAULT = "sweep fit, laser-plane homography"
SCAN_THESIS = "per frame, laser-plane homography"  # the thesis's §3.1.3: poles per frame, eq. 3.6


def scan_cloud(records):
    """Per rig and body: the default cloud's distance to the truth and coverage, beside the thesis's method."""
    out = ["| rig | body | steps | points | mean (mm) | p95 (mm) | coverage ≤ 5 mm "
           "| thesis's method: mean / p95 (mm) | ours / thesis's: mean, p95 |",
           "|---|---|---|---:|---:|---:|---:|---|---|"]
    for r in records:
        m = {x["method"]: x for x in r["methods"]}
        d, t = m[SCAN_DEFAULT], m[SCAN_THESIS]
        out.append(f"| {r['rig']} | {r['body']} | {ordinal_steps(r['every'])} | {d['points']:,} | {d['mean_mm']:.3f} "
                   f"| {d['p95_mm']:.3f} | {r['coverage_percent']:.1f} % | {t['mean_mm']:.3f} / {t['p95_mm']:.3f} "
                   f"| {d['mean_mm'] / t['mean_mm']:.2f}, {d['p95_mm'] / t['p95_mm']:.2f} |")
    return "\n".join(out)


def scan_markers(records):
    """Per camera: its markers against the lights' true images, its centre, and the biases it adds."""
    out = ["| rig | camera | marker worst (px) | centre vs truth (mm) | rays meet within (mm) "
           "| calibration alone, signed (\\|.\\|) mm | points by camera, signed mm |",
           "|---|---|---:|---:|---:|---|---:|"]
    for r in records:
        for c in r["cameras"]:
            out.append(f"| {r['rig']} | {c['camera']} | {c['marker_worst_px']:.3f} | {c['centre_mm']:.2f} "
                       f"| {c['rays_mm']:.2f} | {signed(c['calibration_signed_mm'], 3)} ({c['calibration_abs_mm']:.3f}) "
                       f"| {signed(c['points_signed_mm'], 3)} |")
    return "\n".join(out)


def render(records):
    """Per rig and subject: the frames of a scan, the renderer's wall time, the cameras' own."""
    out = ["| rig, subject | steps | frames | wall time | the cameras take | wall / cameras |",
           "|---|---|---:|---:|---:|---:|"]
    for r in records:
        subject = f"swaying {r['sway_mm']:g} mm" if r["sway_mm"] > 0 else "still"
        out.append(f"| {r['rig']}, {subject} | {ordinal_steps(r['every'])} | {r['scan_frames']:,} "
                   f"| {r['scan_seconds']:.1f} s | {r['cameras_seconds']:.1f} s "
                   f"| {r['scan_seconds'] / r['cameras_seconds']:.2f} |")
    return "\n".join(out)


def hole_fill(records):
    """Per minimum weight and programme limit: the loops, what the fill adds and its time."""
    out = ["| minimum relative weight | open surface (triangles) | limit (edges) | loops | longest loop (edges) "
           "| fill added (m²) | `fill_holes` (s, best of) |",
           "|---:|---:|---:|---:|---:|---:|---:|"]
    for r in records:
        out.append(f"| {100 * r['min_relative_weight']:.0f} % | {r['open_triangles']:,} | {r['max_dp']} | {r['loops']} "
                   f"| {r['longest_edges']} | {r['area_mm2'] / 1e6:.2f} | {r['seconds']:.2f} ({r['repeat']}) |")
    return "\n".join(out)


def formats(records):
    """Per mesh: its size in each format, and the Draco encodings' error and times."""
    out = ["| mesh | triangles | PLY MB | OBJ MB | STL MB | GLB MB | bits | largest vertex error mm | encode s "
           "| decode s | archive `mesh.drc` MB | error mm | encode s | decode s |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in records:
        out.append(f"| {r['mesh']} | {r['triangles']:,} | {mb(r['ply_bytes'])} | {mb(r['obj_bytes'])} "
                   f"| {mb(r['stl_bytes'])} | {mb(r['glb_bytes'], 3)} | {r['glb_bits']} | {r['glb_error_mm']:.3f} "
                   f"| {r['glb_encode_seconds']:.2f} | {r['glb_decode_seconds']:.2f} | {mb(r['drc_bytes'], 3)} "
                   f"| {r['drc_error_mm']:.4f} | {r['drc_encode_seconds']:.2f} | {r['drc_decode_seconds']:.2f} |")
    return "\n".join(out)


# What each file of an archived scan is (docs/archive.md).
SCAN_FILES = {
    "manifest.json": "the folder's checksummed manifest",
    "raw/record.json": "the calibration record",
    "raw/stripes.bin": "every frame's stripes and planes: the raw record a scan is reprocessed from",
    "calibration.json": "the calibration's summary",
    "measurements.json": "the measurements with their loops and paths",
    "mesh.drc": "the surface, within 0.01 mm, with its confidence",
    "mesh.glb": "the display mesh, served",
    "points.drc": "the point cloud, served",
    "points.ply": "the point cloud with camera, laser, frame and confidence",
    "scan.json": "the scan's record",
}


def archived_scan(records):
    """One archived scan's folder, file by file."""
    out = ["| file | bytes | what it is |", "|---|---:|---|"]
    for r in records:
        role = SCAN_FILES.get(r["file"]) or SCAN_FILES.get(r["file"].split("/", 1)[-1], "")
        out.append(f"| {r['file']} | {r['bytes']:,} | {role} |")
    out.append(f"| in all | **{sum(r['bytes'] for r in records):,}** | |")
    return "\n".join(out)


def crash_drill(records):
    """The archive's crash drill: kills, and what each left."""
    out = ["| kills | scans completed before a kill | interrupted scans marked failed "
           "| kills that left half-written files | completed scans lost |", "|---:|---:|---:|---:|---:|"]
    out += [f"| {r['kills']} | {r['completed']} | {r['interrupted_marked_failed']} | {r['kills_mid_write']} "
            f"| **{r['completed_lost']}** |" for r in records]
    return "\n".join(out)


def avatars(records):
    """Per surface and budget: the product's decimation beside meshoptimizer's collapses alone."""
    out = ["| surface | triangles | budget → kept | time s | non-manifold edges | median / p95 mm | largest mm "
           "| OBJ MB | GLB MB | meshoptimizer alone: s, non-manifold edges |",
           "|---|---:|---|---:|---:|---|---:|---:|---:|---|"]
    for r in records:
        out.append(f"| {r['mesh']} | {r['triangles']:,} | {r['budget'] // 1000} k → {r['kept']:,} | {r['seconds']:.2f} "
                   f"| {r['non_manifold_edges']} | {r['median_mm']:.3f} / {r['p95_mm']:.3f} | {r['largest_mm']:.2f} "
                   f"| {mb(r['obj_bytes'])} | {mb(r['glb_bytes'])} | {r['meshoptimizer_seconds']:.2f}, "
                   f"{r['meshoptimizer_non_manifold_edges']} |")
    return "\n".join(out)


def server_load(records):
    """Per case: wrk's throughput and latency against the server, idle and during a scan."""
    out = ["| case | requests/s | p50 ms | p99 ms | transfer MB/s | errors |", "|---|---:|---:|---:|---:|---|"]
    for r in records:
        detail = f" ({r['error_detail']})" if r["error_detail"] else ""
        out.append(f"| {r['case']} | {r['requests_per_s']:.0f} | {r['p50_ms']:.1f} | {r['p99_ms']:.1f} "
                   f"| {r['transfer_mb_s']:.0f} | {r['errors']} of {r['requests']:,}{detail} |")
    r = records[0]
    out += ["", f"wrk: {r['threads']} threads, {r['connections']} connections, {r['seconds']} s a case; the scan read "
                f"has {r['measurements']} automatic measurements (JSON {r['json_bytes'] / 1e3:.0f} KB) and a "
                f"{r['glb_bytes'] / 1e3:.0f} KB GLB."]
    return "\n".join(out)


def ui_first_frame(records):
    """Per model: medians of the page's User Timing marks in headless Chromium."""
    def ms(x):
        return "—" if x is None else f"{x:.0f} ms"
    out = ["| model | triangles | GLB | page load → first frame | scan opened → first frame "
           "| of which fetch + Draco decode | normals | first draw | scan opened → picking ready | BVH build "
           "| opened again in the app | pick (median / max) |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in records:
        out.append(f"| {r['label']} | {r['triangles']:,} | {r['glbKB']:.0f} KB | {ms(r['loadToFrame'])} "
                   f"| **{ms(r['openToFrame'])}** | {ms(r['decoded'])} | {ms(r['normals'])} | {ms(r['draw'])} "
                   f"| **{ms(r['picking'])}** | {ms(r['bvh'])} | {ms(r['warm'])} "
                   f"| {r['pick']:.2f} / {r['pickMax']:.2f} ms |")
    r = records[0]
    out += ["", f"Medians of {r['runs']} runs; headless Chromium {r['chromium']} (WebGL on SwiftShader, no GPU)."]
    return "\n".join(out)


# devices_benchmark's benchmarks: what each row is.
DEVICE_PATHS = [
    ("BM_TmclRequestInProcess", "TMCL request, board in process",
     "frame encode, checksum, the simulated board's interpreter, decode"),
    ("BM_TmclRequestPty", "TMCL request over a pseudo-terminal",
     "`SerialLink` byte for byte to `PtyBoard` (termios, `poll`, the pty's wake-ups); a USB CDC-ACM board adds its "
     "1 ms USB frames"),
    ("BM_ControllerLaserOnOffPty", "A laser on and off through `TmclController` (pty)", "two confirmed `SIO` requests"),
    ("BM_ControllerLaserStepPty", "One laser step there and back, waiting until reached (pty)",
     "`MVP` and `GAP 8` polls, and the simulated motor's 16 microsteps at 20,000/s"),
    ("BM_WatchdogTrip", "Board-side watchdog trip after the cable is pulled, laser on, 500 ms period",
     "the stored TMCL program alone, no host; it samples the heartbeat once a period, so a trip takes one to two "
     "periods after the last feed"),
    ("BM_AravisFakeGrab/8", "Aravis fake camera, software trigger, 1280 × 1024 Mono8",
     "the fake paces itself; our cost per frame is the CPU time (trigger, buffer pool, copy into a `Frame`)"),
    ("BM_AravisFakeGrab/16", "the same, Mono16", ""),
    ("BM_Unpack", "Unpack 1280 × 1024", "to 16-bit pixels"),
]


def duration(value, unit):
    ns = value * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[unit]
    if ns < 1e3:
        return f"{ns:.0f} ns"
    if ns < 1e5:
        return f"{ns / 1e3:.1f} µs"
    return f"{ns / 1e6:.2f} ms" if ns < 1e8 else f"{ns / 1e6:.0f} ms"


def devices(records):
    """Per device path: Google Benchmark's median (or only) run, wall and CPU time, the rate;
    the pixel formats' unpacking in one row."""
    medians = [r for r in records if r.get("aggregate_name") == "median"]
    runs = medians or [r for r in records if r.get("run_type") == "iteration"]
    # Without the library's suffixes: /real_time, /manual_time, /iterations:N.
    for r in runs:
        r["path"] = re.sub(r"/(real_time|manual_time|iterations:\d+)", "", r["run_name"])
    out = ["| Path | Time (wall) | CPU | Rate | What it is |", "|---|---:|---:|---:|---|"]
    for prefix, name, what in DEVICE_PATHS:
        if prefix == "BM_Unpack":
            unpack = [r for r in runs if r["path"].startswith("BM_Unpack/")]
            if unpack:
                out.append(f"| {name} {' / '.join(r.get('label', '') for r in unpack)} "
                           f"| {' / '.join(duration(r['real_time'], r['time_unit']) for r in unpack)} | "
                           f"| {' / '.join(format(r['items_per_second'] / 1e9, '.2f') for r in unpack)} Gpx/s "
                           f"| {what} |")
            continue
        for r in (r for r in runs if r["path"] == prefix):
            wall = r["real_time"] * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[r["time_unit"]]
            per_s = 1e9 / wall
            rate = f"{per_s / 1e6:.1f} M/s" if per_s >= 1e6 else f"{per_s:,.0f}/s" if per_s >= 1.5 else ""
            out.append(f"| {name} | {duration(r['real_time'], r['time_unit'])} "
                       f"| {duration(r['cpu_time'], r['time_unit'])} | {rate} | {what} |")
    repetitions = max(r.get("repetitions", 1) for r in records)
    out += ["", f"{'Medians of ' + str(repetitions) + ' repetitions' if medians else 'One run each'}."]
    return "\n".join(out)


def posture_sweep(records):
    """Per rig and body: how often the sweep checks as the truth does, its largest misses, its cost."""
    groups = OrderedDict()
    for r in records:
        groups.setdefault((r["rig"], os.path.splitext(os.path.basename(r["body"]))[0]), []).append(r)
    out = ["| rig, body | checks as the truth's | where they agree, arms, ankles, turn: largest \\|sweep − truth\\| "
           "| frames a camera; at the frame rate | processing |", "|---|---:|---|---:|---:|"]

    def largest(rs, keys):
        diffs = [abs(r["sweep"][k] - r["truth"][k]) for r in rs if "sweep" in r for k in keys
                 if r["sweep"].get(k) is not None and r["truth"].get(k) is not None]
        return max(diffs) if diffs else float("nan")

    for (rig, body), rs in groups.items():
        agree = sum(r.get("agree", False) for r in rs)
        ok = [r for r in rs if "sweep" in r]
        agreeing = [r for r in ok if r["agree"]]
        proc = [r["processing_seconds"] for r in ok]
        misses = "; ".join(f"{r['posed']['arms_deg']:g}°, {r['posed']['ankles_mm']:g} mm, "
                           f"{r['posed']['turn_deg']:+g}°: {r.get('differ') or r.get('error')}"
                           for r in rs if not r.get("agree", False))
        out.append(f"| {rig}, {body} | {agree} of {len(rs)} "
                   f"| {largest(agreeing, ['arm_left_deg', 'arm_right_deg']):.1f}°, "
                   f"{largest(agreeing, ['ankles_mm']):.1f} mm, {largest(agreeing, ['turn_deg']):.1f}° "
                   f"| {ok[0]['frames_per_camera']:.0f}; {ok[0]['camera_seconds']:.1f} s "
                   f"| {min(proc):.1f}-{max(proc):.1f} s |")
        if misses:
            out.append(f"| | misses: {misses} | | | |")
    return "\n".join(out)


def measure_repeat(records):
    """Per body: two scans (other noise; the second swaying), the automatic set's differences."""
    out = ["| rig | body | second scan sways | values | over 2 mm | median (mm) | largest (mm) |",
           "|---|---|---:|---:|---:|---:|---|"]
    for r in records:
        p = r["repeat"]
        out.append(f"| {r['rig']} | {r['body']} | {p['sway_mm']:g} mm | {p['count']} | {p['over_2mm']} "
                   f"| {p['median_mm']:.2f} | {p['largest'].replace('_', ' ')} {p['largest_mm']:.2f} |")
    return "\n".join(out)


def open3d_body(records):
    """bodyscan's defaults against Open3D's pipeline on one cloud: time, memory, distances, topology."""
    ours = next(r for r in records if r["mesh"] == "bodyscan")
    theirs = next(r for r in records if r["mesh"] == "open3d")

    def dist(r, key):
        d = r[key]
        return f"{d['mean']:.3f} / {d['rms']:.3f} / {d['p95']:.3f} / {d['p99']:.3f} / {d['max']:.2f}"

    order = ["neighbours", "normals", "orientation", "kernels", "field", "mesh", "poisson"]

    def stages(r):  # in the order each pipeline runs them
        times = sorted(r["stages_seconds"].items(), key=lambda kv: order.index(kv[0]) if kv[0] in order else 99)
        return ", ".join(f"{k} {v:.1f}" for k, v in times) + " s"

    def topology(r):
        closed = "closed, " if r["boundary_edges"] == 0 and r["non_manifold_edges"] == 0 else ""
        return (f"{closed}{r['components']} component{'s' if r['components'] != 1 else ''}, {r['boundary_edges']} "
                f"boundary, {r['non_manifold_edges']} non-manifold edges (Euler {signed(r['euler'], 0)})")

    speed = theirs["process_seconds"] / ours["process_seconds"]
    out = [f"| | bodyscan (defaults) | Open3D {theirs['version']} | ratio |", "|---|---:|---:|---:|",
           f"| wall time, whole process (PLY in → mesh out) | **{ours['process_seconds']:.1f} s** "
           f"| {theirs['process_seconds']:.1f} s | **{speed:.1f}× faster** |",
           f"| stages (in process) | {stages(ours)} | {stages(theirs)} | |",
           f"| peak RSS, whole process | **{ours['process_peak_mb'] / 1024:.2f} GB** "
           f"| {theirs['process_peak_mb'] / 1024:.2f} GB | {ours['process_peak_mb'] / theirs['process_peak_mb']:.2f}× |",
           f"| output → truth: mean / RMS / p95 / p99 / max (mm) | {dist(ours, 'output_to_truth_mm')} "
           f"| {dist(theirs, 'output_to_truth_mm')} "
           f"| RMS {theirs['output_to_truth_mm']['rms'] / ours['output_to_truth_mm']['rms']:.1f}× lower |",
           f"| truth → output: mean / RMS / p95 / p99 / max (mm) | {dist(ours, 'truth_to_output_mm')} "
           f"| {dist(theirs, 'truth_to_output_mm')} "
           f"| RMS {theirs['truth_to_output_mm']['rms'] / ours['truth_to_output_mm']['rms']:.1f}× lower |",
           f"| triangles | {ours['triangles'] / 1e6:.2f} M | {theirs['triangles'] / 1e6:.2f} M | |",
           f"| topology | {topology(ours)} | {topology(theirs)} | |",
           "",
           f"{ours['points']:,} points, {ours['noise_mm']:g} mm noise per axis. Chosen automatically: spacing "
           f"{ours['spacing_mm']:.2f} mm, estimated noise {ours['noise_estimate_mm']:.3f} mm, voxel "
           f"{ours['voxel_mm']:.2f} mm, {ours['bricks']:,} bricks ({ours['field_mb']:.0f} MB of field)."]
    return "\n".join(out)


def open3d_sphere(records):
    """The nonuniform sphere: bodyscan's defaults against Open3D at its best depth, per N and noise."""
    cells = {(r["points"], r["noise"]): r for r in records if "defaults" in r and "open3d" in r}
    sizes = sorted({n for n, _ in cells}, reverse=True)
    noises = sorted({x for _, x in cells})
    out = ["| N | " + " | ".join(f"s = {x:.2f}" for x in noises) + " |", "|---:|" + "---:|" * len(noises)]
    ratios = []
    for n in sizes:
        row = []
        for x in noises:
            r = cells.get((n, x))
            if not r:
                row.append("—")
                continue
            ratio = r["defaults"]["rms"] / r["open3d"]["rms"]
            ratios.append(ratio)
            row.append(f"{r['defaults']['rms']:.6f} / {r['open3d']['rms']:.6f} ({r['open3d']['depth']}; {ratio:.2f})")
        out.append(f"| {n} | " + " | ".join(row) + " |")
    gmean = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
    ratio = records[0]["nonuniform"]
    out += ["", f"Density varying {ratio:g}× across the sphere. bodyscan is more accurate in "
                f"**{sum(x < 1 for x in ratios)} of {len(ratios)} cells** (geometric mean ratio {gmean:.2f}, "
                f"largest {max(ratios):.2f})."]
    return "\n".join(out)


def poissonrecon(records):
    """bodyscan against PoissonRecon on a uniform cloud and a scan's: time, memory, distances, size."""
    cases = [c for c in ("uniform", "scan") if any(r["case"] == c for r in records)]
    cell = {(r["case"], r["method"]): r for r in records}
    columns = []
    for c in cases:
        n = cell[(c, "bodyscan")]["points"]
        what = f"{n / 1e6:g} M uniform" if c == "uniform" else f"tiered scan, {n / 1e3:.0f} k"
        columns.append((c, "bodyscan", f"{what}: bodyscan{' --body' if c == 'scan' else ''}"))
        if (c, "poisson") in cell:
            columns.append((c, "poisson", f"PoissonRecon depth {cell[(c, 'poisson')]['depth']}"))

    def seconds(r):
        if r["method"] == "poisson":
            return f"{r['process_seconds'] + r['normals_seconds']:.1f} (normals {r['normals_seconds']:.1f})"
        return f"{r['process_seconds']:.1f}"

    def dist(key):
        return lambda r: f"{r[key]['rms']:.3f} / {r[key]['p95']:.3f} / {r[key]['max']:.1f}"

    def closed(r):
        return "closed" if r["boundary_edges"] == 0 and r["non_manifold_edges"] == 0 else (
            f"{r['boundary_edges']} boundary, {r['non_manifold_edges']} non-manifold edges")

    rows = [("wall time, whole process (s)", seconds),
            ("peak RSS (GB)", lambda r: f"{r['process_peak_mb'] / 1024:.2f}"),
            ("output → truth: RMS / p95 / max (mm)", dist("output_to_truth_mm")),
            ("truth → output: RMS / p95 / max (mm)", dist("truth_to_output_mm")),
            ("triangles", lambda r: f"{r['triangles'] / 1e6:.2f} M"),
            ("surface", lambda r: f"{closed(r)}, {r['components']} component{'s' if r['components'] != 1 else ''}")]
    out = ["| | " + " | ".join(title for _, _, title in columns) + " |", "|---|" + "---:|" * len(columns)]
    for name, fmt in rows:
        out.append(f"| {name} | " + " | ".join(fmt(cell[(c, m)]) for c, m, _ in columns) + " |")
    notes = []
    for c in cases:
        if (c, "poisson") not in cell:
            continue
        ours, theirs = cell[(c, "bodyscan")], cell[(c, "poisson")]
        time = (theirs["process_seconds"] + theirs["normals_seconds"]) / ours["process_seconds"]
        p95 = ours["output_to_truth_mm"]["p95"] / theirs["output_to_truth_mm"]["p95"]
        notes.append(f"{c}: bodyscan takes {1 / time:.2f}× PoissonRecon's time, its p95 is {p95:.2f}× PoissonRecon's")
    if notes:
        out += ["", "Ratios: " + "; ".join(notes) + "."]
    return "\n".join(out)


def latency(records):
    """Per scan: each stage after the last frame, the totals to the measurements and to mesh.glb, the peak."""
    out = ["| scan | points | triangles | replay (during the scan) | cloud | surface | measurements | files "
           "| → measurements | → mesh.glb | peak RSS |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in records:
        a = r["after_last_frame_seconds"]
        out.append(f"| {r['scan']} | {r['points']:,} | {r['triangles'] / 1e6:.2f} M | {r['replay_seconds']:.2f} s "
                   f"| {a['cloud']:.1f} s | {a['surface']:.1f} s | {a['measurements']:.1f} s | {a['files']:.1f} s "
                   f"| **{r['to_measurements_seconds']:.1f} s** | **{r['to_glb_seconds']:.1f} s** "
                   f"| {r['peak_mb'] / 1024:.2f} GB |")
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
    "scan_cloud": (scan_cloud, "scan"),
    "scan_markers": (scan_markers, "scan"),
    "render": (render, "render"),
    "hole_fill": (hole_fill, "hole_fill"),
    "formats": (formats, "formats"),
    "archived_scan": (archived_scan, "archived_scan"),
    "crash_drill": (crash_drill, "crash_drill"),
    "avatars": (avatars, "avatars"),
    "server_load": (server_load, "server_load"),
    "ui_first_frame": (ui_first_frame, "ui_first_frame"),
    "devices": (devices, "devices"),
    "posture_sweep": (posture_sweep, "posture_sweep"),
    "measure_repeat": (measure_repeat, "measure_repeat"),
    "open3d_body": (open3d_body, "open3d_body"),
    "open3d_sphere": (open3d_sphere, "open3d_sphere"),
    "poissonrecon": (poissonrecon, "poissonrecon"),
    "latency": (latency, "latency"),
}


def figures_path(name):
    return os.path.join(FIGURES, name + ".json")


def with_provenance(text, runs):
    """The rendered table and its provenance; a closing note and the provenance share a paragraph."""
    return text + ("\n\n" if text.rstrip().endswith("|") else "\n") + provenance(runs)


def rendered(table):
    render, figures = TABLES[table]
    runs, records = load([figures_path(figures)])
    return with_provenance(render(records), runs)


def rewrite(doc_text):
    """The document with every table block rendered afresh; unknown names fail."""
    def block(m):
        name = m.group(2)
        if name not in TABLES:
            sys.exit(f"tables: {DOC} names a table '{name}' this script does not know")
        return m.group(1) + rendered(name) + " " + m.group(4)
    return BLOCK.sub(block, doc_text)


def hand_tables(doc_text):
    """The first lines of Markdown tables standing outside every table block."""
    starts, inside, previous = [], False, False
    for number, line in enumerate(doc_text.split("\n"), 1):
        if re.match(r"<!-- table [a-z0-9_]+ -->", line):
            inside = True
        is_row = line.startswith("|")
        if is_row and not previous and not inside:
            starts.append(number)
        if "<!-- /table -->" in line:
            inside = False
        previous = is_row
    return starts


def main(argv):
    if argv[:1] == ["--print"] and len(argv) >= 3 and argv[1] in TABLES:
        runs, records = load(argv[2:])
        print(with_provenance(TABLES[argv[1]][0](records), runs))
        return 0
    if argv[:1] == ["--store"] and len(argv) >= 3:
        runs, records = load(argv[2:])
        os.makedirs(FIGURES, exist_ok=True)
        with open(figures_path(argv[1]), "w") as f:
            json.dump({"runs": runs, "records": records}, f, indent=1, ensure_ascii=False)
            f.write("\n")
        print(f"tables: stored {len(records)} records of {len(runs)} runs as {figures_path(argv[1])}")
        return 0
    if argv[:1] == ["--wrap"] and len(argv) == 3:
        records = json.load(sys.stdin)
        with open(argv[1], "w") as f:
            json.dump({"run": run_record(argv[2]), "records": records}, f, indent=1, ensure_ascii=False)
            f.write("\n")
        return 0
    if argv not in ([], ["--check"]):
        print(__doc__, file=sys.stderr)
        return 2
    text = open(DOC).read()
    new = rewrite(text)
    count = len(BLOCK.findall(text))
    if argv == ["--check"]:
        loose = hand_tables(text)
        if loose:
            print(f"tables: {DOC} has tables no benchmark's figures render, at lines {', '.join(map(str, loose))}; "
                  "give each a <!-- table NAME --> block", file=sys.stderr)
            return 1
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
