#include "recon/geometry/sample_surface.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "recon/geometry/mesh_distance.hpp"
#include "recon/io/ply.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

const std::string kBodyPath = BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply";

TriangleMesh load_body() {
  StatusOr<TriangleMesh> mesh = read_ply_mesh(kBodyPath);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(mesh).value() : TriangleMesh{};
}

TriangleMesh box(float sx, float sy, float sz) { return testing::box_mesh(Vec3f::Zero(), Vec3f(sx, sy, sz)); }

double triangle_area(const TriangleMesh& m, size_t t) {
  const Vec3d a = m.vertices[m.triangles[t][0]].cast<double>();
  const Vec3d b = m.vertices[m.triangles[t][1]].cast<double>();
  const Vec3d c = m.vertices[m.triangles[t][2]].cast<double>();
  return 0.5 * (b - a).cross(c - a).norm();
}

// |observed - expected| for a binomial count, in standard deviations.
double binomial_z(size_t observed, size_t n, double p) {
  return (static_cast<double>(observed) - n * p) / std::sqrt(n * p * (1.0 - p));
}

std::vector<double> nearest_neighbour_distances(const std::vector<Vec3f>& p) {
  std::vector<double> nn(p.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < p.size(); ++i) {
    for (size_t j = 0; j < p.size(); ++j) {
      if (i != j) nn[i] = std::min(nn[i], static_cast<double>((p[i] - p[j]).norm()));
    }
  }
  return nn;
}

void expect_on_sphere_with_exact_normals(const PointCloud& cloud, double radius) {
  ASSERT_EQ(cloud.normals.size(), cloud.positions.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3d p = cloud.positions[i].cast<double>();
    const Vec3d n = cloud.normals[i].cast<double>();
    ASSERT_NEAR(p.norm(), radius, 1e-6 * radius);
    ASSERT_NEAR(n.norm(), 1.0, 1e-6);
    ASSERT_NEAR((n - p / radius).norm(), 0.0, 1e-6);
  }
}

TEST(FibonacciSphere, PointsOnSphereWithExactNormals) {
  const PointCloud cloud = fibonacci_sphere(1024, 250.0);
  ASSERT_EQ(cloud.size(), 1024u);
  EXPECT_TRUE(cloud.is_consistent());
  expect_on_sphere_with_exact_normals(cloud, 250.0);
  EXPECT_TRUE(fibonacci_sphere(0, 1.0).empty());
  EXPECT_EQ(fibonacci_sphere(1, 1.0).size(), 1u);
}

TEST(FibonacciSphere, NearestNeighbourSpacingIsNearlyUniform) {
  const PointCloud cloud = fibonacci_sphere(1024, 1.0);
  const std::vector<double> nn = nearest_neighbour_distances(cloud.positions);
  const auto [lo, hi] = std::minmax_element(nn.begin(), nn.end());
  EXPECT_LT(*hi / *lo, 1.5);
  // n points share the area 4π: spacing about sqrt(4π/n).
  const double expected = std::sqrt(4.0 * std::numbers::pi / 1024.0);
  EXPECT_GT(*lo, 0.8 * expected);
  EXPECT_LT(*hi, 1.1 * expected);
  // Equal areas: each hemisphere of every axis holds half the points.
  for (int axis = 0; axis < 3; ++axis) {
    const auto upper =
        std::count_if(cloud.positions.begin(), cloud.positions.end(), [&](const Vec3f& p) { return p[axis] > 0; });
    EXPECT_NEAR(static_cast<double>(upper), 512.0, 12.0) << "axis " << axis;
  }
}

TEST(SampleMeshUniform, BodySamplesLieOnTheMeshWithTheirTriangleNormals) {
  const TriangleMesh body = load_body();
  ASSERT_FALSE(body.empty());
  const PointCloud cloud = sample_mesh_uniform(body, 100000, 42, true);
  ASSERT_EQ(cloud.size(), 100000u);
  ASSERT_EQ(cloud.normals.size(), 100000u);
  const MeshDistance md(body);
  size_t normal_mismatches = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const ClosestPoint cp = md.closest_point(cloud.positions[i]);
    ASSERT_LT(cp.distance, 1e-3f) << i;
    ASSERT_NEAR(cloud.normals[i].norm(), 1.0f, 1e-5f);
    // The nearest triangle may be a neighbour when the sample sits on a shared edge.
    const Triangle& t = body.triangles[cp.triangle];
    const Vec3f n =
        (body.vertices[t[1]] - body.vertices[t[0]]).cross(body.vertices[t[2]] - body.vertices[t[0]]).normalized();
    normal_mismatches += n.dot(cloud.normals[i]) < 0.999f;
  }
  EXPECT_LT(normal_mismatches, 100u);
}

