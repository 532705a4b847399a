#include "recon/geometry/fill_holes.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>

#include "recon/geometry/mesh_components.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

using testing::box_mesh;
using testing::icosphere;

// Removes every triangle whose three vertices satisfy `cut`.
template <typename Pred>
TriangleMesh without(TriangleMesh m, Pred cut) {
  std::erase_if(m.triangles, [&](const Triangle& t) {
    return cut(m.vertices[t[0]]) && cut(m.vertices[t[1]]) && cut(m.vertices[t[2]]);
  });
  remove_unreferenced_vertices(m);
  return m;
}

// A flat n x n grid of unit squares in z = 0, wound to face +z.
TriangleMesh grid(int n) {
  TriangleMesh m;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) m.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.f);
  auto id = [&](int x, int y) { return static_cast<uint32_t>(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      m.triangles.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
      m.triangles.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
    }
  return m;
}

void expect_closed(const TriangleMesh& m, const char* what) {
  const MeshTopology t = analyze_topology(m);
  EXPECT_EQ(t.boundary_edges, 0u) << what;
  EXPECT_EQ(t.non_manifold_edges, 0u) << what;
  EXPECT_EQ(t.inconsistent_edges, 0u) << what;
  EXPECT_EQ(t.degenerate_triangles, 0u) << what;
}

TEST(FillHoles, CubeMissingAFaceClosesWithTheRightWinding) {
  TriangleMesh m = box_mesh(Vec3f::Zero(), Vec3f::Constant(2.f));
  m.triangles.erase(m.triangles.begin() + 2, m.triangles.begin() + 4);  // the z = 2 face
  const HoleFillStats s = fill_holes(m);
  EXPECT_EQ(s.holes, 1u);
  EXPECT_EQ(s.holes_filled, 1u);
  EXPECT_EQ(s.largest_hole_edges, 4u);
  expect_closed(m, "cube");
  // A square loop in a plane: the patch is that plane, so the volume is exact.
  EXPECT_NEAR(signed_volume(m), 8.0, 1e-5);
  EXPECT_NEAR(s.area_added, 4.0, 1e-5);
  for (size_t v = 8; v < m.vertices.size(); ++v) EXPECT_NEAR(m.vertices[v].z(), 2.f, 1e-5f);
}

TEST(FillHoles, PlanarHoleIsFilledFlatAtTheMeshDensity) {
  // A 6 x 6 hole in a 20 x 20 grid; the outer rim (80 edges) is left open by the
  // size limit, which shows the limit works.
  TriangleMesh m =
      without(grid(20), [](const Vec3f& p) { return p.x() >= 7 && p.x() <= 13 && p.y() >= 7 && p.y() <= 13; });
  const size_t before = m.triangles.size();
  HoleFillOptions o;
  o.max_hole_edges = 40;
  const HoleFillStats s = fill_holes(m, o);
  EXPECT_EQ(s.holes, 2u);
  EXPECT_EQ(s.holes_filled, 1u);
  EXPECT_EQ(s.largest_hole_edges, 80u);
  EXPECT_EQ(analyze_topology(m).boundary_edges, 80u);  // only the rim
  EXPECT_NEAR(s.area_added, 36.0, 1e-3);
  // Refined to about the surrounding density: 72 triangles fill the same area in
  // the grid; the loop-only triangulation would have 22.
  EXPECT_GT(s.triangles_added, 40u);
  EXPECT_LT(s.triangles_added, 150u);
  EXPECT_EQ(m.triangles.size(), before + s.triangles_added);
  for (const Vec3f& p : m.vertices) EXPECT_NEAR(p.z(), 0.f, 1e-4f);
  // New vertices lie inside the hole and carry confidence 0; the rest keep 1.
  ASSERT_EQ(m.confidence.size(), m.vertices.size());
  EXPECT_EQ(s.vertices_added, static_cast<size_t>(std::count(m.confidence.begin(), m.confidence.end(), 0.f)));
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    if (m.confidence[v] == 0.f) {
      EXPECT_GT(m.vertices[v].x(), 7.f);
      EXPECT_LT(m.vertices[v].x(), 13.f);
    }
  }
}

