// The whole pipeline against surfaces it was sampled from: spheres at two scales,
// open sheets, a cube's edges, confidence, each normal source, bad input, progress,
// and the demo body.
#include "recon/surface/reconstruct.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "recon/geometry/mesh_distance.hpp"
#include "recon/geometry/sample_surface.hpp"
#include "recon/io/ply.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// One standard normal draw (Box-Muller, the cosine half).
double gaussian(std::mt19937_64& rng) {
  return std::sqrt(-2.0 * std::log(1.0 - uniform01(rng))) * std::cos(2 * std::numbers::pi * uniform01(rng));
}

ReconstructResult run(const PointCloud& cloud, const ReconstructOptions& options = {}) {
  auto r = reconstruct_surface(cloud, options);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? std::move(r).value() : ReconstructResult{};
}

PointCloud without_normals(PointCloud c) {
  c.normals.clear();
  return c;
}

// RMS of |v| - radius over the vertices, relative to nothing (the cloud's unit).
double radial_rms(const TriangleMesh& m, double radius) {
  double sum = 0;
  for (const Vec3f& v : m.vertices) sum += std::pow(v.cast<double>().norm() - radius, 2);
  return m.vertices.empty() ? std::numeric_limits<double>::infinity()
                            : std::sqrt(sum / static_cast<double>(m.vertices.size()));
}

double radial_mean(const TriangleMesh& m, double radius) {
  double sum = 0;
  for (const Vec3f& v : m.vertices) sum += v.cast<double>().norm() - radius;
  return sum / static_cast<double>(m.vertices.size());
}

void expect_closed_single(const TriangleMesh& m, const std::string& what) {
  ASSERT_FALSE(m.empty()) << what;
  const MeshTopology t = analyze_topology(m);
  EXPECT_EQ(t.boundary_edges, 0u) << what;
  EXPECT_EQ(t.non_manifold_edges, 0u) << what;
  EXPECT_EQ(t.inconsistent_edges, 0u) << what;
  EXPECT_EQ(t.components, 1u) << what;
  EXPECT_EQ(t.euler_characteristic, 2) << what;
  EXPECT_GT(signed_volume(m), 0.0) << what << ": wound inward";
}

TEST(ReconstructSurface, UnitSphereWithoutNormals) {
  const PointCloud c = without_normals(fibonacci_sphere(4096, 1.0));
  const ReconstructResult r = run(c);
  expect_closed_single(r.mesh, "sphere");
  EXPECT_EQ(r.stats.normals, NormalSource::kMst);
  EXPECT_EQ(r.stats.orientation_components, 1u);
  EXPECT_EQ(r.stats.input_points, 4096u);
  EXPECT_EQ(r.stats.used_points, 4096u);
  EXPECT_LT(radial_rms(r.mesh, 1.0), 0.002);
  EXPECT_NEAR(signed_volume(r.mesh), 4.0 / 3.0 * std::numbers::pi, 0.01 * 4.0 / 3.0 * std::numbers::pi);
  // The output's vertex normals are unit and outward.
  ASSERT_EQ(r.mesh.normals.size(), r.mesh.vertices.size());
  for (size_t i = 0; i < r.mesh.vertices.size(); ++i) {
    EXPECT_NEAR(r.mesh.normals[i].norm(), 1.f, 1e-4f);
    EXPECT_GT(r.mesh.normals[i].dot(r.mesh.vertices[i].normalized()), 0.9f) << i;
  }
}

