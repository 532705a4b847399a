// Marching cubes: the generated case table checked for closure and winding, then
// meshes of fields whose zero sets are known spheres and planes.
#include "recon/surface/marching_cubes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "recon/geometry/mesh_components.hpp"
#include "recon/geometry/sample_surface.hpp"
#include "tests/recon/surface/sphere_kernels.hpp"

namespace bodyscan {
namespace {

// ---------------------------------------------------------------------------------
// The case table.

// Midpoint of cube edge e in doubled coordinates (each 0, 1 or 2): edge 4a + b + 2c
// runs along axis a from the corner whose coordinates on axes a+1, a+2 are b, c.
using P3 = std::array<int, 3>;
P3 edge_mid2(int e) {
  const int a = e / 4;
  P3 p{};
  p[a] = 1;
  p[(a + 1) % 3] = 2 * (e & 1);
  p[(a + 2) % 3] = 2 * ((e >> 1) & 1);
  return p;
}
P3 corner2(int v) { return {2 * (v & 1), 2 * ((v >> 1) & 1), 2 * ((v >> 2) & 1)}; }
bool corner_inside(int mask, int v) { return (mask >> v) & 1; }

// The two corners an edge joins.
std::pair<int, int> edge_corners(int e) {
  const P3 m = edge_mid2(e);
  int c0 = 0, c1 = 0;
  for (int d = 0; d < 3; ++d) {
    const int lo = m[d] == 1 ? 0 : m[d] / 2, hi = m[d] == 1 ? 1 : m[d] / 2;
    c0 |= lo << d;
    c1 |= hi << d;
  }
  return {c0, c1};
}

using Segment = std::pair<P3, P3>;  // directed, in doubled coordinates

// Segments of the case's triangles used once (the patch's boundary), directed as the
// triangles walk them. Fails the test if an edge is used more than twice or twice in
// the same direction.
std::vector<Segment> boundary_segments(int mask) {
  std::map<std::pair<P3, P3>, int> directed;
  for (const auto& t : marching_cubes_case(static_cast<uint8_t>(mask))) {
    for (int k = 0; k < 3; ++k) ++directed[{edge_mid2(t[k]), edge_mid2(t[(k + 1) % 3])}];
  }
  std::vector<Segment> boundary;
  for (const auto& [seg, count] : directed) {
    EXPECT_EQ(count, 1) << "mask " << mask << ": a segment walked twice the same way";
    const int back = directed.count({seg.second, seg.first}) ? directed.at({seg.second, seg.first}) : 0;
    if (back == 0) boundary.push_back(seg);
  }
  return boundary;
}

// The boundary segments lying on the face `axis` = side (side 0 or 2 in doubled coords).
std::set<Segment> on_face(const std::vector<Segment>& segs, int axis, int side) {
  std::set<Segment> out;
  for (const Segment& s : segs)
    if (s.first[axis] == side && s.second[axis] == side) out.insert(s);
  return out;
}

TEST(MarchingCubesTable, EmptyAndFullCasesHaveNoTriangles) {
  EXPECT_TRUE(marching_cubes_case(0).empty());
  EXPECT_TRUE(marching_cubes_case(255).empty());
}

// True when some face has its inside corners on one diagonal and its outside corners
// on the other: the face whose cut the sign pattern alone does not decide.
bool has_ambiguous_face(int mask) {
  for (int a = 0; a < 3; ++a) {
    for (int side = 0; side < 2; ++side) {
      const int b = (a + 1) % 3, c = (a + 2) % 3, base = side << a;
      const bool c00 = corner_inside(mask, base), c11 = corner_inside(mask, base | 1 << b | 1 << c);
      const bool c10 = corner_inside(mask, base | 1 << b), c01 = corner_inside(mask, base | 1 << c);
      if (c00 == c11 && c10 == c01 && c00 != c10) return true;
    }
  }
  return false;
}

// A case's triangles as edge triples rotated to start at their smallest edge (winding
// kept), sorted; `reversed` flips each triangle's winding first.
std::vector<std::array<int, 3>> canonical_case(int mask, bool reversed) {
  std::vector<std::array<int, 3>> out;
  for (const auto& t : marching_cubes_case(static_cast<uint8_t>(mask))) {
    std::array<int, 3> e = {t[0], t[1], t[2]};
    if (reversed) std::swap(e[1], e[2]);
    std::rotate(e.begin(), std::min_element(e.begin(), e.end()), e.end());
    out.push_back(e);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(MarchingCubesTable, ComplementaryCasesAreTheSameSurfaceReversed) {
  // Swapping inside and outside turns the surface around. The classic table's rule
  // (a complement has the same triangles) holds exactly where no face is ambiguous.
  // On an ambiguous face this table always cuts the two inside corners off
  // separately (the outside stays connected across the face), for a case and its
  // complement alike, so that neighbouring cells agree: there the complement is a
  // different surface and may have more triangles (e.g. two diagonal corners of a
  // face: 2 triangles; its complement: 4).
  size_t unambiguous = 0, differing = 0;
  for (int mask = 0; mask < 256; ++mask) {
    if (has_ambiguous_face(mask)) {
      differing += marching_cubes_case(static_cast<uint8_t>(mask)).size() !=
                   marching_cubes_case(static_cast<uint8_t>(255 - mask)).size();
      continue;
    }
    ++unambiguous;
    EXPECT_EQ(canonical_case(mask, false), canonical_case(255 - mask, true)) << "mask " << mask;
  }
  EXPECT_GT(unambiguous, 100u);
  EXPECT_GT(differing, 0u);  // the asymmetry is real, not an artefact of the test
}

TEST(MarchingCubesTable, AmbiguousFacesSeparateTheInsideCorners) {
  // Corners 0 and 3 of the z = 0 face inside (diagonal): two separate corner
  // triangles; corners 1 and 2 inside: likewise. The complements (six corners inside)
  // join the inside around the two outside corners in one sheet.
  for (int mask : {0x09, 0x06}) {
    EXPECT_EQ(marching_cubes_case(static_cast<uint8_t>(mask)).size(), 2u) << mask;
    EXPECT_EQ(marching_cubes_case(static_cast<uint8_t>(255 - mask)).size(), 4u) << mask;
  }
}

TEST(MarchingCubesTable, TrianglesUseOnlyCrossedEdges) {
  for (int mask = 1; mask < 255; ++mask) {
    const auto& tris = marching_cubes_case(static_cast<uint8_t>(mask));
    EXPECT_FALSE(tris.empty()) << "mask " << mask << " has a sign change but no triangles";
    std::set<int> used;
    for (const auto& t : tris) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_LT(t[k], 12) << "mask " << mask;
        const auto [c0, c1] = edge_corners(t[k]);
        EXPECT_NE(corner_inside(mask, c0), corner_inside(mask, c1))
            << "mask " << mask << " puts a vertex on edge " << int{t[k]} << " whose ends agree";
        used.insert(t[k]);
      }
      EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) << "degenerate triangle, mask " << mask;
    }
    // Every crossed edge carries a vertex.
    for (int e = 0; e < 12; ++e) {
      const auto [c0, c1] = edge_corners(e);
      if (corner_inside(mask, c0) != corner_inside(mask, c1)) {
        EXPECT_TRUE(used.count(e)) << "mask " << mask << " leaves crossed edge " << e << " unused";
      }
    }
  }
}

TEST(MarchingCubesTable, PatchBoundaryLiesOnTheCubeFaces) {
  // Inside the cube the patch is a manifold: segments used twice are walked once each
  // way (checked by boundary_segments); those used once lie on a face.
  for (int mask = 1; mask < 255; ++mask) {
    for (const Segment& s : boundary_segments(mask)) {
      bool on_a_face = false;
      for (int d = 0; d < 3; ++d) on_a_face |= s.first[d] == s.second[d] && (s.first[d] == 0 || s.first[d] == 2);
      EXPECT_TRUE(on_a_face) << "mask " << mask << ": an open edge inside the cube";
    }
  }
}

TEST(MarchingCubesTable, NeighbouringCellsCutTheirSharedFaceAlike) {
  // Cell A and the cell B beyond A's face `axis` = 1 share four corners. Whatever B's
  // other four corners are, B's boundary on its face `axis` = 0 must be A's on the
  // shared face walked backwards: that is what makes the mesh closed and consistently
  // wound across cells.
  for (int axis = 0; axis < 3; ++axis) {
    for (int a = 0; a < 256; ++a) {
      std::set<Segment> shared;
      for (const Segment& s : on_face(boundary_segments(a), axis, 2)) {
        Segment back{s.second, s.first};
        back.first[axis] = 0;
        back.second[axis] = 0;
        shared.insert(back);
      }
      for (int others = 0; others < 16; ++others) {
        int b = 0, bit = 0;
        for (int v = 0; v < 8; ++v) {
          if ((v >> axis) & 1) {
            b |= ((others >> bit++) & 1) << v;  // B's far face: any values
          } else if (corner_inside(a, v | (1 << axis))) {
            b |= 1 << v;  // B's near face = A's far face
          }
        }
        EXPECT_EQ(on_face(boundary_segments(b), axis, 0), shared) << "axis " << axis << " cells " << a << " | " << b;
      }
    }
  }
}

TEST(MarchingCubesTable, AdjacentCellsNeverShareAnEdgeMoreThanTwice) {
  size_t in_face = 0;
  for (int mask = 1; mask < 255; ++mask) {
    for (const auto& t : marching_cubes_case(static_cast<uint8_t>(mask))) {
      const P3 a = edge_mid2(t[0]), b = edge_mid2(t[1]), c = edge_mid2(t[2]);
      for (int d = 0; d < 3; ++d) in_face += a[d] == b[d] && b[d] == c[d] && a[d] != 1;
    }
  }
  EXPECT_EQ(in_face, 0u) << "triangles lying in a cube face";
  size_t overused = 0;
  for (int axis = 0; axis < 3; ++axis) {
    for (int a = 0; a < 256; ++a) {
      for (int others = 0; others < 16; ++others) {
        int b = 0, bit = 0;
        for (int v = 0; v < 8; ++v) {
          if ((v >> axis) & 1) {
            b |= ((others >> bit++) & 1) << v;
          } else if (corner_inside(a, v | (1 << axis))) {
            b |= 1 << v;
          }
        }
        std::map<std::pair<P3, P3>, int> uses;
        auto add = [&](int mask, int shift) {
          for (const auto& t : marching_cubes_case(static_cast<uint8_t>(mask))) {
            for (int k = 0; k < 3; ++k) {
              P3 p = edge_mid2(t[k]), q = edge_mid2(t[(k + 1) % 3]);
              p[axis] += shift;
              q[axis] += shift;
              ++uses[{std::min(p, q), std::max(p, q)}];
            }
          }
        };
        add(a, 0);
        add(b, 2);
        for (const auto& [seg, count] : uses) overused += count > 2;
      }
    }
  }
  EXPECT_EQ(overused, 0u);
}

Vec3d tri_normal(const std::array<uint8_t, 3>& t) {
  Vec3d p[3];
  for (int k = 0; k < 3; ++k) {
    const P3 m = edge_mid2(t[k]);
    p[k] = Vec3d(m[0], m[1], m[2]) / 2;
  }
  return (p[1] - p[0]).cross(p[2] - p[0]);
}

Vec3d tri_centroid(const std::array<uint8_t, 3>& t) {
  Vec3d c = Vec3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const P3 m = edge_mid2(t[k]);
    c += Vec3d(m[0], m[1], m[2]) / 6;
  }
  return c;
}

