// Components joined by shared edges, and the small ones dropped.
#include "recon/geometry/mesh_components.hpp"

#include <gtest/gtest.h>

#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

// A closed box and a small closed tetrahedron that shares one of the box's
// corners (vertex 0) and nothing else.
TriangleMesh box_and_tetra_on_a_corner() {
  TriangleMesh m = testing::box_mesh(Vec3f::Zero(), Vec3f::Ones());
  const uint32_t corner = 0;
  const Vec3f c = m.vertices[corner];
  const uint32_t a = static_cast<uint32_t>(m.vertices.size());
  m.vertices.push_back(c + Vec3f(-0.1f, 0.f, 0.f));
  m.vertices.push_back(c + Vec3f(0.f, -0.1f, 0.f));
  m.vertices.push_back(c + Vec3f(0.f, 0.f, -0.1f));
  const uint32_t b = a + 1, d = a + 2;
  for (const Triangle& t : {Triangle{corner, b, a}, Triangle{corner, a, d}, Triangle{corner, d, b}, Triangle{a, b, d}})
    m.triangles.push_back(t);
  return m;
}

TEST(MeshComponents, APieceTouchingAtOneVertexIsItsOwnComponent) {
  TriangleMesh m = box_and_tetra_on_a_corner();
  const size_t box_triangles = m.triangles.size() - 4;
  const MeshComponents c = label_components(m);
  ASSERT_EQ(c.triangle_count.size(), 2u);
  EXPECT_EQ(c.triangle_count[0], box_triangles);
  EXPECT_EQ(c.triangle_count[1], 4u);
  EXPECT_EQ(analyze_topology(m).components, 2u);  // as the topology counts them

  const size_t box_vertices = m.vertices.size() - 3;
  EXPECT_EQ(remove_small_components(m, 0.5), 1u);
  EXPECT_EQ(m.triangles.size(), box_triangles);
  EXPECT_EQ(m.vertices.size(), box_vertices);  // the shared corner stays
  const MeshTopology t = analyze_topology(m);
  EXPECT_EQ(t.components, 1u);
  EXPECT_TRUE(t.closed());
}

TEST(MeshComponents, LargestFirstAndNothingRemovedAboveTheFraction) {
  TriangleMesh m = box_and_tetra_on_a_corner();
  const size_t before = m.triangles.size();
  EXPECT_EQ(remove_small_components(m, 0.1), 0u);  // 4 of 12 triangles: kept
  EXPECT_EQ(m.triangles.size(), before);
  TriangleMesh empty;
  EXPECT_TRUE(label_components(empty).triangle_count.empty());
  EXPECT_EQ(remove_small_components(empty, 0.5), 0u);
}

}  // namespace
}  // namespace bodyscan