TEST(ReconstructSurface, IsolatedStraysGetNoKernel) {
  // A sphere and three stray points far off (a floor sample, a speck): each would
  // get a kernel as wide as the gap to its neighbours and the grid with it.
  PointCloud c = fibonacci_sphere(4096, 1.0);
  for (const Vec3f& p : {Vec3f(12, 0, 0), Vec3f(0, -9, 7), Vec3f(-15, 4, 0)}) {
    c.positions.push_back(p);
    c.normals.push_back(Vec3f::UnitY());
  }
  const ReconstructResult r = run(c);
  expect_closed_single(r.mesh, "sphere with strays");
  EXPECT_EQ(r.stats.isolated_points, 3u);
  for (const Vec3f& v : r.mesh.vertices) EXPECT_LT(v.norm(), 1.1f);
  EXPECT_LT(radial_rms(r.mesh, 1.0), 0.002);
  ReconstructOptions keep;
  keep.isolated_spacing_ratio = 0;
  auto all = reconstruct_surface(c, keep);
  if (all.ok()) {
    EXPECT_EQ(all->stats.isolated_points, 0u);
  }
}

TEST(ReconstructSurface, NoisyUnitSphere) {
  // Noise 0.01 per axis, about 0.18 of the spacing (0.055).
  PointCloud c = without_normals(fibonacci_sphere(4096, 1.0));
  add_gaussian_noise(c, 0.01, 7);
  const ReconstructResult r = run(c);
  expect_closed_single(r.mesh, "noisy sphere");
  EXPECT_NEAR(r.stats.noise_sigma, 0.01, 0.002);  // the estimate the defaults follow
  EXPECT_LT(radial_rms(r.mesh, 1.0), 0.01);
}

TEST(ReconstructSurface, SparseSphereIsScaleInvariant) {
  // 128 points on a 1 m sphere in mm (spacing ~300 mm) and the same on a unit sphere:
  // the same relative error, because every default follows the cloud's own spacing.
  const ReconstructResult big = run(without_normals(fibonacci_sphere(128, 1000.0)));
  const ReconstructResult unit = run(without_normals(fibonacci_sphere(128, 1.0)));
  expect_closed_single(big.mesh, "1 m sphere");
  expect_closed_single(unit.mesh, "unit sphere");
  const double rel_big = radial_rms(big.mesh, 1000.0) / 1000.0;
  const double rel_unit = radial_rms(unit.mesh, 1.0);
  // Measured 0.0435. The thesis (Table 4.1, N = 128, s = 0) reports 0.0294; the gap
  // is the bent kernels' residual bias, not an estimation error: kernels built from
  // the exact normals with the exact bend 1/R give the same 0.043 when sigma_t is
  // 0.45 R, as it is at this density. Bounded where it stands so it cannot regress.
  EXPECT_LT(rel_big, 0.05);
  EXPECT_NEAR(rel_big / rel_unit, 1.0, 0.1) << rel_big << " vs " << rel_unit;
  EXPECT_NEAR(big.stats.voxel_size / unit.stats.voxel_size, 1000.0, 1.0);
}