TEST(MarchingCubesTable, SingleCornerCasesWindOutward) {
  for (int v = 0; v < 8; ++v) {
    const P3 c2 = corner2(v);
    const Vec3d corner = Vec3d(c2[0], c2[1], c2[2]) / 2;
    // Corner v alone inside: the triangle cuts it off and faces away from it.
    const auto& in = marching_cubes_case(static_cast<uint8_t>(1 << v));
    ASSERT_EQ(in.size(), 1u) << "corner " << v;
    EXPECT_GT(tri_normal(in[0]).dot(tri_centroid(in[0]) - corner), 0.0) << "corner " << v << " inside";
    // Corner v alone outside: the triangle faces toward it.
    const auto& out = marching_cubes_case(static_cast<uint8_t>(255 ^ (1 << v)));
    ASSERT_EQ(out.size(), 1u) << "corner " << v;
    EXPECT_LT(tri_normal(out[0]).dot(tri_centroid(out[0]) - corner), 0.0) << "corner " << v << " outside";
    // Both on the three edges at the corner.
    for (const auto* t : {&in[0], &out[0]}) {
      for (int k = 0; k < 3; ++k) {
        const auto [c0, c1] = edge_corners((*t)[k]);
        EXPECT_TRUE(c0 == v || c1 == v) << "corner " << v;
      }
    }
  }
}