TEST(FillHoles, CurvedHoleFollowsTheSphere) {
  // A cap of about 45 degrees half-angle cut from a unit sphere leaves a planar loop
  // 0.27 below the pole. Unfaired and membrane patches span it flat (the membrane of
  // a planar loop is the plane); the thin plate continues the sphere's curvature
  // nearly to the pole.
  const TriangleMesh sphere = icosphere(5, 1.0);
  const auto in_cap = [](const Vec3f& p) { return p.z() > std::cos(0.25 * M_PI); };
  double lowest_top[3] = {0, 0, 0};
  const HoleFairing fairings[3] = {HoleFairing::kNone, HoleFairing::kMembrane, HoleFairing::kThinPlate};
  for (int f = 0; f < 3; ++f) {
    TriangleMesh m = without(sphere, in_cap);
    HoleFillOptions o;
    o.fairing = fairings[f];
    const HoleFillStats s = fill_holes(m, o);
    EXPECT_EQ(s.holes_filled, 1u);
    expect_closed(m, "sphere");
    float top = -1.f;
    for (const Vec3f& p : m.vertices) top = std::max(top, p.z());
    lowest_top[f] = top;
    if (fairings[f] == HoleFairing::kThinPlate) {
      for (size_t v = 0; v < m.vertices.size(); ++v) {
        if (m.confidence[v] == 0.f) {
          EXPECT_NEAR(m.vertices[v].norm(), 1.0f, 0.08f);
        }
      }
    }
  }
  EXPECT_NEAR(lowest_top[0], 0.734, 0.01);  // the loop's plane
  EXPECT_NEAR(lowest_top[1], lowest_top[0], 1e-4);
  EXPECT_GT(lowest_top[2], 0.92);
}

TEST(FillHoles, AMeshWithNormalsGetsThemForThePatchesVerticesToo) {
  // A reconstructed surface carries its normals; the refined patch adds vertices,
  // and every vertex, old or new, must have its normal from the filled faces after:
  // outward, and nowhere steeper than the flat patch's rim (the cap is 45 degrees).
  TriangleMesh m = without(icosphere(5, 1.0), [](const Vec3f& p) { return p.z() > std::cos(0.25 * M_PI); });
  m.normals = compute_vertex_normals(m);
  const size_t before = m.vertices.size();
  const HoleFillStats s = fill_holes(m, HoleFillOptions{});
  ASSERT_EQ(s.holes_filled, 1u);
  ASSERT_GT(m.vertices.size(), before);
  ASSERT_EQ(m.normals.size(), m.vertices.size());
  TriangleMesh bare = m;
  bare.normals.clear();
  const std::vector<Vec3f> expected = compute_vertex_normals(bare);
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    EXPECT_LT((m.normals[v] - expected[v]).norm(), 1e-6f) << "vertex " << v;
    EXPECT_GT(m.normals[v].dot(m.vertices[v].normalized()), 0.6f) << "vertex " << v;
  }
}

TEST(FillHoles, LongLoopsAreSplitAndStillClose) {
  // A hole of about 300 boundary edges, filled with the dynamic programme limited to
  // 40 edges: the loop is cut by diagonals first.
  const TriangleMesh sphere = icosphere(6, 1.0);
  TriangleMesh m = without(sphere, [](const Vec3f& p) { return p.y() > 0.5f; });
  HoleFillOptions o;
  o.max_dp_edges = 40;
  const HoleFillStats s = fill_holes(m, o);
  EXPECT_GT(s.largest_hole_edges, 200u);
  expect_closed(m, "split loop");
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    if (m.confidence[v] == 0.f) {
      EXPECT_GT(m.vertices[v].y(), 0.45f);
    }
  }
}