TEST(ReconstructSurface, PlanePatchIsOpenAndFlat) {
  // 2500 random points on a 10 x 10 square of z = 0 (spacing ~0.2).
  std::mt19937_64 rng(11);
  PointCloud c;
  for (int i = 0; i < 2500; ++i)
    c.positions.emplace_back(10.f * static_cast<float>(uniform01(rng)), 10.f * static_cast<float>(uniform01(rng)), 0.f);
  const ReconstructResult r = run(c);
  ASSERT_FALSE(r.mesh.empty());
  const MeshTopology t = analyze_topology(r.mesh);
  EXPECT_GT(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.components, 1u);
  const double spacing = r.stats.median_density_sigma;  // mean distance to 10 neighbours
  double worst = 0;
  for (const Vec3f& v : r.mesh.vertices) worst = std::max(worst, static_cast<double>(std::abs(v.z())));
  EXPECT_LT(worst, 0.05 * spacing);
  // The sheet covers the square (up to a kernel's reach beyond the edge points).
  Vec3f lo = Vec3f::Constant(1e9f), hi = Vec3f::Constant(-1e9f);
  for (const Vec3f& v : r.mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_LT(lo.x(), 0.5f);
  EXPECT_LT(lo.y(), 0.5f);
  EXPECT_GT(hi.x(), 9.5f);
  EXPECT_GT(hi.y(), 9.5f);
}

TEST(ReconstructSurface, OpenCylinderTube) {
  // A tube of radius 1 and length 6 (no caps), 6000 random points: one component,
  // open only at its two rims (no holes in the wall), the wall at radius 1 away from
  // the open ends.
  std::mt19937_64 rng(12);
  PointCloud c;
  for (int i = 0; i < 6000; ++i) {
    const double phi = 2 * std::numbers::pi * uniform01(rng), y = 6 * uniform01(rng);
    c.positions.emplace_back(std::cos(phi), y, std::sin(phi));
  }
  const ReconstructResult r = run(c);
  ASSERT_FALSE(r.mesh.empty());
  const MeshTopology t = analyze_topology(r.mesh);
  EXPECT_GT(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.components, 1u);
  // Boundary vertices only at the rims (within a kernel's reach of y = 0 and y = 6).
  std::map<std::pair<uint32_t, uint32_t>, int> edge_uses;
  for (const Triangle& tri : r.mesh.triangles)
    for (int k = 0; k < 3; ++k) ++edge_uses[std::minmax(tri[k], tri[(k + 1) % 3])];
  size_t wall_holes = 0;
  for (const auto& [e, count] : edge_uses) {
    const float y = r.mesh.vertices[e.first].y();
    wall_holes += count == 1 && y > 0.5f && y < 5.5f;
  }
  EXPECT_EQ(wall_holes, 0u);
  double sum = 0;
  size_t n = 0;
  for (const Vec3f& v : r.mesh.vertices) {
    if (v.y() < 1.f || v.y() > 5.f) continue;
    sum += std::pow(std::hypot(v.x(), v.z()) - 1.0, 2);
    ++n;
  }
  ASSERT_GT(n, 1000u);
  EXPECT_LT(std::sqrt(sum / n), 0.005);
}

TEST(ReconstructSurface, AStripedLimbKeepsItsRadiusAcrossAGap) {
  // A forearm as the tiered rig's stripes sample it where they are sparse: a
  // cylinder of radius 26 mm, rings 12 mm apart along it, points 3 mm apart round
  // each ring, 0.2 mm of noise, and a 45-degree strip facing away from every camera
  // with no points at all. Bent by the mean curvature (half the limb's across it,
  // half along it where the limb is straight), the kernels either side of a point
  // along its ring sit outside the limb and outweigh those along the limb: the wall
  // came out 0.11 mm thick on average and, across the gap, where only the ring's
  // kernels reach, 0.87 mm. Bent along the principal directions: 0.03 and 0.09.
  std::mt19937_64 rng(5);
  const double radius = 26, ring = 12, step = 3, gap_lo = 80, gap_hi = 125;  // mm and degrees
  PointCloud c;
  for (double y = 3; y < 300; y += ring) {
    const int around = static_cast<int>(2 * std::numbers::pi * radius / step);
    for (int i = 0; i < around; ++i) {
      const double deg = 360.0 * (i + 0.5 * uniform01(rng)) / around;
      if (deg > gap_lo && deg < gap_hi) continue;
      const double a = deg * std::numbers::pi / 180;
      const Vec3f n(static_cast<float>(std::cos(a)), 0.f, static_cast<float>(std::sin(a)));
      c.positions.push_back(n * static_cast<float>(radius + 0.2 * gaussian(rng)) +
                            Vec3f(0.f, static_cast<float>(y + 0.2 * gaussian(rng)), 0.f));
      c.normals.push_back(n);
    }
  }
  const ReconstructResult r = run(c);
  ASSERT_FALSE(r.mesh.empty());
  double gap_sum = 0, rest_sum = 0;
  size_t gap_n = 0, rest_n = 0;
  for (const Vec3f& v : r.mesh.vertices) {
    if (v.y() < 60.f || v.y() > 240.f) continue;
    const double deg = std::fmod(std::atan2(v.z(), v.x()) * 180 / std::numbers::pi + 360, 360);
    const double e = std::hypot(v.x(), v.z()) - radius;
    if (deg > gap_lo && deg < gap_hi)
      gap_sum += e, ++gap_n;
    else
      rest_sum += e, ++rest_n;
  }
  ASSERT_GT(gap_n, 100u);
  ASSERT_GT(rest_n, 1000u);
  EXPECT_NEAR(gap_sum / gap_n, 0.0, 0.3);
  EXPECT_NEAR(rest_sum / rest_n, 0.0, 0.06);
}

TEST(ReconstructSurface, ACrownSeenOnlyUpItsSidesStandsHalfAsHighWithItsNormalsCarried) {
  // A head's crown as the tiered rig's cameras leave it: a sphere of radius 90
  // sampled 6 apart with 0.3 of noise, and a strip 36 wide over its top that no
  // camera saw. The kernels either side reach across the strip and close it. With
  // the PCA normals, which belong to their neighbourhoods' means a few mm down the
  // sphere, they extrapolate from planes tilted up toward the strip, and the top
  // stands 2.0 mm high; carried to their points (correct_normal_tilt), 1.0, and
  // with the edge's kernels bent by the operator fitted to the carried normals,
  // 0.86.
  std::mt19937_64 rng(11);
  const double radius = 90, spacing = 6, half_strip = 18, noise = 0.3;
  const PointCloud sphere =
      fibonacci_sphere(static_cast<size_t>(4 * std::numbers::pi * radius * radius / (spacing * spacing)), radius);
  PointCloud c;
  for (const Vec3f& unit : sphere.normals) {
    const Eigen::Vector3d d = unit.cast<double>();
    if (d.y() > 0 && std::abs(d.z()) * radius < half_strip) continue;
    const Eigen::Vector3d p = d * (radius + noise * gaussian(rng)) +
                              0.3 * noise * Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng));
    c.positions.push_back(p.cast<float>());
  }
  auto top = [&](bool correct) {
    ReconstructOptions o;
    o.correct_normal_tilt = correct;
    o.max_hole_area_fraction = 1.0;  // as a body's scan is closed
    o.hole_fairing = HoleFairing::kThinPlate;
    o.min_relative_weight = 0.02f;
    const ReconstructResult r = run(c, o);
    double y = -1e9;
    for (const Vec3f& v : r.mesh.vertices) y = std::max(y, static_cast<double>(v.y()));
    return y - radius;
  };
  const double before = top(false), after = top(true);
  EXPECT_GT(before, 1.6);  // 1.98
  EXPECT_LT(after, 1.1);   // 0.86
  EXPECT_GT(after, -0.5);
  EXPECT_LT(after, 0.6 * before);
}