TEST(MarchingCubesTable, HalfCubeIsOneQuad) {
  // The lower half (z = 0 corners) inside: a quad across the four vertical edges,
  // facing +z (outside).
  const auto& tris = marching_cubes_case(0x0F);
  ASSERT_EQ(tris.size(), 2u);
  for (const auto& t : tris) {
    const Vec3d n = tri_normal(t).normalized();
    EXPECT_NEAR(n.z(), 1.0, 1e-12);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(t[k] / 4, 2) << "vertex on a non-vertical edge";
  }
}

// ---------------------------------------------------------------------------------
// Meshes of known fields.

// Kernels on a sphere of `radius` about `centre`, exact normals, bent by the sphere's
// curvature so the zero set sits on the sphere.
std::vector<Kernel> sphere_kernels(size_t n, double radius, const Vec3f& centre) {
  const float spacing = static_cast<float>(std::sqrt(4 * std::numbers::pi / static_cast<double>(n)) * radius);
  return bodyscan::testing::sphere_kernels(n, radius, centre, 1.4f * spacing, 0.5f * spacing,
                                           static_cast<float>(1 / radius));
}

ImplicitField build(const std::vector<Kernel>& ks, float voxel, int brick_size = 8) {
  ImplicitFieldOptions o;
  o.voxel_size = voxel;
  o.brick_size = brick_size;
  auto f = build_implicit_field(ks, o);
  EXPECT_TRUE(f.ok()) << f.status().message();
  return std::move(f).value();
}