TEST(FillHoles, ALoopOfSeveralHundredEdgesIsTakenWholeAlikeEveryTime) {
  // A cap cut from a fine sphere leaves a loop of about 600 edges, under a limit
  // of 1000: the programme takes it whole, solving each length's cells in
  // parallel. The thin plate continues the sphere (as far as the umbrella
  // operator's does: 0.1 at most here), and a second fill of the same mesh is the
  // same to the bit.
  const TriangleMesh sphere = icosphere(7, 1.0);
  const auto in_cap = [](const Vec3f& p) { return p.y() > 0.6f; };
  TriangleMesh first;
  for (int run = 0; run < 2; ++run) {
    TriangleMesh m = without(sphere, in_cap);
    HoleFillOptions o;
    o.fairing = HoleFairing::kThinPlate;
    o.max_dp_edges = 1000;
    const HoleFillStats s = fill_holes(m, o);
    ASSERT_EQ(s.holes_filled, 1u);
    EXPECT_GT(s.largest_hole_edges, 500u);
    EXPECT_LT(s.largest_hole_edges, o.max_dp_edges);
    expect_closed(m, "fine sphere");
    float worst = 0.f;
    for (size_t v = 0; v < m.vertices.size(); ++v)
      if (m.confidence[v] == 0.f) worst = std::max(worst, std::abs(m.vertices[v].norm() - 1.f));
    EXPECT_LT(worst, 0.12f);  // the flat span the loop bounds is 0.4 below the pole
    if (run == 0) {
      first = std::move(m);
    } else {
      EXPECT_TRUE(m.triangles == first.triangles);
      EXPECT_TRUE(m.vertices == first.vertices);
    }
  }
}

TEST(FillHoles, HolesMeetingAtAVertexAndSeveralHolesAllClose) {
  // Two triangles of a cube removed at opposite faces, and on an icosphere two
  // fans that share only their centre's neighbour: loops through one vertex twice
  // are split into simple loops.
  TriangleMesh m = icosphere(3, 1.0);
  const size_t nt = m.triangles.size();
  // Remove two triangles that touch at exactly one vertex.
  const Triangle first = m.triangles[0];
  size_t second = nt;
  for (size_t i = 1; i < nt && second == nt; ++i) {
    int shared = 0;
    for (uint32_t a : m.triangles[i])
      for (uint32_t b : first) shared += a == b;
    if (shared == 1) second = i;
  }
  ASSERT_LT(second, nt);
  m.triangles.erase(m.triangles.begin() + static_cast<long>(second));
  m.triangles.erase(m.triangles.begin());
  // And a third, far away.
  m.triangles.erase(m.triangles.begin() + static_cast<long>(nt / 2));
  const HoleFillStats s = fill_holes(m);
  EXPECT_EQ(s.holes_filled, 3u);
  expect_closed(m, "touching holes");
  EXPECT_EQ(analyze_topology(m).euler_characteristic, 2);
}

TEST(FillHoles, HolesFilledSideBySideGiveTheMeshOfFillingThemOneByOne) {
  // Caps cut from a sphere, two of them touching at a vertex: the patches are made
  // side by side and appended in loop order, so the mesh is the same, vertex for
  // vertex, with one thread as with all of them.
  TriangleMesh m = icosphere(4, 1.0);
  const std::vector<Vec3f> centres = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0.6f, 0.6f, -0.53f}};
  m = without(m, [&](const Vec3f& v) {
    for (const Vec3f& c : centres)
      if ((v - c.normalized()).norm() < 0.3f) return true;
    return false;
  });
  const size_t nt = m.triangles.size();
  // And two triangles touching at one vertex, away from the caps.
  size_t f = 0;
  for (bool clear = false; !clear; ++f) {
    clear = true;
    for (const Vec3f& c : centres) clear = clear && (m.vertices[m.triangles[f][0]] - c.normalized()).norm() > 0.7f;
  }
  --f;
  const Triangle first = m.triangles[f];
  for (size_t i = 0; i < nt; ++i) {
    int shared = 0;
    for (uint32_t a : m.triangles[i])
      for (uint32_t b : first) shared += a == b;
    if (shared != 1) continue;
    m.triangles.erase(m.triangles.begin() + static_cast<long>(std::max(i, f)));
    m.triangles.erase(m.triangles.begin() + static_cast<long>(std::min(i, f)));
    break;
  }
  ASSERT_EQ(m.triangles.size(), nt - 2);
  TriangleMesh one = m, all = m;
  HoleFillStats s_one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    s_one = fill_holes(one);
  }
  const HoleFillStats s_all = fill_holes(all);
  EXPECT_EQ(s_all.holes_filled, centres.size() + 2);
  EXPECT_EQ(s_one.holes_filled, s_all.holes_filled);
  EXPECT_GT(s_all.vertices_added, 20u);
  expect_closed(all, "caps and touching holes");
  EXPECT_EQ(one.vertices, all.vertices);
  EXPECT_EQ(one.triangles, all.triangles);
  EXPECT_EQ(one.confidence, all.confidence);
}