TriangleMesh cube_mesh() { return testing::box_mesh(Vec3f::Constant(-1.f), Vec3f::Ones()); }

TEST(ReconstructSurface, SharpeningKeepsCubeEdgesCloser) {
  // Kernels lose size where the surface bends (eq. 3.24), so a cube's edges and
  // corners are rounded less: the farthest output vertex from the true cube comes
  // closer with s = 2 than with s = 0.
  const TriangleMesh cube = cube_mesh();
  ASSERT_GT(signed_volume(cube), 0.0);
  const PointCloud c = sample_mesh_uniform(cube, 6000, 13, /*with_normals=*/false);
  const MeshDistance truth(cube);
  auto worst_distance = [&](float s) {
    ReconstructOptions o;
    o.sharpening = s;
    // A fixed grid (half the density sigma of 0.076) keeps the two runs fast; the
    // default floor of 200 voxels per diagonal costs 3x the time here.
    o.voxel_size = 0.035f;
    const ReconstructResult r = run(c, o);
    // Not required closed here: holes along the edges are NoiseFreeCubeIsWatertight.
    EXPECT_EQ(analyze_topology(r.mesh).components, 1u) << "s=" << s;
    double worst = 0;
    for (float d : truth.distances(r.mesh.vertices)) worst = std::max(worst, static_cast<double>(d));
    return worst;
  };
  const double plain = worst_distance(0.f), sharp = worst_distance(2.f);
  EXPECT_LE(sharp, plain) << "s=2: " << sharp << ", s=0: " << plain;
}