TriangleMesh extract(const ImplicitField& f, const MarchingCubesOptions& o = {}) {
  auto m = extract_isosurface(f, o);
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? std::move(m).value() : TriangleMesh{};
}

void expect_closed_sphere_topology(const MeshTopology& t) {
  EXPECT_EQ(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.degenerate_triangles, 0u);
  EXPECT_EQ(t.unreferenced_vertices, 0u);
}

TEST(ExtractIsosurface, SphereIsClosedAndOutward) {
  // 3000 points on the unit sphere (spacing 0.065), voxel 0.02.
  const ImplicitField f = build(sphere_kernels(3000, 1.0, Vec3f::Zero()), 0.02f);
  const TriangleMesh m = extract(f);
  ASSERT_FALSE(m.empty());
  ASSERT_TRUE(m.is_consistent());
  const MeshTopology t = analyze_topology(m);
  expect_closed_sphere_topology(t);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 2);
  // Outward winding: positive volume, the ball's within 2%.
  const double ball = 4.0 / 3.0 * std::numbers::pi;
  EXPECT_NEAR(signed_volume(m), ball, 0.02 * ball);
  // Vertices on the sphere: the bent kernels' zero set is within a few thousandths,
  // and linear interpolation across a voxel adds at most h^2 / 8R = 5e-5.
  double worst = 0;
  for (const Vec3f& v : m.vertices) worst = std::max(worst, std::abs(v.cast<double>().norm() - 1.0));
  EXPECT_LT(worst, 0.01);
  // Every triangle faces away from the centre.
  size_t inward = 0;
  for (const Triangle& tri : m.triangles) {
    const Vec3f a = m.vertices[tri[0]], b = m.vertices[tri[1]], c = m.vertices[tri[2]];
    inward += (b - a).cross(c - a).dot(a + b + c) < 0.f;
  }
  EXPECT_EQ(inward, 0u);
}

