// A surface decimated to a triangle budget, for the tools that cannot take a scan's
// millions of triangles (CAD avatars, a screen's display mesh), with the distance
// it moved measured rather than promised.
//
// Edge collapses with quadric error metrics (meshoptimizer's meshopt_simplify:
// M. Garland, P. Heckbert, "Surface simplification using quadric error metrics",
// SIGGRAPH 1997). Its collapses may fold a thin part into a fin or pinch two parts
// together along an edge; both are mended (simplify.cpp), so that a closed surface
// comes out closed, every edge between two triangles (the tests check it on bodies
// and scans).
#pragma once

#include <cstddef>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

struct SimplifyOptions {
  size_t max_triangles = 70000;  // the budget (CLO3D asks for about 70,000)
  // Stop collapsing earlier if the next collapse would move the surface farther
  // than this (mm); the budget is then undercut. 0: the budget alone decides.
  double max_error_mm = 0;
  // Measure max_deviation_mm (two distance queries per vertex, about half the
  // time on a body); off, it is reported as 0.
  bool measure_deviation = true;
};

struct SimplifyResult {
  TriangleMesh mesh;  // vertices, triangles, normals recomputed; no confidence
  // The largest distance from a vertex of either surface to the other (a two-way
  // Hausdorff distance sampled at the vertices), mm.
  double max_deviation_mm = 0;
};

// The mesh with at most options.max_triangles triangles. Vertices within a
// thousandth of a millimetre of each other are joined first, so that no two print
// alike in any unit. A mesh already within the budget comes back otherwise as it
// is, normals computed. Errors on an inconsistent mesh or a budget under 4.
StatusOr<SimplifyResult> simplify(const TriangleMesh& mesh, const SimplifyOptions& options = {});

}  // namespace bodyscan