TEST(ReconstructSurface, NoiseFreeCubeIsWatertight) {
  // Where a convex edge rounds the surface off, the rounded zero set lies outside
  // most kernels' support and cells there fall under the weight cut: the field alone
  // leaves small holes along this cube's edges (12 boundary edges, seed 13). The
  // hole filling closes them, and the filled part is tiny.
  const PointCloud c = sample_mesh_uniform(cube_mesh(), 20000, 13, /*with_normals=*/false);
  ReconstructOptions open;
  open.close_holes = false;
  EXPECT_GT(analyze_topology(run(c, open).mesh).boundary_edges, 0u) << "the field closes by itself now: "
                                                                       "make this test harder";
  const ReconstructResult r = run(c);
  expect_closed_single(r.mesh, "cube, 20000 points");
  EXPECT_GE(r.stats.holes_filled, 1u);
  EXPECT_LT(r.stats.hole_area, 1e-3 * surface_area(r.mesh));
}

TEST(ReconstructSurface, NoiseAsLargeAsTheSpacingDoesNotInflateTheSphere) {
  // 4096 points on the unit sphere with noise 0.1 per axis, about the spacing: the
  // thesis's hardest column. Noise along a curved surface puts points outside it on
  // average, and a normal width below the noise makes the sum find the (outer)
  // mode; the defaults remove both (measured: mean +0.006, RMS 0.0186, thesis
  // 0.0300; before, mean +0.050).
  PointCloud c = without_normals(fibonacci_sphere(4096, 1.0));
  add_gaussian_noise(c, 0.1, 5);
  const ReconstructResult r = run(c);
  expect_closed_single(r.mesh, "noisy sphere");
  EXPECT_LT(std::abs(radial_mean(r.mesh, 1.0)), 0.015);
  EXPECT_LT(radial_rms(r.mesh, 1.0), 0.02999);
}

TEST(ReconstructSurface, LowConfidencePointsPullLess) {
  // Every other point of a unit sphere moved outward by 0.05. With equal confidence the
  // surface sits about halfway (+0.025); with confidence 0.1 on the moved points it
  // must stay much closer to the true sphere.
  PointCloud c = without_normals(fibonacci_sphere(2048, 1.0));
  for (size_t i = 1; i < c.size(); i += 2) c.positions[i] *= 1.05f;
  // One fixed grid for all runs (half the density sigma, ~0.065): the comparison is
  // between weightings, and it keeps the four runs fast.
  ReconstructOptions fixed;
  fixed.voxel_size = 0.03f;
  const double equal = radial_mean(run(c, fixed).mesh, 1.0);
  c.confidence.assign(c.size(), 1.f);
  for (size_t i = 1; i < c.size(); i += 2) c.confidence[i] = 0.1f;
  const ReconstructResult weighted = run(c, fixed);
  expect_closed_single(weighted.mesh, "weighted sphere");
  const double trusted = radial_mean(weighted.mesh, 1.0);
  EXPECT_GT(equal, 0.01);
  EXPECT_LT(std::abs(trusted), 0.5 * equal) << "equal " << equal << " weighted " << trusted;
  // use_confidence = false ignores the weights.
  ReconstructOptions o = fixed;
  o.use_confidence = false;
  EXPECT_NEAR(radial_mean(run(c, o).mesh, 1.0), equal, 1e-6);
  // Zero confidence drops points altogether.
  for (size_t i = 1; i < c.size(); i += 2) c.confidence[i] = 0.f;
  const ReconstructResult dropped = run(c, fixed);
  EXPECT_EQ(dropped.stats.used_points, c.size() / 2);
  EXPECT_LT(std::abs(radial_mean(dropped.mesh, 1.0)), 0.002);
}

