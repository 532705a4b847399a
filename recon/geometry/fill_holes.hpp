// Closing a mesh's holes, and trimming flaps the data does not support.
//
// fill_holes follows Liepa, "Filling holes in meshes" (SGP 2003):
//  1. each boundary loop is triangulated without new vertices by dynamic
//     programming over the loop (Barequet & Sharir), choosing the triangulation
//     that minimises the largest dihedral angle - between its own triangles and
//     with the mesh triangles on the loop - then the total area, so the patch
//     bends as little as possible away from the surface around it;
//  2. the patch is refined to the density of the surrounding mesh: a triangle is
//     split at its centroid while it is larger than its corners' local edge
//     lengths, and edges are flipped to the Delaunay condition;
//  3. the new vertices are faired: their positions minimise the squared umbrella
//     Laplacian, either at the new vertices only (a membrane: the smooth minimal
//     surface the loop spans, the default) or also at the loop's vertices (a thin
//     plate: the patch continues the surrounding surface's curvature instead of
//     spanning it - the flat fill the thesis blames for its expanded measurements,
//     §5 - but on a twisted loop, as in a cavity a scanner cannot see into, it
//     balloons out; measured in docs/reconstruction.md).
// Loops longer than max_dp_edges are first cut by short diagonals (the dynamic
// programme is cubic in the loop length).
//
// New vertices get confidence 0 and the loop's keep theirs (the mesh's confidence
// is created, all 1, if it had none), so measurements can tell where the surface
// was invented.
#pragma once

#include <cstddef>
#include <functional>

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

enum class HoleFairing { kNone, kMembrane, kThinPlate };

struct HoleFillOptions {
  // Loops with more boundary edges than this stay open (0 = fill every loop).
  size_t max_hole_edges = 0;
  // Loops whose initial triangulation is larger than this stay open (0 = no
  // limit): an opening that big is the surface's real edge, not a hole.
  double max_hole_area = 0.0;
  // Longer loops are split by diagonals before the cubic dynamic programme. The
  // shortest diagonal can run across the body rather than the hole - the square
  // rig's feet, 70 mm up - and 1000 takes those loops whole (the fill then takes
  // 7.2 s instead of 5.3 on that scan, bench/hole_fill_benchmark). But on the
  // thesis rig the whole programme spans the unseen shoulder tops worse than the
  // split parts do (fewer measurements within the ISO allowance at 1000;
  // docs/benchmarks.md §7, "Hole filling"), so the default stays at 400.
  size_t max_dp_edges = 400;
  bool refine = true;
  HoleFairing fairing = HoleFairing::kMembrane;
};

struct HoleFillStats {
  size_t holes = 0;  // boundary loops found
  size_t holes_filled = 0;
  size_t largest_hole_edges = 0;  // boundary edges of the longest loop
  size_t triangles_added = 0;
  size_t vertices_added = 0;
  double area_added = 0.0;  // square units of the mesh
};

// Fills the mesh's boundary loops in place. Needs an edge-manifold, consistently
// wound mesh (as marching cubes makes); loops through non-manifold edges are
// skipped. Vertex normals, if present, are recomputed.
HoleFillStats fill_holes(TriangleMesh& mesh, const HoleFillOptions& options = {});

// Removes triangles from the mesh's boundary inward while all three of their
// vertices are `unsupported` (e.g. farther from every measured point than the noise
// allows): flaps the field grew past its data. Stops at the first supported
// triangle on every path, so a closed mesh is never touched. Drops vertices no
// triangle uses any more. Returns the number of triangles removed.
size_t trim_boundary_flaps(TriangleMesh& mesh, const std::function<bool(uint32_t vertex)>& unsupported);

}  // namespace bodyscan