TEST(SampleMeshUniform, DeterministicForASeed) {
  const TriangleMesh body = load_body();
  ASSERT_FALSE(body.empty());
  const PointCloud a = sample_mesh_uniform(body, 5000, 7, true);
  const PointCloud b = sample_mesh_uniform(body, 5000, 7, true);
  const PointCloud c = sample_mesh_uniform(body, 5000, 8, true);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_NE(a.positions, c.positions);
  const PointCloud no_normals = sample_mesh_uniform(body, 5000, 7, false);
  EXPECT_TRUE(no_normals.normals.empty());
  EXPECT_EQ(no_normals.positions, a.positions);  // normals draw no random numbers
}

TEST(SampleMeshUniform, FacesOfABoxGetSamplesInProportionToArea) {
  // A 1 × 2 × 4 box: the faces normal to z, y and x have areas 2, 4 and 8 (total 28).
  const TriangleMesh m = box(1, 2, 4);
  const size_t n = 200000;
  const PointCloud cloud = sample_mesh_uniform(m, n, 3, true);
  ASSERT_EQ(cloud.size(), n);
  const double total = 28.0;
  const float size[3] = {1, 2, 4};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const float plane = side * size[axis];
      Vec3f outward = Vec3f::Zero();
      outward[axis] = side ? 1.0f : -1.0f;
      size_t count = 0;
      for (size_t i = 0; i < n; ++i) {
        if (cloud.positions[i][axis] == plane && cloud.normals[i].isApprox(outward, 1e-6f)) {
          ++count;
        }
      }
      const double area = size[(axis + 1) % 3] * size[(axis + 2) % 3];
      EXPECT_LT(std::abs(binomial_z(count, n, area / total)), 4.0)
          << "axis " << axis << " side " << side << " count " << count;
    }
  }
  // No point is anywhere but on the surface.
  for (const Vec3f& p : cloud.positions) {
    int on_faces = 0;
    for (int axis = 0; axis < 3; ++axis) on_faces += p[axis] == 0 || p[axis] == size[axis];
    ASSERT_GE(on_faces, 1);
  }
}

TEST(SampleMeshUniform, UniformInsideATriangle) {
  // The triangle's midpoints cut it into four triangles of equal area: each corner's
  // quarter (barycentric weight of that corner > 1/2) and the middle one get 1/4.
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {3, 7, 0}};
  m.triangles = {{0, 1, 2}};
  const size_t n = 100000;
  const PointCloud cloud = sample_mesh_uniform(m, n, 5, false);
  size_t corner[3] = {0, 0, 0};
  size_t middle = 0;
  for (const Vec3f& p : cloud.positions) {
    // Barycentric coordinates in the plane z = 0.
    const Eigen::Matrix2d basis{{10, 3}, {0, 7}};
    const Eigen::Vector2d uv = basis.inverse() * Eigen::Vector2d(p.x(), p.y());
    const double w[3] = {1.0 - uv.x() - uv.y(), uv.x(), uv.y()};
    ASSERT_GE(std::min({w[0], w[1], w[2]}), -1e-6);
    bool in_corner = false;
    for (int k = 0; k < 3; ++k) {
      if (w[k] > 0.5) {
        ++corner[k];
        in_corner = true;
      }
    }
    middle += !in_corner;
  }
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(binomial_z(corner[k], n, 0.25)), 4.0) << k;
  EXPECT_LT(std::abs(binomial_z(middle, n, 0.25)), 4.0);
}

TEST(SampleMeshUniform, BodyRegionGetsSamplesInProportionToArea) {
  const TriangleMesh body = load_body();
  ASSERT_FALSE(body.empty());
  // Triangles whose centroid is above 1.4 m: head, neck and shoulders.
  std::vector<uint8_t> in_region(body.triangles.size());
  double region_area = 0, total_area = 0;
  for (size_t t = 0; t < body.triangles.size(); ++t) {
    const Triangle& tri = body.triangles[t];
    const float y = (body.vertices[tri[0]].y() + body.vertices[tri[1]].y() + body.vertices[tri[2]].y()) / 3.0f;
    in_region[t] = y > 1400.0f;
    total_area += triangle_area(body, t);
    if (in_region[t]) region_area += triangle_area(body, t);
  }
  const double p = region_area / total_area;
  ASSERT_GT(p, 0.05);
  ASSERT_LT(p, 0.5);
  const size_t n = 200000;
  const PointCloud cloud = sample_mesh_uniform(body, n, 11, false);
  const MeshDistance md(body);
  size_t count = 0;
  for (const Vec3f& q : cloud.positions) count += in_region[md.closest_point(q).triangle];
  EXPECT_LT(std::abs(binomial_z(count, n, p)), 4.0) << "count " << count << " expected " << n * p;
}