// A sphere seen by six cameras on the axes at distance 5: each point carries the id
// of the camera it faces most.
PointCloud sphere_with_cameras(size_t n) {
  PointCloud c = without_normals(fibonacci_sphere(n, 1.0));
  c.camera_centres = {{5, 0, 0}, {-5, 0, 0}, {0, 5, 0}, {0, -5, 0}, {0, 0, 5}, {0, 0, -5}};
  for (const Vec3f& p : c.positions) {
    int best = 0;
    for (int k = 1; k < 6; ++k)
      if (c.camera_centres[k].dot(p) > c.camera_centres[best].dot(p)) best = k;
    c.camera.push_back(best);
  }
  return c;
}

TEST(ReconstructSurface, EveryNormalSourceGivesTheClosedSphere) {
  const PointCloud with_normals = fibonacci_sphere(2048, 1.0);
  const PointCloud with_cameras = sphere_with_cameras(2048);
  struct Case {
    const PointCloud* cloud;
    NormalSource requested, used;
  };
  const Case cases[] = {
      {&with_normals, NormalSource::kAuto, NormalSource::kInput},
      {&with_cameras, NormalSource::kAuto, NormalSource::kCameras},
      {&with_normals, NormalSource::kMst, NormalSource::kMst},
      {&with_cameras, NormalSource::kCameras, NormalSource::kCameras},
      {&with_normals, NormalSource::kInput, NormalSource::kInput},
  };
  for (const Case& k : cases) {
    ReconstructOptions o;
    o.normal_source = k.requested;
    const ReconstructResult r = run(*k.cloud, o);
    const std::string what = std::string("requested ") + to_string(k.requested);
    expect_closed_single(r.mesh, what);
    EXPECT_EQ(r.stats.normals, k.used) << what;
    EXPECT_LT(radial_rms(r.mesh, 1.0), 0.003) << what;
  }
}

TEST(ReconstructSurface, InputNormalsDecideInsideAndOutside) {
  // Inward input normals are kept as given: the result is the same sphere wound inside
  // out (negative volume), which shows the input's orientation was used, not re-derived.
  PointCloud c = fibonacci_sphere(2048, 1.0);
  for (Vec3f& n : c.normals) n = -n;
  ReconstructOptions o;
  o.normal_source = NormalSource::kInput;
  const ReconstructResult r = run(c, o);
  ASSERT_FALSE(r.mesh.empty());
  EXPECT_LT(signed_volume(r.mesh), 0.0);
}

TEST(ReconstructSurface, NormalSourceNames) {
  for (NormalSource s : {NormalSource::kAuto, NormalSource::kInput, NormalSource::kCameras, NormalSource::kMst}) {
    NormalSource parsed = NormalSource::kAuto;
    ASSERT_TRUE(parse_normal_source(to_string(s), &parsed)) << to_string(s);
    EXPECT_EQ(parsed, s);
  }
  NormalSource untouched = NormalSource::kMst;
  EXPECT_FALSE(parse_normal_source("MST", &untouched));
  EXPECT_FALSE(parse_normal_source("", &untouched));
  EXPECT_EQ(untouched, NormalSource::kMst);
}

void expect_invalid(const PointCloud& c, const ReconstructOptions& o, const std::string& what,
                    const std::string& message_part) {
  auto r = reconstruct_surface(c, o);
  ASSERT_FALSE(r.ok()) << what;
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument) << what;
  EXPECT_NE(r.status().message().find(message_part), std::string::npos)
      << what << ": message '" << r.status().message() << "' should mention '" << message_part << "'";
}

