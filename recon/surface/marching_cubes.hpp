// Marching cubes (Lorensen & Cline 1987) on the zero level set of a sparse
// ImplicitField, into one indexed, crack-free mesh.
//
// The case table is generated at start-up from one rule rather than typed in: on
// every cube face, walking its corners counter-clockwise seen from outside, each
// entry into the inside region is joined to the next exit. The rule depends only on
// the face's four corners, so the two cells sharing a face always cut it the same
// way (no cracks, the ambiguity of the original table), and the joined face
// segments close into loops that are triangulated as fans. Triangles wind
// counter-clockwise seen from outside (where the field is negative).
//
// Every grid edge's vertex is created once, by the brick that owns the edge's first
// node, so brick seams carry no duplicate vertices.
#pragma once

#include <array>
#include <vector>

#include "core/progress.hpp"
#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/surface/implicit_field.hpp"

namespace bodyscan {

struct MarchingCubesOptions {
  // A node is defined when its Gaussian weight W is at least this (and > 0): only
  // cells whose eight corners are defined produce triangles. W is a sum of kernel
  // peaks of height `weight` (1 for full-confidence points).
  float min_weight = 1e-6f;
  ProgressFn progress;
};

// The triangles of one cube configuration as triples of cube-edge numbers.
// Corner v sits at (v & 1, v >> 1 & 1, v >> 2 & 1); edge 4a + b + 2c runs along axis
// a from the corner whose other two coordinates are the bits b, c (in axis order
// a+1, a+2 mod 3). `inside_mask` bit v is set when corner v is inside (field > 0).
const std::vector<std::array<uint8_t, 3>>& marching_cubes_case(uint8_t inside_mask);

StatusOr<TriangleMesh> extract_isosurface(const ImplicitField& field, const MarchingCubesOptions& options = {});

}  // namespace bodyscan