// Triangles as position triples, rotated so the smallest position comes first
// (winding kept), then sorted: a mesh's geometry independent of vertex numbering.
using PosTri = std::array<std::array<float, 3>, 3>;
std::vector<PosTri> canonical_triangles(const TriangleMesh& m) {
  std::vector<PosTri> out;
  for (const Triangle& t : m.triangles) {
    PosTri p;
    for (int k = 0; k < 3; ++k) {
      const Vec3f& v = m.vertices[t[k]];
      p[k] = {v.x(), v.y(), v.z()};
    }
    const int first = static_cast<int>(std::min_element(p.begin(), p.end()) - p.begin());
    std::rotate(p.begin(), p.begin() + first, p.end());
    out.push_back(p);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::array<float, 3>> sorted_positions(const TriangleMesh& m) {
  std::vector<std::array<float, 3>> out;
  for (const Vec3f& v : m.vertices) out.push_back({v.x(), v.y(), v.z()});
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ExtractIsosurface, BrickSeamsLeaveNoTrace) {
  // The same kernels cut into bricks of 4, 8 and 256 nodes (one brick for the whole
  // grid): the field is bit-identical by design, and each grid edge's vertex is made
  // once, so the meshes must be identical and no two vertices share a position.
  const std::vector<Kernel> ks = sphere_kernels(1200, 1.0, Vec3f(0.013f, -0.021f, 0.007f));
  const float voxel = 0.03f;
  const TriangleMesh reference = extract(build(ks, voxel, 256));
  ASSERT_FALSE(reference.empty());
  const auto ref_pos = sorted_positions(reference);
  const auto ref_tris = canonical_triangles(reference);
  EXPECT_EQ(std::adjacent_find(ref_pos.begin(), ref_pos.end()), ref_pos.end()) << "duplicate vertex";
  for (int bs : {4, 8}) {
    const ImplicitField f = build(ks, voxel, bs);
    EXPECT_GT(f.num_bricks(), 8u) << "brick " << bs << " should cut the surface into many bricks";
    const TriangleMesh m = extract(f);
    EXPECT_EQ(m.num_vertices(), reference.num_vertices()) << "brick " << bs;
    EXPECT_EQ(m.num_triangles(), reference.num_triangles()) << "brick " << bs;
    const auto pos = sorted_positions(m);
    EXPECT_EQ(std::adjacent_find(pos.begin(), pos.end()), pos.end()) << "duplicate vertex, brick " << bs;
    EXPECT_TRUE(pos == ref_pos) << "vertex positions differ, brick " << bs;
    EXPECT_TRUE(canonical_triangles(m) == ref_tris) << "triangles differ, brick " << bs;
    const MeshTopology t = analyze_topology(m);
    expect_closed_sphere_topology(t);
    EXPECT_EQ(t.components, 1u);
  }
}

TEST(ExtractIsosurface, TwoSpheresAreTwoClosedComponents) {
  std::vector<Kernel> ks = sphere_kernels(1500, 1.0, Vec3f(-1.5f, 0.f, 0.f));
  const std::vector<Kernel> b = sphere_kernels(1500, 0.7, Vec3f(1.5f, 0.3f, 0.f));
  ks.insert(ks.end(), b.begin(), b.end());
  const TriangleMesh m = extract(build(ks, 0.025f));
  const MeshTopology t = analyze_topology(m);
  expect_closed_sphere_topology(t);
  EXPECT_EQ(t.components, 2u);
  EXPECT_EQ(t.euler_characteristic, 4);  // two spheres
  const MeshComponents c = label_components(m);
  ASSERT_EQ(c.triangle_count.size(), 2u);
  // Each component closed and outward on its own: its signed volume is its ball's.
  for (uint32_t comp = 0; comp < 2; ++comp) {
    TriangleMesh part;
    part.vertices = m.vertices;
    for (size_t i = 0; i < m.triangles.size(); ++i)
      if (c.triangle_label[i] == comp) part.triangles.push_back(m.triangles[i]);
    remove_unreferenced_vertices(part);
    const MeshTopology pt = analyze_topology(part);
    EXPECT_TRUE(pt.closed()) << "component " << comp;
    EXPECT_EQ(pt.euler_characteristic, 2) << "component " << comp;
    const double r = comp == 0 ? 1.0 : 0.7;  // the larger first
    const double ball = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    EXPECT_NEAR(signed_volume(part), ball, 0.03 * ball) << "component " << comp;
  }
}

TEST(ExtractIsosurface, OpenPatchHasABoundaryOnThePlane) {
  // Flat kernels on a 2 x 2 square of the plane z = 0.01: an open sheet, cut where the
  // kernels' support ends; every vertex on the plane.
  std::vector<Kernel> ks;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      Kernel k;
      k.center = Vec3f(0.05f * i, 0.05f * j, 0.01f);
      k.t1 = Vec3f::UnitX();
      k.t2 = Vec3f::UnitY();
      k.n = Vec3f::UnitZ();
      k.sigma_t1 = k.sigma_t2 = 0.07f;
      k.sigma_n = 0.025f;
      ks.push_back(k);
    }
  }
  const TriangleMesh m = extract(build(ks, 0.02f));
  ASSERT_FALSE(m.empty());
  const MeshTopology t = analyze_topology(m);
  EXPECT_GT(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 1);  // a disc
  for (const Vec3f& v : m.vertices) ASSERT_NEAR(v.z(), 0.01f, 1e-4f);
  for (const Triangle& tri : m.triangles) {  // facing +z, the kernels' outside
    const Vec3f a = m.vertices[tri[0]], b = m.vertices[tri[1]], c = m.vertices[tri[2]];
    EXPECT_GT((b - a).cross(c - a).z(), 0.f);
  }
}

