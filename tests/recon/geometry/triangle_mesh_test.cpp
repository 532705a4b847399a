// Mesh topology, normals, volume and area against shapes whose answers are known.
#include "recon/geometry/triangle_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "recon/io/ply.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

using testing::unit_cube;

TEST(TriangleMeshTest, ClosedCube) {
  const TriangleMesh cube = unit_cube();
  ASSERT_TRUE(cube.is_consistent());
  const MeshTopology t = analyze_topology(cube);
  EXPECT_TRUE(t.closed());
  EXPECT_EQ(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.degenerate_triangles, 0u);
  EXPECT_EQ(t.unreferenced_vertices, 0u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 2);
}

TEST(TriangleMeshTest, CubeVolumeAndArea) {
  TriangleMesh cube = unit_cube();
  EXPECT_NEAR(signed_volume(cube), 1.0, 1e-12);
  EXPECT_NEAR(surface_area(cube), 6.0, 1e-12);
  // Far from the origin and scaled to mm: the reference point keeps it exact.
  for (Vec3f& v : cube.vertices) v = v * 100.0f + Vec3f(5000.0f, 2000.0f, -3000.0f);
  EXPECT_NEAR(signed_volume(cube), 1e6, 1e-6);
  EXPECT_NEAR(surface_area(cube), 6e4, 1e-6);
  // Turned inside out, the volume changes sign.
  for (Triangle& t : cube.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(signed_volume(cube), -1e6, 1e-6);
}

TEST(TriangleMeshTest, OpenSquare) {
  TriangleMesh square;
  square.vertices = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 1, 0), Vec3f(0, 1, 0)};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  const MeshTopology t = analyze_topology(square);
  EXPECT_FALSE(t.closed());
  EXPECT_EQ(t.boundary_edges, 4u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 1);  // a disc
  EXPECT_NEAR(surface_area(square), 1.0, 1e-12);
}

TEST(TriangleMeshTest, FlippedTriangleMakesInconsistentEdges) {
  TriangleMesh cube = unit_cube();
  std::swap(cube.triangles[5][1], cube.triangles[5][2]);
  const MeshTopology t = analyze_topology(cube);
  EXPECT_TRUE(t.closed());  // still watertight, just wound wrongly
  EXPECT_EQ(t.inconsistent_edges, 3u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 2);
}

TEST(TriangleMeshTest, DegenerateUnreferencedComponentsAndNonManifold) {
  TriangleMesh mesh = unit_cube();
  // A separate triangle, an unused vertex, a degenerate triangle on the cube.
  mesh.vertices.emplace_back(5, 5, 5);
  mesh.vertices.emplace_back(6, 5, 5);
  mesh.vertices.emplace_back(5, 6, 5);
  mesh.vertices.emplace_back(9, 9, 9);
  mesh.triangles.push_back({8, 9, 10});
  mesh.triangles.push_back({0, 0, 1});
  MeshTopology t = analyze_topology(mesh);
  EXPECT_EQ(t.components, 2u);
  EXPECT_EQ(t.unreferenced_vertices, 1u);
  EXPECT_EQ(t.degenerate_triangles, 1u);
  EXPECT_EQ(t.boundary_edges, 3u);
  EXPECT_EQ(t.euler_characteristic, 2 + 1);  // sphere plus disc

  // A fin on a cube edge: that edge is now used by three triangles.
  TriangleMesh fin = unit_cube();
  fin.vertices.emplace_back(0.5f, -1.0f, -1.0f);
  fin.triangles.push_back({0, 1, 8});
  t = analyze_topology(fin);
  EXPECT_EQ(t.non_manifold_edges, 1u);
  EXPECT_EQ(t.boundary_edges, 2u);
  EXPECT_FALSE(t.closed());
  EXPECT_EQ(t.components, 1u);
}

TEST(TriangleMeshTest, EmptyMesh) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3f(1, 2, 3)};
  const MeshTopology t = analyze_topology(mesh);
  EXPECT_EQ(t.components, 0u);
  EXPECT_EQ(t.unreferenced_vertices, 1u);
  EXPECT_EQ(t.euler_characteristic, 0);
  EXPECT_EQ(signed_volume(mesh), 0.0);
  EXPECT_EQ(surface_area(mesh), 0.0);
}

TEST(TriangleMeshTest, ConsistencyChecks) {
  TriangleMesh mesh = unit_cube();
  EXPECT_TRUE(mesh.is_consistent());
  mesh.normals.resize(7);
  EXPECT_FALSE(mesh.is_consistent());
  mesh.normals.resize(8);
  EXPECT_TRUE(mesh.is_consistent());
  mesh.triangles.push_back({0, 1, 8});
  EXPECT_FALSE(mesh.is_consistent());
}

TEST(TriangleMeshTest, PointCloudConsistency) {
  PointCloud cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  EXPECT_TRUE(cloud.is_consistent());
  cloud.laser = {1};
  EXPECT_FALSE(cloud.is_consistent());
  cloud.laser = {1, 2};
  cloud.camera = {0, kUnknownSource};
  EXPECT_TRUE(cloud.is_consistent());  // ids without centres: nothing to index yet
  cloud.camera_centres = {Vec3f(0, 0, 0)};
  EXPECT_TRUE(cloud.is_consistent());
  cloud.camera = {1, 0};
  EXPECT_FALSE(cloud.is_consistent());
  cloud.camera = {-2, 0};
  EXPECT_FALSE(cloud.is_consistent());
}

TEST(TriangleMeshTest, CubeNormalsPointOutward) {
  const TriangleMesh cube = unit_cube();
  const std::vector<Vec3f> normals = compute_vertex_normals(cube);
  ASSERT_EQ(normals.size(), 8u);
  const Vec3f centre(0.5f, 0.5f, 0.5f);
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_NEAR(normals[i].norm(), 1.0f, 1e-6f);
    // Each corner's normal stays in its octant (weights differ with the diagonals).
    const Vec3f out = cube.vertices[i] - centre;
    for (int k = 0; k < 3; ++k) EXPECT_GT(normals[i][k] * out[k], 0.0f) << i;
  }
}

TEST(TriangleMeshTest, MaleBody) {
  auto mesh = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply");
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  const MeshTopology t = analyze_topology(*mesh);
  EXPECT_TRUE(t.closed());
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.degenerate_triangles, 0u);
  EXPECT_EQ(t.unreferenced_vertices, 0u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 2);
  // The README's 62.82 L, wound outward.
  EXPECT_NEAR(signed_volume(*mesh), 62.82e6, 62.82e6 * 1e-3);
  const std::vector<Vec3f> normals = compute_vertex_normals(*mesh);
  for (const Vec3f& n : normals) ASSERT_NEAR(n.norm(), 1.0f, 1e-5f);
}

}  // namespace
}  // namespace bodyscan