TEST(FillHoles, OpeningsLargerThanTheAreaLimitStayOpen) {
  // A 4 x 4 grid missing a 1 x 1 square: its rim would take a fill of area 16, the
  // square one of area 1; with a limit of 2 only the square is filled.
  TriangleMesh m =
      without(grid(4), [](const Vec3f& p) { return p.x() >= 1 && p.x() <= 2 && p.y() >= 1 && p.y() <= 2; });
  const size_t grid_vertices = m.vertices.size();
  HoleFillOptions o;
  o.max_hole_area = 2.0;
  const HoleFillStats s = fill_holes(m, o);
  EXPECT_EQ(s.holes, 2u);  // the square and the grid's rim (area 16)
  EXPECT_EQ(s.holes_filled, 1u);
  EXPECT_NEAR(s.area_added, 1.0, 1e-4);
  EXPECT_EQ(analyze_topology(m).boundary_edges, 16u);
  // No vertex of the discarded rim patch is left behind.
  EXPECT_EQ(m.vertices.size(), grid_vertices + s.vertices_added);
}

TEST(FillHoles, ClosedMeshIsUntouched) {
  TriangleMesh m = icosphere(2, 1.0);
  const TriangleMesh before = m;
  const HoleFillStats s = fill_holes(m);
  EXPECT_EQ(s.holes, 0u);
  EXPECT_EQ(m.triangles, before.triangles);
  EXPECT_EQ(m.vertices.size(), before.vertices.size());
}

TEST(TrimBoundaryFlaps, PeelsOnlyUnsupportedTrianglesReachableFromTheBoundary) {
  // A grid whose right part is "unsupported": the peel removes it from the open rim
  // inward and stops at the supported part.
  TriangleMesh m = grid(10);
  const size_t n = m.triangles.size();
  const size_t removed = trim_boundary_flaps(m, [&](uint32_t v) { return m.vertices[v].x() >= 6.f; });
  EXPECT_EQ(removed, 80u);  // the columns x in [6, 10]: 4 x 10 squares of 2 triangles
  EXPECT_EQ(m.triangles.size(), n - removed);
  for (const Vec3f& p : m.vertices) EXPECT_LE(p.x(), 6.f);

  // A closed mesh has no boundary to peel from, even if nothing is supported.
  TriangleMesh closed = icosphere(2, 1.0);
  EXPECT_EQ(trim_boundary_flaps(closed, [](uint32_t) { return true; }), 0u);

  // An unsupported island inside a supported region is not reachable either.
  TriangleMesh g = grid(10);
  EXPECT_EQ(trim_boundary_flaps(g,
                                [&](uint32_t v) {
                                  const Vec3f& p = g.vertices[v];
                                  return p.x() >= 4 && p.x() <= 6 && p.y() >= 4 && p.y() <= 6;
                                }),
            0u);
}

}  // namespace
}  // namespace bodyscan
