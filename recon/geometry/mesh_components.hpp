// Connected components of a triangle mesh: triangles joined by shared edges, as
// analyze_topology() counts them. A piece that touches the rest at a single
// vertex (a small closed blob the hole filling left in an eye socket) is a
// component of its own, so that remove_small_components() drops it.
#pragma once

#include <cstdint>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

struct MeshComponents {
  std::vector<uint32_t> triangle_label;  // component of each triangle
  std::vector<size_t> triangle_count;    // triangles per component, largest first
};

// Labels components; component 0 is the largest, then by decreasing size.
MeshComponents label_components(const TriangleMesh& mesh);

// Removes every component with fewer triangles than `min_fraction` of the largest
// one (stray blobs from outliers), and the vertices only they used. Returns the
// number of components removed.
size_t remove_small_components(TriangleMesh& mesh, double min_fraction);

// Drops vertices no triangle uses and renumbers the triangles.
void remove_unreferenced_vertices(TriangleMesh& mesh);

}  // namespace bodyscan