TEST(SampleMeshUniform, MeshWithoutAreaGivesNoPoints) {
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  flat.triangles = {{0, 1, 2}, {1, 1, 1}};
  EXPECT_TRUE(sample_mesh_uniform(flat, 100, 1, true).empty());
  EXPECT_TRUE(sample_mesh_uniform(TriangleMesh{}, 100, 1, true).empty());
  EXPECT_TRUE(sample_mesh_uniform(box(1, 1, 1), 0, 1, true).empty());
}

TEST(AddGaussianNoise, StandardDeviationPerAxis) {
  const size_t n = 100000;
  const double sigma = 2.0;
  PointCloud cloud;
  cloud.positions.assign(n, Vec3f(100, 1200, -300));
  cloud.normals.assign(n, Vec3f(0, 0, 1));
  PointCloud noisy = cloud;
  add_gaussian_noise(noisy, sigma, 17);
  EXPECT_EQ(noisy.normals, cloud.normals);

  Vec3d mean = Vec3d::Zero();
  for (size_t i = 0; i < n; ++i) mean += (noisy.positions[i] - cloud.positions[i]).cast<double>();
  mean /= n;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  size_t within_one_sigma[3] = {0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const Vec3d e = (noisy.positions[i] - cloud.positions[i]).cast<double>() - mean;
    covariance += e * e.transpose();
    for (int k = 0; k < 3; ++k) within_one_sigma[k] += std::abs(e[k]) < sigma;
  }
  covariance /= n - 1;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(std::sqrt(covariance(k, k)), sigma, 0.03 * sigma) << "axis " << k;
    EXPECT_NEAR(mean[k], 0.0, 4.0 * sigma / std::sqrt(n)) << "axis " << k;
    // Gaussian, not merely the right variance: 68.27 % within one sigma.
    EXPECT_NEAR(within_one_sigma[k] / static_cast<double>(n), 0.6827, 0.006) << "axis " << k;
    for (int j = 0; j < k; ++j) {
      EXPECT_LT(std::abs(covariance(j, k)) / (sigma * sigma), 0.02) << "axes " << j << k;
    }
  }

  PointCloud again = cloud;
  add_gaussian_noise(again, sigma, 17);
  EXPECT_EQ(again.positions, noisy.positions);
  PointCloud still = cloud;
  add_gaussian_noise(still, 0.0, 17);
  EXPECT_EQ(still.positions, cloud.positions);
}

TEST(NonuniformSphere, DensityGrowsByTheRatioFromPoleToPole) {
  const size_t n = 200000;
  const double radius = 100.0;
  const double k = 8.0;
  const PointCloud cloud = nonuniform_sphere(n, radius, k, 31);
  ASSERT_EQ(cloud.size(), n);
  expect_on_sphere_with_exact_normals(cloud, radius);

  // Caps of equal area (5 % each) at both poles; t = (y / r + 1) / 2. Exact expected
  // ratio of their densities is ∫_{1-c}^1 k^t dt / ∫_0^c k^t dt = k^(1-c).
  const double c = 0.05;
  size_t top = 0, bottom = 0;
  for (const Vec3f& p : cloud.positions) {
    const double t = (p.y() / radius + 1.0) / 2.0;
    top += t > 1.0 - c;
    bottom += t < c;
  }
  ASSERT_GT(bottom, 0u);
  const double ratio = static_cast<double>(top) / static_cast<double>(bottom);
  EXPECT_NEAR(ratio, k, 0.25 * k);
  EXPECT_NEAR(ratio, std::pow(k, 1.0 - c), 0.08 * std::pow(k, 1.0 - c));

  // Ten equal-area bands: counts follow the density's integral over each band.
  size_t band[10] = {};
  for (const Vec3f& p : cloud.positions) {
    const double t = (p.y() / radius + 1.0) / 2.0;
    ++band[std::min(9, static_cast<int>(t * 10))];
  }
  for (int b = 0; b < 10; ++b) {
    const double expected = (std::pow(k, (b + 1) / 10.0) - std::pow(k, b / 10.0)) / (k - 1.0);
    EXPECT_LT(std::abs(binomial_z(band[b], n, expected)), 4.0) << "band " << b;
  }
}

TEST(NonuniformSphere, RatioOneIsUniformAndSeedsAreDeterministic) {
  const PointCloud uniform = nonuniform_sphere(100000, 10.0, 1.0, 4);
  size_t top = 0;
  for (const Vec3f& p : uniform.positions) top += p.y() > 5.0f;  // cap of 1/4 the area
  EXPECT_LT(std::abs(binomial_z(top, 100000, 0.25)), 4.0);
  EXPECT_EQ(nonuniform_sphere(1000, 10.0, 8.0, 4).positions, nonuniform_sphere(1000, 10.0, 8.0, 4).positions);
  EXPECT_NE(nonuniform_sphere(1000, 10.0, 8.0, 4).positions, nonuniform_sphere(1000, 10.0, 8.0, 5).positions);
}

}  // namespace
}  // namespace bodyscan
