#!/usr/bin/python3
"""The surface across an unseen strip of a wrist: a cylinder of radius 27 mm (a
170 mm girth), 300 mm long along Y, sampled every 1.5 mm round and along, with a
strip of GAP degrees round it left unseen over Y in [-40, 40] but for a stray
point every 16 mm along and 6 mm round (as the tiered rig leaves the right wrist:
docs/benchmarks.md §7). Each cloud is made into a closed surface by
`bodyscan reconstruct --body` (normals from the points, as a scan's), then
measured by `bodyscan measure --girth-y 0`.

    bench/gap_cylinder.py [--bodyscan build/app/bodyscan] [--seed 1 ...] [--json OUT.json]

Prints per case the radius's error (mean and largest, mm) over the strip's middle
(|Y| < 20, within 20 degrees of its centre) and on the far side, and the tape's
girth at Y = 0 against the true 169.65 mm; with several seeds, each seed's
cases in turn. --json also writes the cases (bench/tables.py renders the
gap_cylinder table from it). Uses Debian's python3-numpy
(deploy/install-deps.sh --bench).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tables import run_record  # noqa: E402

RADIUS = 27.0
STEP = 1.5


def cloud(gap_deg, noise, stray, quiet_strays, rng):
    na = int(2 * np.pi * RADIUS / STEP)
    pts = []
    for y in np.arange(-150, 150.01, STEP):
        for i in range(na):
            a = 2 * np.pi * i / na
            deg = np.degrees(a)
            in_strip = abs(y) < 40 and (deg < gap_deg / 2 or deg > 360 - gap_deg / 2)
            if in_strip and not (stray and abs((y + 150) % 16) < 0.75 and i % 4 == 0):
                continue
            r = RADIUS + (0 if in_strip and quiet_strays else noise) * rng.standard_normal()
            pts.append((r * np.cos(a), y, r * np.sin(a)))
    return np.array(pts)


def write_ply(path, pts, normals=None):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(pts))
        f.write("property float x\nproperty float y\nproperty float z\n")
        if normals is not None:
            f.write("property float nx\nproperty float ny\nproperty float nz\n")
        f.write("end_header\n")
        for i, p in enumerate(pts):
            if normals is None:
                f.write("%.4f %.4f %.4f\n" % tuple(p))
            else:
                f.write("%.4f %.4f %.4f %.5f %.5f %.5f\n" % (*p, *normals[i]))


def read_ply_vertices(path):
    with open(path) as f:
        lines = f.read().split("\n")
    end = lines.index("end_header")
    nv = int(next(l for l in lines if l.startswith("element vertex")).split()[-1])
    return np.array([[float(x) for x in l.split()[:3]] for l in lines[end + 1:end + 1 + nv]])


# (strip's width, noise, stray points in it, the strays without noise, the true
# normals given instead of those the reconstruction estimates)
CASES = [(0, 0, False, False, False), (40, 0, False, False, False), (40, 0, True, False, False),
         (0, 0.3, False, False, False), (40, 0.3, False, False, False), (40, 0.3, False, False, True),
         (40, 0.3, True, False, False), (40, 0.3, True, True, False), (60, 0.3, True, False, False)]


def run_case(bodyscan, tmp, rng, gap, noise, stray, quiet, given):
    src, out = os.path.join(tmp, "c.ply"), os.path.join(tmp, "m.ply")
    pts = cloud(gap, noise, stray, quiet, rng)
    radial = pts * np.array([1, 0, 1])
    write_ply(src, pts, radial / np.linalg.norm(radial, axis=1)[:, None] if given else None)
    subprocess.run([bodyscan, "reconstruct", src, "-o", out, "--body", "--ascii", "-q"] +
                   (["--normals", "input"] if given else []), check=True)
    v = read_ply_vertices(out)
    r = np.hypot(v[:, 0], v[:, 2]) - RADIUS
    a = np.degrees(np.arctan2(v[:, 2], v[:, 0]))
    mid = np.abs(v[:, 1]) < 20
    strip = mid & (np.abs(a) < 20)
    far = mid & (np.abs(np.abs(a) - 180) < 30)
    m = json.loads(subprocess.run([bodyscan, "measure", out, "--girth-y", "0"], check=True,
                                  capture_output=True, text=True).stdout)
    girth = m["measurements"][0]["value_mm"]
    return {"strip_deg": gap, "noise_mm": noise, "stray": stray, "quiet_strays": quiet,
            "true_normals": given, "strip_mean_mm": float(r[strip].mean()), "strip_largest_mm": float(r[strip].max()),
            "far_mean_mm": float(r[far].mean()), "girth_mm": girth, "girth_error_mm": girth - 2 * np.pi * RADIUS}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bodyscan", default="build/app/bodyscan")
    ap.add_argument("--seed", type=int, action="append")
    ap.add_argument("--json")
    args = ap.parse_args()
    run = run_record()
    records = []
    print("seed  gap (deg)  noise (mm)  stray points  normals     strip: mean / largest (mm)  far side mean  "
          "girth at Y=0 (mm, off the truth)")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seed or [1]:
            rng = np.random.default_rng(seed)
            for case in CASES:
                c = run_case(args.bodyscan, tmp, rng, *case)
                c["seed"] = seed
                records.append(c)
                stray = ("noise-free" if c["quiet_strays"] else "yes") if c["stray"] else "no"
                print("%4d  %9d  %10.1f  %12s  %-9s  %+8.3f / %+6.3f  %+13.3f  %.2f (%+.2f)" %
                      (seed, c["strip_deg"], c["noise_mm"], stray, "true" if c["true_normals"] else "estimated",
                       c["strip_mean_mm"], c["strip_largest_mm"], c["far_mean_mm"], c["girth_mm"],
                       c["girth_error_mm"]), flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"run": run, "records": records}, f, indent=1)


if __name__ == "__main__":
    main()