TEST(ReconstructSurface, BadInputIsAStatus) {
  const PointCloud sphere = fibonacci_sphere(64, 1.0);
  {
    PointCloud c;
    c.positions.assign(sphere.positions.begin(), sphere.positions.begin() + 7);
    expect_invalid(c, {}, "7 points", "8 points");
    expect_invalid(PointCloud{}, {}, "empty cloud", "8 points");
  }
  {
    PointCloud c = without_normals(sphere);
    c.positions[10].y() = std::numeric_limits<float>::quiet_NaN();
    expect_invalid(c, {}, "NaN coordinate", "non-finite");
    c.positions[10].y() = std::numeric_limits<float>::infinity();
    expect_invalid(c, {}, "infinite coordinate", "non-finite");
  }
  {
    ReconstructOptions o;
    o.normal_source = NormalSource::kInput;
    expect_invalid(without_normals(sphere), o, "input normals missing", "normals");
    o.normal_source = NormalSource::kCameras;
    expect_invalid(without_normals(sphere), o, "cameras missing", "camera");
  }
  {
    PointCloud c = sphere;
    c.normals.pop_back();
    expect_invalid(c, {}, "attribute count mismatch", "one entry per point");
  }
  {
    PointCloud c = sphere;
    c.normals[5] = Vec3f::Zero();
    ReconstructOptions o;
    o.normal_source = NormalSource::kInput;
    expect_invalid(c, o, "zero input normal", "normal 5");
  }
  {
    PointCloud c = without_normals(sphere);
    c.confidence.assign(c.size(), 0.f);
    for (int i = 0; i < 7; ++i) c.confidence[i] = 1.f;
    expect_invalid(c, {}, "7 confident points", "8 points");
  }
}

TEST(ReconstructSurface, ProgressRunsThroughTheStagesAndCancels) {
  const PointCloud c = without_normals(fibonacci_sphere(2048, 1.0));
  const std::vector<std::string> order = {"neighbours", "normals", "orientation", "kernels", "field", "mesh", "done"};
  std::vector<std::pair<std::string, double>> calls;
  ReconstructOptions o;
  o.progress = [&](std::string_view stage, double f) {
    calls.emplace_back(std::string(stage), f);
    return true;
  };
  ASSERT_FALSE(run(c, o).mesh.empty());
  ASSERT_FALSE(calls.empty());
  // Stages appear in pipeline order, each fraction in [0, 1], the last call "done" at 1.
  size_t stage = 0;
  for (const auto& [name, f] : calls) {
    while (stage < order.size() && order[stage] != name) ++stage;
    ASSERT_LT(stage, order.size()) << "stage '" << name << "' out of order or unknown";
    EXPECT_GE(f, 0.0) << name;
    EXPECT_LE(f, 1.0 + 1e-12) << name;  // "field" computes 0.1 + 0.9 d / n
  }
  EXPECT_EQ(calls.back().first, "done");
  EXPECT_EQ(calls.back().second, 1.0);
  for (const std::string& s : order) {
    EXPECT_TRUE(std::any_of(calls.begin(), calls.end(), [&](const auto& e) { return e.first == s; }))
        << "stage " << s << " never reported";
  }
  // Cancelling in any stage stops the run with kCancelled ("done" is past the point
  // of no return).
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    ReconstructOptions oc;
    oc.progress = [&](std::string_view s, double) { return s != order[i]; };
    auto r = reconstruct_surface(c, oc);
    ASSERT_FALSE(r.ok()) << "cancel in " << order[i];
    EXPECT_EQ(r.status().code(), StatusCode::kCancelled) << "cancel in " << order[i];
  }
}

TEST(ReconstructSurface, ProgressIsMonotonicWithinAStageSingleThreaded) {
  // Within a stage, fractions never go back. (With several threads the field and mesh
  // stages report from whichever worker takes the lock first; see the report.)
  const PointCloud c = without_normals(fibonacci_sphere(2048, 1.0));
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  std::string last_stage;
  double last = -1;
  size_t backwards = 0;
  ReconstructOptions o;
  o.progress = [&](std::string_view stage, double f) {
    if (stage != last_stage) {
      last_stage = std::string(stage);
      last = -1;
    }
    backwards += f < last;
    last = f;
    return true;
  };
  ASSERT_FALSE(run(c, o).mesh.empty());
  EXPECT_EQ(backwards, 0u);
}

