// Small analytic meshes shared by the tests.
#pragma once

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::testing {

// The box [lo, hi] as 12 triangles wound counter-clockwise seen from outside.
// Vertex i sits at corner (i & 1, i >> 1 & 1, i >> 2 & 1); faces are triangles 2k
// and 2k + 1 for k = z lo, z hi, y lo, y hi, x lo, x hi.
TriangleMesh box_mesh(const Vec3f& lo, const Vec3f& hi);

// The cube [0, 1]^3 (box_mesh).
TriangleMesh unit_cube();

// An icosahedron subdivided `levels` times, its vertices projected onto the
// sphere of `radius` about the origin; wound outward.
TriangleMesh icosphere(int levels, double radius);

}  // namespace bodyscan::testing
