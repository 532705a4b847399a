#!/usr/bin/python3
"""The peer on the sphere table: Open3D's standard pipeline on one sphere cloud.

    open3d_sphere.py POINTS.ply [--depths 6,7,8] [--k 30] [--json OUT.json]

estimate_normals (k nearest) + orient_normals_consistent_tangent_plane (k) +
Screened Poisson at each depth; prints, per depth, RMS of (|v| - 1) over the output
vertices (the thesis's error measure) and the time, then the best depth. Poisson's
octree depth is its resolution knob, so giving it the best of several is Open3D
tuned per cell, as our --tuned is. --json writes the best depth and its RMS.
"""
import argparse
import json
import time

import numpy as np
import open3d as o3d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("points")
    ap.add_argument("--depths", default="6,7,8")
    ap.add_argument("--k", type=int, default=30)
    ap.add_argument("--json")
    args = ap.parse_args()

    pcd = o3d.io.read_point_cloud(args.points)
    pcd.normals = o3d.utility.Vector3dVector()
    t0 = time.perf_counter()
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(args.k))
    pcd.orient_normals_consistent_tangent_plane(args.k)
    t_normals = time.perf_counter() - t0
    best = None
    for depth in (int(d) for d in args.depths.split(",")):
        t1 = time.perf_counter()
        mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
        dt = time.perf_counter() - t1 + t_normals
        v = np.asarray(mesh.vertices)
        rms = float(np.sqrt(np.mean((np.linalg.norm(v, axis=1) - 1.0) ** 2))) if len(v) else float("nan")
        print(f"depth {depth}: rms {rms:.6f}, {len(mesh.triangles)} triangles, {dt:.2f} s")
        if best is None or rms < best[1]:
            best = (depth, rms)
    print(f"best depth {best[0]} rms {best[1]:.6f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"depth": best[0], "rms": best[1], "k": args.k, "version": o3d.__version__}, f)


if __name__ == "__main__":
    main()