// The demo body, sampled with scanner-like noise (200k points, 0.5 mm per axis):
// the accuracy the product promises. Reconstructed once (~10-15 s) on first use, so
// a test that is skipped or filtered out does not pay for it.
struct BodyRun {
  TriangleMesh truth;
  StatusOr<ReconstructResult> result = internal_error("not run");
};

const BodyRun& body_run() {
  static const BodyRun run = [] {
    BodyRun r;
    auto body = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply");
    if (!body.ok()) {
      r.result = body.status();
      return r;
    }
    r.truth = std::move(body).value();
    PointCloud c = sample_mesh_uniform(r.truth, 200000, 2024, /*with_normals=*/false);
    add_gaussian_noise(c, 0.5, 2025);
    r.result = reconstruct_surface(c, {});
    return r;
  }();
  return run;
}

class MaleAverageBody : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(body_run().result.ok()) << body_run().result.status().message();
    truth_ = &body_run().truth;
    result_ = &body_run().result.value();
  }
  const TriangleMesh* truth_ = nullptr;
  const ReconstructResult* result_ = nullptr;
};

TEST_F(MaleAverageBody, AccurateSingleSurface) {
  const TriangleMesh& m = result_->mesh;
  ASSERT_FALSE(m.empty());
  const MeshTopology t = analyze_topology(m);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_NEAR(result_->stats.noise_sigma, 0.5, 0.075) << "mm";
  // 50k samples each way put the percentiles within ~0.01 mm.
  const MeshComparison cmp = compare_meshes(m, *truth_, 50000, 2026);
  EXPECT_LT(cmp.output_to_truth.rms, 0.5) << "mm";
  EXPECT_LT(cmp.output_to_truth.p95, 0.8) << "mm";
  EXPECT_LT(cmp.truth_to_output.p95, 1.0) << "mm";
  // The enclosed volume (62.82 L) within 1.5% (measured +0.9%, about 0.3 mm of
  // outward offset over the 1.9 m^2 skin; the holes of the next test are small).
  const double volume = signed_volume(*truth_);
  EXPECT_NEAR(volume, 62.82e6, 0.01e6) << "mm^3";
  EXPECT_NEAR(signed_volume(m), volume, 0.015 * volume) << "mm^3";
}

TEST(MaleAverageBodyTopology, Watertight) {
  // The field alone leaves open flaps where two surfaces come close or meet at a
  // crease (gluteal cleft, toes, and the mouth and eye cavities inside the head
  // that the shared mesh models): trimmed and filled, the surface is closed.
  ASSERT_TRUE(body_run().result.ok()) << body_run().result.status().message();
  const MeshTopology t = analyze_topology(body_run().result->mesh);
  EXPECT_EQ(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.components, 1u);
  // Not genus 0 like the truth: gaps narrower than the kernels (between fingers,
  // between the lips and the cheeks of the cleft) are bridged, and a bridge between
  // two fingers joined at the palm is a handle. Euler -60 here (genus 31); a
  // regression that makes the surface spongy shows as many more.
  EXPECT_GE(t.euler_characteristic, -90);
  // The fill stays small (measured 0.4% of the skin, mostly inside the mouth
  // cavity) and is marked: confidence 0 on the invented vertices only.
  const ReconstructResult& r = *body_run().result;
  EXPECT_LT(r.stats.hole_area, 0.01 * surface_area(r.mesh));
  ASSERT_EQ(r.mesh.confidence.size(), r.mesh.vertices.size());
  const size_t invented = static_cast<size_t>(std::count(r.mesh.confidence.begin(), r.mesh.confidence.end(), 0.f));
  EXPECT_GT(invented, 0u);
  EXPECT_LT(invented, r.mesh.vertices.size() / 100);
  std::printf("[ body ] holes filled %zu, area %.0f mm^2 of %.0f, invented vertices %zu, Euler %ld\n",
              r.stats.holes_filled, r.stats.hole_area, surface_area(r.mesh), invented, t.euler_characteristic);
}

}  // namespace
}  // namespace bodyscan
