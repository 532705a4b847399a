// A surface decimated to a triangle budget, for the tools that cannot take a scan's
// millions of triangles (CAD avatars, a screen's display mesh), with the distance
// it moved measured rather than promised.
//
// Edge collapses with quadric error metrics (meshoptimizer's meshopt_simplify:
// M. Garland, P. Heckbert, "Surface simplification using quadric error metrics",
// SIGGRAPH 1997). A collapse never changes the topology, so a closed surface stays
// closed; the budget is met unless that would take a collapse that does.
#pragma once

#include <cstddef>

#include "recon/core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

struct SimplifyOptions {
  size_t max_triangles = 70000;  // the budget (CLO3D asks for about 70,000)
  // Stop collapsing earlier if the next collapse would move the surface farther
  // than this (mm); the budget is then undercut. 0: the budget alone decides.
  double max_error_mm = 0;
};

struct SimplifyResult {
  TriangleMesh mesh;  // vertices, triangles, normals recomputed; no confidence
  // The largest distance from a vertex of either surface to the other (a two-way
  // Hausdorff distance sampled at the vertices), mm.
  double max_deviation_mm = 0;
};

// The mesh with at most options.max_triangles triangles (fewer where a collapse
// would tear or fold it). A mesh already within the budget comes back as it is,
// normals computed. Errors on an inconsistent mesh or a budget under 4.
StatusOr<SimplifyResult> simplify(const TriangleMesh& mesh, const SimplifyOptions& options = {});

}  // namespace bodyscan
