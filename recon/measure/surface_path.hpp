// Lengths along the body (a tape laid on the skin between two points, rather than
// around a plane's section): the shortest path on the mesh's surface.
//
// The path is exact for the triangle mesh, not an edge-graph approximation (which
// runs 2-8 % long by zig-zagging along edges):
//  1. both ends are snapped to the nearest point of the surface;
//  2. a strip of edge-adjacent triangles joining them is found by Dijkstra on the
//     triangles' adjacency (centroid to centroid);
//  3. the strip is unfolded into the plane and the shortest path through it is
//     pulled taut with the funnel algorithm (Lee & Preparata 1984), which is exact
//     within the strip;
//  4. where the taut path wraps round a strip vertex whose other side is shorter
//     (the angle there, going round the other way, is under 180 degrees), the strip
//     is re-routed through that vertex's other triangles, and step 3 repeats until
//     no vertex is left to re-route. What remains is a locally shortest geodesic:
//     it passes through a vertex only where the surface is saddle-shaped;
//  5. a body has more than one of those between two points (over a muscle's ridge
//     or round it), and steps 2-4 settle into the one nearest the strip they start
//     from: they run from each end, and the shorter path is kept.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

struct SurfacePath {
  // The tape's length: the path measured in chords of SurfacePathOptions::tape_step_mm,
  // as a tape laid along it bridges roughness shorter than that.
  double value_mm = 0;
  double path_mm = 0;                 // the exact path's own length on the mesh
  double straight_mm = 0;             // the chord between the two ends
  std::vector<Eigen::Vector3d> path;  // on the surface, from the first end to the second
  Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::Zero();  // the ends as snapped
  float min_confidence = 1;  // lowest mesh confidence along the path (1: all measured)
  double fill_bound_mm = 0;  // how far filled skin under it could move it (fill_bound.hpp)
  size_t reroutes = 0;       // vertex re-routings step 4 made (both searches)
};

struct SurfacePathOptions {
  size_t max_reroute_rounds = 10000;
  // A scanned surface is rough on the scale of its noise, and the exact path on it
  // follows every ripple (2-4 % long over a scan's noise; docs/measurements.md).
  // The value is the path's length in chords this long (0 = the path itself). The
  // error against the exact length on a smooth body is under L^3 / (24 R^2) per
  // chord of length L over skin of radius R: 0.1 mm per chord at R = 20 mm.
  double tape_step_mm = 10;
};

// Shortest paths on one mesh, its adjacency and snapping grid built once
// (O(T log T)). Keeps a reference to the mesh, which must outlive it and not
// change. One query at a time (the search keeps its scratch arrays).
class SurfacePaths {
 public:
  explicit SurfacePaths(const TriangleMesh& mesh);
  ~SurfacePaths();
  SurfacePaths(const SurfacePaths&) = delete;
  SurfacePaths& operator=(const SurfacePaths&) = delete;

  // The shortest path between the surface points nearest `from` and `to`. Errors:
  // empty mesh; the two points lie on parts of the mesh that do not connect.
  StatusOr<SurfacePath> shortest(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                 const SurfacePathOptions& options = {}) const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// One path on a mesh (builds a SurfacePaths for it).
StatusOr<SurfacePath> mesh_surface_path(const TriangleMesh& mesh, const Eigen::Vector3d& from,
                                        const Eigen::Vector3d& to, const SurfacePathOptions& options = {});

}  // namespace bodyscan