TEST(ExtractIsosurface, MinWeightAndEmptyFields) {
  const ImplicitField f = build(sphere_kernels(500, 1.0, Vec3f::Zero()), 0.05f);
  // No node is that sure: nothing is defined, nothing is meshed.
  MarchingCubesOptions o;
  o.min_weight = 1e6f;
  EXPECT_TRUE(extract(f, o).empty());
  EXPECT_TRUE(extract(ImplicitField{}).empty());
}

TEST(ExtractIsosurface, ProgressAndCancel) {
  const ImplicitField f = build(sphere_kernels(500, 1.0, Vec3f::Zero()), 0.04f);
  std::vector<double> fractions;
  MarchingCubesOptions o;
  o.progress = [&](std::string_view stage, double fr) {
    EXPECT_EQ(stage, "mesh");
    fractions.push_back(fr);
    return true;
  };
  EXPECT_FALSE(extract(f, o).empty());
  ASSERT_FALSE(fractions.empty());
  for (double fr : fractions) {
    EXPECT_GT(fr, 0.0);
    EXPECT_LE(fr, 1.0);
  }
  EXPECT_NEAR(*std::max_element(fractions.begin(), fractions.end()), 1.0, 1e-12);
  o.progress = [](std::string_view, double) { return false; };
  auto m = extract_isosurface(f, o);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace bodyscan
