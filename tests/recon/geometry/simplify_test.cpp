#include "recon/geometry/simplify.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "recon/geometry/mesh_distance.hpp"
#include "recon/io/ply.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

TEST(Simplify, ABodyKeepsItsShapeClosedWithinTheBudget) {
  auto body = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
  ASSERT_TRUE(body.ok()) << body.status().message();
  ASSERT_TRUE(analyze_topology(*body).closed());
  for (size_t budget : {50000, 20000, 5000}) {
    SimplifyOptions o;
    o.max_triangles = budget;
    auto s = simplify(*body, o);
    ASSERT_TRUE(s.ok()) << s.status().message();
    const MeshTopology t = analyze_topology(s->mesh);
    EXPECT_LE(s->mesh.num_triangles(), budget);
    EXPECT_GT(s->mesh.num_triangles(), budget * 9 / 10) << "the budget is used";
    EXPECT_TRUE(t.closed()) << budget << ": " << t.boundary_edges << " open, " << t.non_manifold_edges
                            << " non-manifold edges";
    EXPECT_EQ(t.inconsistent_edges, 0u);
    EXPECT_EQ(s->mesh.normals.size(), s->mesh.num_vertices());
    EXPECT_TRUE(s->mesh.confidence.empty());
    // The volume and the distance to the original: a tape round the decimated body
    // reads within a few mm of the full one.
    EXPECT_NEAR(signed_volume(s->mesh) / signed_volume(*body), 1.0, budget >= 20000 ? 0.005 : 0.02) << budget;
    const MeshDistance to_body(*body);
    double worst = 0;
    for (const Vec3f& v : s->mesh.vertices) worst = std::max<double>(worst, to_body.closest_point(v).distance);
    EXPECT_LE(worst, s->max_deviation_mm + 1e-4) << "the deviation reported covers the decimated vertices";
    EXPECT_LT(s->max_deviation_mm, budget >= 20000 ? 3.0 : 8.0) << budget;
  }
}

TEST(Simplify, AScanWhoseThighsTouchStaysClosed) {
  // Collapses pinch the surface where two parts lie close (the thighs, the
  // fingers): edges shared by four triangles, which the repair opens and closes.
  auto scan = read_ply_mesh(BODYSCAN_SOURCE_DIR "/tests/data/male_muscular_thighs_touching.ply");
  ASSERT_TRUE(scan.ok()) << scan.status().message();
  for (size_t budget : {20000, 5000}) {
    SimplifyOptions o;
    o.max_triangles = budget;
    auto s = simplify(*scan, o);
    ASSERT_TRUE(s.ok()) << s.status().message();
    const MeshTopology t = analyze_topology(s->mesh);
    EXPECT_TRUE(t.closed()) << budget << ": " << t.non_manifold_edges << " non-manifold edges";
    EXPECT_EQ(t.inconsistent_edges, 0u);
    EXPECT_EQ(t.unreferenced_vertices, 0u);
    for (const Vec3f& n : s->mesh.normals) ASSERT_NEAR(n.norm(), 1.f, 1e-3f) << "a unit normal at every vertex";
    EXPECT_LE(s->mesh.num_triangles(), budget);
    EXPECT_NEAR(signed_volume(s->mesh) / signed_volume(*scan), 1.0, 0.02) << budget;
  }
}

TEST(Simplify, AMeshWithinTheBudgetComesBackAsItIs) {
  const TriangleMesh sphere = testing::icosphere(2, 100);
  SimplifyOptions o;
  o.max_triangles = sphere.num_triangles();
  auto s = simplify(sphere, o);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->mesh.vertices, sphere.vertices);
  EXPECT_EQ(s->mesh.triangles, sphere.triangles);
  EXPECT_EQ(s->max_deviation_mm, 0);
}

TEST(Simplify, VerticesAHairApartAreJoined) {
  // Marching cubes leaves such pairs where the surface passes through a grid node;
  // in metres they would print alike. Here one corner of a triangle is a copy of
  // its vertex 0.0002 mm away.
  const TriangleMesh sphere = testing::icosphere(2, 100);
  TriangleMesh split = sphere;
  const uint32_t v = split.triangles[0][0];
  split.vertices.push_back(split.vertices[v] + Vec3f(2e-4f, 0, 0));
  split.triangles[0][0] = static_cast<uint32_t>(split.vertices.size() - 1);
  ASSERT_FALSE(analyze_topology(split).closed());
  auto s = simplify(split, {});
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->mesh.num_vertices(), sphere.num_vertices());
  EXPECT_TRUE(analyze_topology(s->mesh).closed());
}

TEST(Simplify, AnErrorBoundStopsEarly) {
  const TriangleMesh sphere = testing::icosphere(5, 100);  // 20,480 triangles
  SimplifyOptions o;
  o.max_triangles = 100;
  o.max_error_mm = 0.05;
  auto s = simplify(sphere, o);
  ASSERT_TRUE(s.ok());
  EXPECT_GT(s->mesh.num_triangles(), 100u);
  EXPECT_LT(s->max_deviation_mm, 0.2);
  o.max_error_mm = 0;
  auto coarse = simplify(sphere, o);
  ASSERT_TRUE(coarse.ok());
  EXPECT_LE(coarse->mesh.num_triangles(), 100u);
  EXPECT_TRUE(analyze_topology(coarse->mesh).closed());
}

TEST(Simplify, BadArgumentsGetAClearError) {
  const TriangleMesh sphere = testing::icosphere(2, 100);
  SimplifyOptions o;
  o.max_triangles = 3;
  EXPECT_EQ(simplify(sphere, o).status().code(), StatusCode::kInvalidArgument);
  o.max_triangles = 100;
  o.max_error_mm = -1;
  EXPECT_EQ(simplify(sphere, o).status().code(), StatusCode::kInvalidArgument);
  TriangleMesh broken = sphere;
  broken.triangles[0][0] = 1000000;
  EXPECT_EQ(simplify(broken, {}).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace bodyscan
