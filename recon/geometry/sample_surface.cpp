// Synthetic point sets with known ground truth. References are in the header.
#include "recon/geometry/sample_surface.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace bodyscan {

namespace {

// Uniform in [0, 1) from the top 53 bits: the same on every standard library, unlike
// std::uniform_real_distribution.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Standard normal pairs by the Box–Muller transform; 1 - u keeps the log finite.
class Gaussian {
 public:
  double operator()(std::mt19937_64& rng) {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(1.0 - uniform01(rng)));
    const double phi = 2.0 * std::numbers::pi * uniform01(rng);
    spare_ = r * std::sin(phi);
    has_spare_ = true;
    return r * std::cos(phi);
  }

 private:
  double spare_ = 0;
  bool has_spare_ = false;
};

// Position and exact outward normal of the point at height y (|y| <= radius) and
// longitude phi on a sphere about the origin whose poles are on ±Y.
void add_sphere_point(PointCloud& cloud, double radius, double y_unit, double phi) {
  y_unit = std::clamp(y_unit, -1.0, 1.0);
  const double ring = std::sqrt(std::max(0.0, 1.0 - y_unit * y_unit));
  const Vec3d n(ring * std::cos(phi), y_unit, ring * std::sin(phi));
  const Vec3d unit = n.normalized();  // already unit up to rounding; make it exact in double
  cloud.positions.push_back((radius * unit).cast<float>());
  cloud.normals.push_back(unit.cast<float>().normalized());
}

}  // namespace

PointCloud sample_mesh_uniform(const TriangleMesh& mesh, size_t n, uint64_t seed, bool with_normals) {
  // Cumulative areas in double: 10^5 float additions would lose the small triangles.
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    assert(tri[0] < mesh.vertices.size() && tri[1] < mesh.vertices.size() && tri[2] < mesh.vertices.size());
    const Vec3d a = mesh.vertices[tri[0]].cast<double>();
    const Vec3d b = mesh.vertices[tri[1]].cast<double>();
    const Vec3d c = mesh.vertices[tri[2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative[t] = total;
  }

  PointCloud cloud;
  if (n == 0 || !(total > 0)) return cloud;
  cloud.positions.reserve(n);
  if (with_normals) cloud.normals.reserve(n);

  // Sequential on purpose: one generator keeps the output a pure function of the seed,
  // and three draws per point cost far less than anything the samples are used for.
  std::mt19937_64 rng(seed);
  for (size_t i = 0; i < n; ++i) {
    // upper_bound never returns a zero-area triangle: its cumulative value equals its
    // predecessor's, so no u in [0, total) lands on it.
    const double u = uniform01(rng) * total;
    const size_t t = std::min<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin(),
                                      cumulative.size() - 1);
    const Triangle& tri = mesh.triangles[t];
    const Vec3d a = mesh.vertices[tri[0]].cast<double>();
    const Vec3d b = mesh.vertices[tri[1]].cast<double>();
    const Vec3d c = mesh.vertices[tri[2]].cast<double>();
    // sqrt makes the density uniform over the triangle instead of crowding corner a.
    const double s = std::sqrt(uniform01(rng));
    const double r = uniform01(rng);
    const Vec3d p = (1.0 - s) * a + s * (1.0 - r) * b + s * r * c;
    cloud.positions.push_back(p.cast<float>());
    if (with_normals) cloud.normals.push_back((b - a).cross(c - a).normalized().cast<float>());
  }
  return cloud;
}

PointCloud fibonacci_sphere(size_t n, double radius) {
  PointCloud cloud;
  cloud.positions.reserve(n);
  cloud.normals.reserve(n);
  // Point i sits at the centre of the i-th of n equal-area latitude bands (y uniform in
  // [-1, 1] gives equal areas) and turns by the golden angle, the most irrational
  // rotation, so no two points line up in longitude.
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (size_t i = 0; i < n; ++i) {
    const double y = 1.0 - (2.0 * static_cast<double>(i) + 1.0) / static_cast<double>(n);
    add_sphere_point(cloud, radius, y, golden_angle * static_cast<double>(i));
  }
  return cloud;
}

void add_gaussian_noise(PointCloud& cloud, double sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  Gaussian gauss;
  for (Vec3f& p : cloud.positions) {
    const Vec3d noise(gauss(rng), gauss(rng), gauss(rng));
    p = (p.cast<double>() + sigma * noise).cast<float>();
  }
}

PointCloud nonuniform_sphere(size_t n, double radius, double density_ratio, uint64_t seed) {
  assert(density_ratio > 0);
  PointCloud cloud;
  cloud.positions.reserve(n);
  cloud.normals.reserve(n);
  std::mt19937_64 rng(seed);
  // Density k^t for t in [0, 1] has CDF F(t) = (k^t - 1) / (k - 1), so t = log(1 + u (k - 1))
  // / log k; log1p/expm1 keep it accurate for k near 1, where it tends to t = u.
  const double log_k = std::log(density_ratio);
  for (size_t i = 0; i < n; ++i) {
    const double u = uniform01(rng);
    const double t = std::abs(log_k) < 1e-12 ? u : std::log1p(u * std::expm1(log_k)) / log_k;
    const double phi = 2.0 * std::numbers::pi * uniform01(rng);
    add_sphere_point(cloud, radius, 2.0 * t - 1.0, phi);
  }
  return cloud;
}

}  // namespace bodyscan
