#!/usr/bin/python3
"""The peer of body_benchmark: Open3D's standard pipeline on the same cloud.

    open3d_body.py POINTS.ply OUT.ply [--depth 9] [--k 30] [--json OUT.json]

estimate_normals (k nearest) + orient_normals_consistent_tangent_plane (k) +
create_from_point_cloud_poisson (Screened Poisson, depth 9). Prints wall time per
stage and in total (--json: also as a JSON record); the mesh is written untrimmed
(Poisson's output as is).
Uses Debian's python3-open3d (deploy/install-deps.sh --bench).
"""
import argparse
import json
import resource
import time

import open3d as o3d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("points")
    ap.add_argument("out")
    ap.add_argument("--depth", type=int, default=9)
    ap.add_argument("--k", type=int, default=30)
    ap.add_argument("--json")
    args = ap.parse_args()

    pcd = o3d.io.read_point_cloud(args.points)
    pcd.normals = o3d.utility.Vector3dVector()  # no input normals, as for ours
    t0 = time.perf_counter()
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(args.k))
    t1 = time.perf_counter()
    pcd.orient_normals_consistent_tangent_plane(args.k)
    t2 = time.perf_counter()
    mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=args.depth)
    t3 = time.perf_counter()
    o3d.io.write_triangle_mesh(args.out, mesh)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"open3d {o3d.__version__}: {len(pcd.points)} points -> {len(mesh.triangles)} triangles")
    print(f"wall time       {t3 - t0:.2f} s (normals {t1 - t0:.2f}, orientation {t2 - t1:.2f}, "
          f"poisson depth {args.depth} {t3 - t2:.2f})")
    print(f"peak memory     {peak_mb:.0f} MB")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"mesh": "open3d", "version": o3d.__version__, "points": len(pcd.points), "depth": args.depth,
                       "k": args.k, "seconds": t3 - t0, "peak_mb": peak_mb,
                       "stages_seconds": {"normals": t1 - t0, "orientation": t2 - t1, "poisson": t3 - t2}}, f)


if __name__ == "__main__":
    main()
