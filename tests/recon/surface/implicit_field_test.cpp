// The kernel field: single kernels against their closed form, the sparse grid against
// direct evaluation, curvature compensation, option checks and memory that follows
// the surface.
#include "recon/surface/implicit_field.hpp"
#include "tests/recon/surface/sphere_kernels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "recon/geometry/sample_surface.hpp"

namespace bodyscan {
namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Options without designated initialisers (ImplicitFieldOptions has a ProgressFn).
ImplicitFieldOptions field_options(float voxel, int brick_size = 8, float epsilon = 1e-3f,
                                   size_t max_bricks = 4'000'000) {
  ImplicitFieldOptions o;
  o.voxel_size = voxel;
  o.brick_size = brick_size;
  o.epsilon = epsilon;
  o.max_bricks = max_bricks;
  return o;
}

// Squared normalised radius of the ellipsoid cut: eq. 3.26 with epsilon.
double cut_r2(float epsilon) { return -2.0 * std::log(static_cast<double>(epsilon)); }

using bodyscan::testing::sphere_kernels;

// The smallest q = |z|^2 over the kernels at x (the bent coordinate as the header
// defines it), to tell nodes well inside or outside every support from nodes on a
// cut, where float and double may disagree.
double min_q(const std::vector<Kernel>& ks, const Vec3d& x, double* max_q_inside, double r2) {
  double best = 1e300;
  *max_q_inside = 0;
  for (const Kernel& k : ks) {
    const Vec3d d = x - k.center.cast<double>();
    const double z1 = d.dot(k.t1.cast<double>()) / k.sigma_t1;
    const double z2 = d.dot(k.t2.cast<double>()) / k.sigma_t2;
    const double z3 = (d.dot(k.n.cast<double>()) +
                       0.5 * (k.bend1 * std::pow(z1 * k.sigma_t1, 2) + k.bend2 * std::pow(z2 * k.sigma_t2, 2))) /
                      k.sigma_n;
    const double q = z1 * z1 + z2 * z2 + z3 * z3;
    best = std::min(best, q);
    if (q < r2) *max_q_inside = std::max(*max_q_inside, q);
  }
  return best;
}

// Any node of an allocated brick, chosen at random.
Eigen::Vector3i random_node(const ImplicitField& f, std::mt19937_64& rng) {
  const size_t b = static_cast<size_t>(uniform01(rng) * static_cast<double>(f.num_bricks()));
  const int bs = f.brick_size();
  const Eigen::Vector3i off(static_cast<int>(uniform01(rng) * bs), static_cast<int>(uniform01(rng) * bs),
                            static_cast<int>(uniform01(rng) * bs));
  return f.brick_coord(b) * bs + off;
}

TEST(ImplicitFieldEvaluate, SingleFlatKernelClosedForm) {
  Kernel k;
  k.center = Vec3f(0.3f, -0.2f, 0.1f);
  const Eigen::Matrix3f rot = Eigen::AngleAxisf(0.9f, Vec3f(1, -2, 0.5f).normalized()).toRotationMatrix();
  k.t1 = rot.col(0);
  k.t2 = rot.col(1);
  k.n = rot.col(2);
  k.sigma_t1 = 0.4f;
  k.sigma_t2 = 0.25f;
  k.sigma_n = 0.1f;
  k.weight = 0.7f;
  const std::vector<Kernel> ks = {k};
  const Vec3d c = k.center.cast<double>();
  const Vec3d t1 = k.t1.cast<double>(), t2 = k.t2.cast<double>(), n = k.n.cast<double>();
  double v, w;
  // On the tangent plane: zero value (up to the float axes' orthogonality, ~1e-7),
  // Gaussian weight.
  for (double a : {-0.5, 0.0, 0.3}) {
    for (double b : {-0.2, 0.1}) {
      ImplicitField::evaluate(ks, 1e-3f, c + a * t1 + b * t2, &v, &w);
      EXPECT_NEAR(v, 0.0, 1e-6);
      const double q = std::pow(a / 0.4, 2) + std::pow(b / 0.25, 2);
      EXPECT_NEAR(w, 0.7 * std::exp(-0.5 * q), 1e-6);
    }
  }
  // Along the normal: f = -w (z/sn) exp(-(z/sn)^2 / 2): positive behind the normal
  // (inside), negative in front (outside), extreme at |z| = sn.
  for (double z : {-0.25, -0.1, -0.03, 0.03, 0.1, 0.25}) {
    ImplicitField::evaluate(ks, 1e-3f, c + z * n + 0.1 * t1, &v, &w);
    const double zn = z / 0.1;
    const double g = 0.7 * std::exp(-0.5 * (zn * zn + std::pow(0.1 / 0.4, 2)));
    EXPECT_NEAR(v, -zn * g, 1e-6) << z;
    EXPECT_NEAR(w, g, 1e-6) << z;
    EXPECT_EQ(v > 0, z < 0) << z;
  }
  // Beyond the cut |z| = sqrt(-2 ln eps) = 3.72 (epsilon 1e-3): nothing.
  ImplicitField::evaluate(ks, 1e-3f, c + 0.38 * n, &v, &w);
  EXPECT_EQ(v, 0.0);
  EXPECT_EQ(w, 0.0);
  ImplicitField::evaluate(ks, 1e-3f, c + 0.36 * n, &v, &w);
  EXPECT_GT(w, 0.0);
  ImplicitField::evaluate(ks, 1e-3f, c + 1.5 * t1, &v, &w);
  EXPECT_EQ(w, 0.0);
}

TEST(ImplicitFieldEvaluate, BentKernelZeroSetIsTheOsculatingSphere) {
  // bend b: the zero set is the sphere of radius 1 / b touching the tangent plane
  // at the centre, n = -(1 - sqrt(1 - b^2 r^2)) / b, for a surface bending away from
  // n with mean curvature b; to second order the paraboloid -b r^2 / 2. Beyond
  // r = 1 / b, where the sphere turns vertical, it goes on as -b r^2.
  Kernel k;
  k.center = Vec3f::Zero();
  k.t1 = Vec3f::UnitX();
  k.t2 = Vec3f::UnitY();
  k.n = Vec3f::UnitZ();
  k.sigma_t1 = k.sigma_t2 = 0.5f;
  k.sigma_n = 0.1f;
  k.bend1 = k.bend2 = 0.8f;
  double v, w;
  for (double u : {-0.6, -0.2, 0.3, 0.7, 1.3}) {
    const double r2 = u * u * 1.09;  // the point below is at (u, 0.3 u)
    auto sphere = [](double rr) { return rr * 0.64 < 1 ? -(1.0 - std::sqrt(1.0 - 0.64 * rr)) / 0.8 : -0.8 * rr; };
    const double sag = sphere(r2);
    ImplicitField::evaluate({k}, 1e-3f, Vec3d(u, 0.3 * u, sag), &v, &w);
    EXPECT_NEAR(v, 0.0, 1e-7) << u;
    if (std::abs(u) < 0.3) {
      EXPECT_NEAR(sag, -0.4 * r2, 0.01 * std::abs(sag)) << "paraboloid near the centre";
    }
    const double sag0 = sphere(u * u);
    ImplicitField::evaluate({k}, 1e-3f, Vec3d(u, 0.0, sag0 - 0.02), &v, &w);
    EXPECT_GT(v, 0.0) << u;  // below the sphere: inside
    ImplicitField::evaluate({k}, 1e-3f, Vec3d(u, 0.0, sag0 + 0.02), &v, &w);
    EXPECT_LT(v, 0.0) << u;
  }
}

// Builds the field and compares random allocated nodes with direct evaluation.
// Nodes within 1e-3 of a kernel's cut (in q) are skipped: there a float rounding
// decides whether a contribution of ~epsilon is in or out.
struct GridCheck {
  size_t compared = 0, outside = 0, mismatches = 0;
  double worst = 0;  // largest |grid - evaluate| / (W + |F|)
};

GridCheck check_grid_against_evaluate(const std::vector<Kernel>& ks, const ImplicitFieldOptions& o, size_t samples,
                                      uint64_t seed) {
  GridCheck r;
  auto field = build_implicit_field(ks, o);
  EXPECT_TRUE(field.ok()) << field.status().message();
  if (!field.ok()) return r;
  const double r2 = cut_r2(o.epsilon);
  std::mt19937_64 rng(seed);
  for (size_t s = 0; s < samples; ++s) {
    const Eigen::Vector3i node = random_node(*field, rng);
    const Vec3d x = field->node_position(node);
    double q_inside;
    const double q = min_q(ks, x, &q_inside, r2);
    if (q > r2 * (1 + 1e-3)) {
      ++r.outside;
      EXPECT_EQ(field->weight_at(node), 0.f) << "node outside every support has weight";
      EXPECT_EQ(field->value_at(node), 0.f);
      continue;
    }
    // Skip nodes near any kernel's cut.
    bool near_cut = false;
    for (const Kernel& k : ks) {
      double qi;
      min_q({k}, x, &qi, 1e300);
      if (std::abs(qi - r2) < 1e-3 * r2) near_cut = true;
    }
    if (near_cut) continue;
    double v, w;
    ImplicitField::evaluate(ks, o.epsilon, x, &v, &w);
    const double scale = w + std::abs(v);
    const double err = std::max(std::abs(field->value_at(node) - v), std::abs(field->weight_at(node) - w)) / scale;
    r.worst = std::max(r.worst, err);
    if (err > 1e-5) ++r.mismatches;
    ++r.compared;
  }
  return r;
}

TEST(ImplicitField, GridMatchesEvaluateFlatKernels) {
  // 400 kernels of mixed sizes and weights on a unit sphere (spacing ~0.18).
  std::vector<Kernel> ks = sphere_kernels(400, 1.0, Vec3f(0.1f, 0.2f, -0.3f), 0.2f, 0.06f, 0.f);
  std::mt19937_64 rng(2);
  for (Kernel& k : ks) {
    k.sigma_t1 *= static_cast<float>(0.7 + 0.6 * uniform01(rng));
    k.sigma_t2 *= static_cast<float>(0.7 + 0.6 * uniform01(rng));
    k.weight = static_cast<float>(0.2 + 0.8 * uniform01(rng));
  }
  const GridCheck r = check_grid_against_evaluate(ks, field_options(0.04f), 8000, 3);
  EXPECT_GT(r.compared, 500u);
  EXPECT_GT(r.outside, 100u);
  EXPECT_EQ(r.mismatches, 0u) << "worst relative error " << r.worst;
}

TEST(ImplicitField, GridMatchesEvaluateBentKernels) {
  // As above with bend 1/R = 1, |bend| sigma_t = 0.2. The grid must visit the whole
  // bent support, which near its rim reaches further along n than the flat one.
  std::vector<Kernel> ks = sphere_kernels(400, 1.0, Vec3f(0.1f, 0.2f, -0.3f), 0.2f, 0.06f, 1.f);
  const GridCheck r = check_grid_against_evaluate(ks, field_options(0.04f), 8000, 4);
  EXPECT_GT(r.compared, 500u);
  EXPECT_EQ(r.mismatches, 0u) << "worst relative error " << r.worst;
}

TEST(ImplicitField, GridMatchesEvaluateBandedKernels) {
  std::vector<Kernel> ks = sphere_kernels(400, 1.0, Vec3f(0.1f, 0.2f, -0.3f), 0.2f, 0.06f, 0.f);
  for (Kernel& k : ks) k.band = 0.1f;  // r sigma_n = 0.22
  const GridCheck r = check_grid_against_evaluate(ks, field_options(0.04f), 8000, 6);
  EXPECT_GT(r.compared, 500u);
  EXPECT_EQ(r.mismatches, 0u) << "worst relative error " << r.worst;
}

TEST(ImplicitField, SingleKernelGridAndSupport) {
  Kernel k;
  k.center = Vec3f(0.f, 0.f, 0.f);  // on a node: the grid is aligned to multiples of the voxel
  k.t1 = Vec3f::UnitX();
  k.t2 = Vec3f::UnitY();
  k.n = Vec3f::UnitZ();
  k.sigma_t1 = k.sigma_t2 = 1.f;
  k.sigma_n = 0.5f;
  k.weight = 0.8f;
  const ImplicitFieldOptions o = field_options(0.25f);
  auto field = build_implicit_field({k}, o);
  ASSERT_TRUE(field.ok()) << field.status().message();
  const double r2 = cut_r2(o.epsilon);
  // Every node of every allocated brick: inside the support it carries exactly the
  // kernel (up to float), outside it nothing. And every node inside is allocated.
  size_t inside = 0;
  for (size_t b = 0; b < field->num_bricks(); ++b) {
    const int bs = field->brick_size();
    for (int i = 0; i < bs * bs * bs; ++i) {
      const Eigen::Vector3i node = field->brick_coord(b) * bs + Eigen::Vector3i(i % bs, (i / bs) % bs, i / (bs * bs));
      const Vec3d x = field->node_position(node);
      double v, w, unused;
      const double q = min_q({k}, x, &unused, r2);
      ImplicitField::evaluate({k}, o.epsilon, x, &v, &w);
      if (std::abs(q - r2) < 1e-4 * r2) continue;
      EXPECT_NEAR(field->value_at(node), v, 1e-6) << node.transpose();
      EXPECT_NEAR(field->weight_at(node), w, 1e-6) << node.transpose();
      inside += q < r2;
    }
  }
  // Nodes inside the ellipsoid with semi-axes r (1, 1, 0.5) / 0.25: 4/3 pi r^3 * 0.5 / h^3.
  const double r = std::sqrt(r2);
  const double expected_nodes = 4.0 / 3.0 * std::numbers::pi * r * r * r * 0.5 / std::pow(0.25, 3);
  EXPECT_NEAR(static_cast<double>(inside), expected_nodes, 0.03 * expected_nodes);
  // The centre node carries the peak weight; value 0 on the plane.
  const Eigen::Vector3i centre = ((-field->origin()) / 0.25).array().round().cast<int>();
  ASSERT_LT((field->node_position(centre)).norm(), 1e-6);
  EXPECT_FLOAT_EQ(field->weight_at(centre), 0.8f);
  EXPECT_EQ(field->value_at(centre), 0.f);
  // Inside (below the plane) positive, outside negative.
  EXPECT_GT(field->value_at(centre + Eigen::Vector3i(0, 0, -2)), 0.f);
  EXPECT_LT(field->value_at(centre + Eigen::Vector3i(0, 0, 2)), 0.f);
  // Far away: not allocated, weight 0.
  EXPECT_EQ(field->weight_at(centre + Eigen::Vector3i(0, 0, 200)), 0.f);
  EXPECT_EQ(field->find_brick(Eigen::Vector3i(1000, 1000, 1000)), -1);
  // median_surface_weight at the centre is the peak; outside the field 0.
  EXPECT_FLOAT_EQ(median_surface_weight(*field, {Vec3f::Zero()}), 0.8f);
  EXPECT_EQ(median_surface_weight(*field, {Vec3f(50.f, 0.f, 0.f)}), 0.f);
  EXPECT_EQ(median_surface_weight(*field, {}), 0.f);
}

TEST(ImplicitField, BitIdenticalAcrossBrickSizes) {
  const std::vector<Kernel> ks = sphere_kernels(300, 1.0, Vec3f::Zero(), 0.25f, 0.08f, 0.5f);
  auto f8 = build_implicit_field(ks, field_options(0.05f, 8));
  ASSERT_TRUE(f8.ok());
  for (int bs : {2, 4, 32}) {
    auto f = build_implicit_field(ks, field_options(0.05f, bs));
    ASSERT_TRUE(f.ok()) << bs;
    ASSERT_EQ(f->origin(), f8->origin());
    size_t checked = 0, mismatched = 0;
    for (size_t b = 0; b < f->num_bricks(); ++b) {
      for (int i = 0; i < bs * bs * bs; ++i) {
        const Eigen::Vector3i node = f->brick_coord(b) * bs + Eigen::Vector3i(i % bs, (i / bs) % bs, i / (bs * bs));
        if (f->weight_at(node) == 0.f && f8->weight_at(node) == 0.f) continue;
        ++checked;
        mismatched += f->value_at(node) != f8->value_at(node) || f->weight_at(node) != f8->weight_at(node);
      }
    }
    EXPECT_GT(checked, 10000u);
    EXPECT_EQ(mismatched, 0u) << "brick size " << bs;
  }
}

// Radius at which the field changes sign along the ray from the origin through u, by
// bisection on [lo, hi] (inside at lo, outside at hi).
double zero_crossing(const std::vector<Kernel>& ks, const Vec3d& u, double lo, double hi) {
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    double v, w;
    ImplicitField::evaluate(ks, 1e-3f, mid * u, &v, &w);
    (v > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(ImplicitField, BendCompensationRemovesTheSphereBias) {
  // Flat kernels of tangential size sigma_t on a sphere put the zero set outside it by
  // about H sigma_t^2 (the neighbours' tangent planes all pass outside a point);
  // bending each kernel by the mean curvature 1/R removes that to first order.
  const double radius = 1.0;
  const float sigma_t = 0.16f, sigma_n = 0.04f;  // 2 and 0.5 spacings of 2000 points
  const std::vector<Kernel> flat = sphere_kernels(2000, radius, Vec3f::Zero(), sigma_t, sigma_n, 0.f);
  const std::vector<Kernel> bent = sphere_kernels(2000, radius, Vec3f::Zero(), sigma_t, sigma_n, 1.f / radius);
  std::mt19937_64 rng(5);
  double flat_sum = 0, bent_sum = 0, bent_worst = 0;
  const int rays = 60;
  for (int i = 0; i < rays; ++i) {
    const double y = 2 * uniform01(rng) - 1, phi = 2 * std::numbers::pi * uniform01(rng);
    const Vec3d u(std::sqrt(1 - y * y) * std::cos(phi), y, std::sqrt(1 - y * y) * std::sin(phi));
    const double df = zero_crossing(flat, u, 0.9, 1.1) - radius;
    const double db = zero_crossing(bent, u, 0.9, 1.1) - radius;
    flat_sum += df;
    bent_sum += db;
    bent_worst = std::max(bent_worst, std::abs(db));
  }
  const double flat_bias = flat_sum / rays, bent_bias = bent_sum / rays;
  const double h_sigma2 = sigma_t * sigma_t / radius;  // 0.0256
  EXPECT_GT(flat_bias, 0.5 * h_sigma2);                // outward, of the predicted size
  EXPECT_LT(flat_bias, 1.5 * h_sigma2);
  EXPECT_LT(std::abs(bent_bias), 0.1 * flat_bias);
  EXPECT_LT(bent_worst, 0.2 * flat_bias);
}

TEST(ImplicitField, RejectsBadOptions) {
  const std::vector<Kernel> ks = sphere_kernels(50, 1.0, Vec3f::Zero(), 0.3f, 0.1f, 0.f);
  auto expect_invalid = [&](const ImplicitFieldOptions& o, const std::string& what) {
    auto f = build_implicit_field(ks, o);
    ASSERT_FALSE(f.ok()) << what;
    EXPECT_EQ(f.status().code(), StatusCode::kInvalidArgument) << what;
    EXPECT_FALSE(f.status().message().empty()) << what;
  };
  expect_invalid(field_options(0.f), "voxel 0");
  expect_invalid(field_options(-0.1f), "negative voxel");
  expect_invalid(field_options(std::nanf("")), "NaN voxel");
  expect_invalid(field_options(INFINITY), "infinite voxel");
  expect_invalid(field_options(0.1f, 8, 1.f), "epsilon 1");
  expect_invalid(field_options(0.1f, 8, 0.f), "epsilon 0");
  expect_invalid(field_options(0.1f, 3), "brick 3");
  expect_invalid(field_options(0.1f, 1), "brick 1");
  expect_invalid(field_options(0.1f, 2048), "brick 2048");
  expect_invalid(field_options(0.1f, 0), "brick 0");
  {
    auto f = build_implicit_field({}, field_options(0.1f));
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.status().code(), StatusCode::kInvalidArgument);
  }
  {
    std::vector<Kernel> bad = ks;
    bad[7].center.x() = std::nanf("");
    auto f = build_implicit_field(bad, field_options(0.1f));
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.status().code(), StatusCode::kInvalidArgument);
  }
  {
    std::vector<Kernel> bad = ks;
    bad[3].weight = 0.f;
    auto f = build_implicit_field(bad, field_options(0.1f));
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.status().code(), StatusCode::kInvalidArgument);
  }
  {
    // A voxel far too small for the kernels: refused by the brick limit, not allocated.
    auto f = build_implicit_field(ks, field_options(0.01f, 8, 1e-3f, 1000));
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.status().code(), StatusCode::kOutOfRange);
    EXPECT_NE(f.status().message().find("voxel"), std::string::npos) << f.status().message();
  }
  {
    // More voxels along an axis than the brick coordinates can address.
    std::vector<Kernel> far = ks;
    far[0].center = Vec3f(1e6f, 0.f, 0.f);
    auto f = build_implicit_field(far, field_options(0.1f));
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.status().code(), StatusCode::kOutOfRange);
  }
}

TEST(ImplicitField, MemoryFollowsTheSurface) {
  // Spheres of radius 16 and 32 with the same spacing (one point per unit area), kernel
  // size and voxel: the allocated bricks follow the area (x4), not the volume (x8).
  auto build = [](double radius) {
    const size_t n = static_cast<size_t>(4 * std::numbers::pi * radius * radius);
    auto f = build_implicit_field(sphere_kernels(n, radius, Vec3f::Zero(), 1.2f, 0.5f, 0.f), field_options(0.5f));
    EXPECT_TRUE(f.ok());
    return std::move(f).value();
  };
  const ImplicitField a = build(16.0), b = build(32.0);
  const double ratio = static_cast<double>(b.num_bricks()) / static_cast<double>(a.num_bricks());
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 5.0);
  const double mem_ratio = static_cast<double>(b.memory_bytes()) / static_cast<double>(a.memory_bytes());
  EXPECT_GT(mem_ratio, 3.0);
  EXPECT_LT(mem_ratio, 5.0);
  EXPECT_GE(b.memory_bytes(), b.num_bricks() * b.nodes_per_brick() * 2 * sizeof(float));
}

TEST(ImplicitField, BandedKernelsAllocateOnlyBricksTheirBandsReach) {
  // A plane tilted to every grid axis, its kernels cut to a thin band: their
  // bounding boxes span a slab several bricks thick, their bands about one brick.
  // Allocated bricks must be those the bands reach, within the rows' rounding.
  const Vec3f n = Vec3f(1.f, 1.f, 1.f).normalized();
  const Vec3f t1 = Vec3f(1.f, -1.f, 0.f).normalized();
  const Vec3f t2 = n.cross(t1);
  std::vector<Kernel> ks;
  for (int i = -20; i <= 20; ++i) {
    for (int j = -20; j <= 20; ++j) {
      Kernel k;
      k.center = 0.5f * (static_cast<float>(i) * t1 + static_cast<float>(j) * t2);
      k.t1 = t1;
      k.t2 = t2;
      k.n = n;
      k.sigma_t1 = k.sigma_t2 = 1.f;
      k.sigma_n = 0.5f;
      k.band = 0.15f;
      ks.push_back(k);
    }
  }
  auto field = build_implicit_field(ks, field_options(0.1f, 8));
  ASSERT_TRUE(field.ok()) << field.status().message();
  size_t reached = 0;
  for (size_t b = 0; b < field->num_bricks(); ++b) {
    const float* w = field->weights(b);
    reached += std::any_of(w, w + field->nodes_per_brick(), [](float x) { return x > 0.f; }) ? 1 : 0;
  }
  EXPECT_GT(reached, 100u);
  EXPECT_LE(static_cast<double>(field->num_bricks()), 1.2 * static_cast<double>(reached));
  EXPECT_GE(field->memory_bytes(), field->num_bricks() * field->nodes_per_brick() * 2 * sizeof(float));
}

TEST(ImplicitField, ProgressAndCancel) {
  const std::vector<Kernel> ks = sphere_kernels(500, 1.0, Vec3f::Zero(), 0.2f, 0.06f, 0.f);
  std::vector<double> fractions;
  ImplicitFieldOptions o = field_options(0.03f);
  o.progress = [&](std::string_view stage, double f) {
    EXPECT_EQ(stage, "field");
    fractions.push_back(f);
    return true;
  };
  ASSERT_TRUE(build_implicit_field(ks, o).ok());
  ASSERT_FALSE(fractions.empty());
  // Worker threads report in any order; the largest is the end.
  EXPECT_NEAR(*std::max_element(fractions.begin(), fractions.end()), 1.0, 1e-9);
  for (double f : fractions) {
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0 + 1e-12);  // 0.1 + 0.9 d / n may round just above 1
  }
  int calls = 0;
  o.progress = [&](std::string_view, double) { return ++calls < 2; };
  auto f = build_implicit_field(ks, o);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.status().code(), StatusCode::kCancelled);
  o.progress = [](std::string_view, double) { return false; };
  EXPECT_EQ(build_implicit_field(ks, o).status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace bodyscan
