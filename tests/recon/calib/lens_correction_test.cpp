#include "recon/calib/lens_correction.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <set>

#include "recon/calib/plane_projection.hpp"  // fit_homography
#include "tests/test_image.hpp"

namespace bodyscan {
namespace {

using Eigen::Vector2d;
using testing::Image;

// A dot grid seen through a radial distortion the test knows. A captured pixel p
// sees the ideal (pinhole) point D(p) = c + (p - c)(1 + k |p - c|^2 / R^2), R the
// half-diagonal: k > 0 is barrel distortion, k = 0.1 squeezes the corners by 9%.
// The ideal grid: `spacing` apart, turned `turn_deg`, node (0, 0) at the centre.
struct Synthetic {
  int w = 800, h = 600;
  double k = 0;
  double spacing = 36, diameter = 14;
  double turn_deg = 4;
  std::set<std::pair<int, int>> removed;  // nodes without a dot
  std::vector<Vector2d> strays;           // extra dots, ideal coordinates

  Vector2d c() const { return {0.5 * (w - 1), 0.5 * (h - 1)}; }
  double r2() const { return c().squaredNorm(); }
  Vector2d ideal(const Vector2d& p) const { return c() + (p - c()) * (1 + k * (p - c()).squaredNorm() / r2()); }
  Vector2d captured(const Vector2d& q) const {
    const double rho = (q - c()).norm();
    double r = rho;  // Newton on r (1 + k r^2 / R^2) = rho
    for (int i = 0; i < 30; ++i) r -= (r * (1 + k * r * r / r2()) - rho) / (1 + 3 * k * r * r / r2());
    return rho > 0 ? Vector2d(c() + (q - c()) * (r / rho)) : c();
  }
  Vector2d node(double col, double row) const {
    const double t = turn_deg * M_PI / 180;
    return c() + spacing * Vector2d(std::cos(t) * col - std::sin(t) * row, std::sin(t) * col + std::cos(t) * row);
  }
  // Grid coordinates of an ideal point.
  Vector2d grid(const Vector2d& q) const {
    const double t = turn_deg * M_PI / 180;
    const Vector2d d = (q - c()) / spacing;
    return {std::cos(t) * d.x() + std::sin(t) * d.y(), -std::sin(t) * d.x() + std::cos(t) * d.y()};
  }
  bool in_dot(const Vector2d& q) const {
    const double r2 = 0.25 * diameter * diameter;
    for (const Vector2d& s : strays)
      if ((q - s).squaredNorm() < r2) return true;
    const Vector2d g = grid(q);
    const int col = static_cast<int>(std::lround(g.x())), row = static_cast<int>(std::lround(g.y()));
    if (removed.count({col, row})) return false;
    return (q - node(col, row)).squaredNorm() < r2;
  }
  // White board 180, dots 15, 6 x 6 samples a pixel, noise 1.5 grey levels.
  Image render(uint32_t seed = 1) const {
    Image im{w, h, std::vector<uint16_t>(static_cast<size_t>(w) * h)};
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0, 1.5);
    constexpr int kSub = 6;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int covered = 0;
        for (int sy = 0; sy < kSub; ++sy)
          for (int sx = 0; sx < kSub; ++sx)
            covered += in_dot(ideal({x - 0.5 + (sx + 0.5) / kSub, y - 0.5 + (sy + 0.5) / kSub}));
        const double v = 180 - 165.0 * covered / (kSub * kSub) + noise(rng);
        im.px[static_cast<size_t>(y) * w + x] = static_cast<uint16_t>(std::clamp(std::lround(v), 0L, 255L));
      }
    return im;
  }
  // The nodes whose captured centre (the image of the ideal one) lies `margin`
  // pixels inside the image, with that centre. The default margin keeps the dots
  // that are wholly inside, with room for find_dots's rim.
  std::map<std::pair<int, int>, Vector2d> visible(std::optional<double> margin = std::nullopt) const {
    std::map<std::pair<int, int>, Vector2d> out;
    const int reach = static_cast<int>(std::hypot(w, h) / spacing);
    for (int row = -reach; row <= reach; ++row)
      for (int col = -reach; col <= reach; ++col) {
        if (removed.count({col, row})) continue;
        const Vector2d p = captured(node(col, row));
        const double m = margin.value_or(0.5 * diameter + 9);
        if (p.x() > m && p.y() > m && p.x() < w - 1 - m && p.y() < h - 1 - m) out[{col, row}] = p;
      }
    return out;
  }
};

// RMS and largest distance between homography(a) and b, the homography fitted a -> b.
std::pair<double, double> after_homography(const std::vector<Vector2d>& a, const std::vector<Vector2d>& b) {
  const auto h = fit_homography(a, b);
  EXPECT_TRUE(h.ok());
  double ss = 0, worst = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double e = (apply_homography(*h, a[i]) - b[i]).norm();
    ss += e * e;
    worst = std::max(worst, e);
  }
  return {std::sqrt(ss / a.size()), worst};
}

TEST(LensDots, CentroidsOfAnUndistortedGridAreSubPixel) {
  Synthetic s;
  const Image im = s.render();
  auto dots = find_dots(im.view());
  ASSERT_TRUE(dots.ok()) << dots.status().message();
  const auto truth = s.visible(-s.diameter);  // any dot with a part in view
  double ss = 0, worst = 0;
  int matched = 0;
  for (const Dot& d : *dots) {
    double best = 1e9;
    for (const auto& [place, p] : truth) best = std::min(best, (d.centre - p).norm());
    ASSERT_LT(best, 1.0) << "a blob where no dot is: " << d.centre.transpose();
    ss += best * best;
    worst = std::max(worst, best);
    ++matched;
  }
  // Every dot wholly inside the image is found (those within a few pixels of the
  // border may be too, or left out as cut).
  EXPECT_GE(matched, static_cast<int>(s.visible().size()));
  EXPECT_LT(std::sqrt(ss / matched), 0.03);  // measured 0.0087
  EXPECT_LT(worst, 0.05);                    // measured 0.023
  std::printf("[ lens ] undistorted grid: %d dots, centroid error RMS %.4f px, worst %.4f px\n", matched,
              std::sqrt(ss / matched), worst);
}

class LensGridTurn : public ::testing::TestWithParam<double> {};

TEST_P(LensGridTurn, IndexesADistortedTurnedGridWithGapsAndStrays) {
  Synthetic s;
  s.k = 0.1;
  s.turn_deg = GetParam();
  s.removed = {{2, 1}, {-3, 0}, {5, -4}, {-6, 3}, {0, 5}};
  for (const auto& [c, r] :
       std::vector<std::pair<double, double>>{{0.5, 0.5}, {-2.5, 1.5}, {3.5, -2.5}, {-5.5, -3.5}, {6.5, 2.5}})
    s.strays.push_back(s.node(c, r));
  const Image im = s.render();
  auto dots = find_dots(im.view());
  ASSERT_TRUE(dots.ok());
  const auto truth = s.visible(-s.diameter);
  const std::vector<GridDot> grid = index_grid(*dots);
  // Every indexed dot is a true one, and one lattice map (a quarter-turn or none, a
  // mirror or none, a shift) takes every found place to the true one.
  std::optional<Eigen::Matrix<int, 2, 3>> map;
  int right = 0;
  for (const GridDot& g : grid) {
    std::pair<int, int> place{0, 0};
    double best = 1e9;
    for (const auto& [p, q] : truth)
      if ((g.centre - q).norm() < best) best = (g.centre - q).norm(), place = p;
    ASSERT_LT(best, 1.0) << "indexed a blob that is not a grid dot at " << g.centre.transpose();
    if (!map) {
      // Learn the map from this dot and its found neighbours' directions.
      const Vector2d u = s.grid(s.ideal(g.centre));
      for (const GridDot& n : grid) {
        if (n.row != g.row || n.col != g.col + 1) continue;
        const Vector2d du = s.grid(s.ideal(n.centre)) - u;
        for (const GridDot& m : grid) {
          if (m.col != g.col || m.row != g.row + 1) continue;
          const Vector2d dv = s.grid(s.ideal(m.centre)) - u;
          Eigen::Matrix<int, 2, 3> a;
          a.col(0) << static_cast<int>(std::lround(du.x())), static_cast<int>(std::lround(du.y()));
          a.col(1) << static_cast<int>(std::lround(dv.x())), static_cast<int>(std::lround(dv.y()));
          a.col(2) = Eigen::Vector2i(place.first, place.second) - a.leftCols<2>() * Eigen::Vector2i(g.col, g.row);
          map = a;
        }
      }
      if (!map) continue;
    }
    const Eigen::Vector2i mapped = map->leftCols<2>() * Eigen::Vector2i(g.col, g.row) + map->col(2);
    EXPECT_EQ(mapped, Eigen::Vector2i(place.first, place.second)) << "found " << g.col << "," << g.row;
    right += mapped == Eigen::Vector2i(place.first, place.second);
  }
  ASSERT_TRUE(map.has_value());
  // Col follows image x and row image y as nearly as the turn allows.
  if (s.turn_deg < 45) {
    EXPECT_EQ(map->leftCols<2>(), (Eigen::Matrix2i() << 1, 0, 0, 1).finished());
  }
  // All true dots but a few at the edges are indexed.
  const size_t in_view = s.visible().size();
  EXPECT_GE(right, static_cast<int>(in_view) - 10) << "of " << in_view;
  std::printf("[ lens ] turn %.0f deg: %zu blobs, %zu indexed, %zu dots wholly in view\n", s.turn_deg, dots->size(),
              grid.size(), in_view);
}

INSTANTIATE_TEST_SUITE_P(Turns, LensGridTurn, ::testing::Values(4.0, 30.0, 45.0, -17.0));

// One distorted calibration image and its correction, shared by the tests below.
struct Calibrated {
  Synthetic s;
  Image im;
  StatusOr<LensCorrection> lens = invalid_argument("not fitted");
  Calibrated() {
    s.k = 0.1;
    im = s.render();
    lens = calibrate_lens(im.view());
  }
  // Points between dots, inside the area the dots cover: each cell whose four dots
  // are wholly in view, sampled 3 x 3.
  std::vector<Vector2d> between_dots() const {
    const auto seen = s.visible();
    std::vector<Vector2d> out;
    for (const auto& [place, p] : seen) {
      const auto [col, row] = place;
      if (!seen.count({col + 1, row}) || !seen.count({col, row + 1}) || !seen.count({col + 1, row + 1})) continue;
      for (double v : {0.25, 0.5, 0.75})
        for (double u : {0.25, 0.5, 0.75}) out.push_back(s.captured(s.node(col + u, row + v)));
    }
    return out;
  }
};
const Calibrated& calibrated() {
  static const Calibrated c;
  return c;
}

TEST(LensCorrection, MatchesTheTrueUndistortionUpToAHomography) {
  const Calibrated& c = calibrated();
  ASSERT_TRUE(c.lens.ok()) << c.lens.status().message();
  std::vector<Vector2d> corrected, raw, truth;
  for (const Vector2d& p : c.between_dots()) {
    corrected.push_back(c.lens->correct(p));
    raw.push_back(p);
    truth.push_back(c.s.ideal(p));
  }
  ASSERT_GT(truth.size(), 2000u);
  const auto [rms, worst] = after_homography(corrected, truth);
  const auto [raw_rms, raw_worst] = after_homography(raw, truth);
  EXPECT_LT(rms, 0.02);                        // measured 0.0063
  EXPECT_LT(worst, 0.06);                      // measured 0.018
  EXPECT_GT(raw_rms, 3.0);                     // uncorrected: the distortion itself (4.4 px)
  EXPECT_LT(c.lens->held_out_rms_px(), 0.03);  // measured 0.011
  std::printf(
      "[ lens ] synthetic k=0.1: %d dots found, %d used, fit %.4f px, held-out %.4f px; truth RMS %.4f max "
      "%.4f px (uncorrected %.2f / %.2f)\n",
      c.lens->dots_found(), c.lens->dots_used(), c.lens->fit_rms_px(), c.lens->held_out_rms_px(), rms, worst, raw_rms,
      raw_worst);
}

TEST(LensCorrection, TableMatchesTheExactSpline) {
  const Calibrated& c = calibrated();
  ASSERT_TRUE(c.lens.ok());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-10, c.s.w + 10), y(-10, c.s.h + 10);
  double worst = 0, worst_inverse = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vector2d p(x(rng), y(rng));
    worst = std::max(worst, (c.lens->correct(p) - c.lens->correct_exact(p)).norm());
    const Vector2d q = c.lens->correct_exact(p);
    worst_inverse = std::max(worst_inverse, (c.lens->distort(q) - c.lens->distort_exact(q)).norm());
  }
  EXPECT_LT(worst, 0.002);  // measured 0.0005
  EXPECT_LT(worst_inverse, 0.002);
  std::printf("[ lens ] table vs exact spline: worst %.5f px (correct), %.5f px (distort)\n", worst, worst_inverse);
}

TEST(LensCorrection, DistortInvertsCorrect) {
  const Calibrated& c = calibrated();
  ASSERT_TRUE(c.lens.ok());
  double worst = 0;
  for (const Vector2d& p : c.between_dots()) worst = std::max(worst, (c.lens->distort(c.lens->correct(p)) - p).norm());
  EXPECT_LT(worst, 0.001);
  std::printf("[ lens ] distort(correct(p)) - p between dots: worst %.5f px\n", worst);
}

TEST(LensCorrection, RemapPutsTheDotsOnTheIdealGrid) {
  const Calibrated& c = calibrated();
  ASSERT_TRUE(c.lens.ok());
  auto remapped = c.lens->remap(c.im.view());
  ASSERT_TRUE(remapped.ok());
  const Image out{c.s.w, c.s.h, *remapped};
  // The remapped image is the ideal image up to a homography: its dots' centroids
  // lie where a homography puts the true grid nodes, as the raw image's do not.
  auto check = [&](const Image& im, bool corrected) {
    auto dots = find_dots(im.view());
    EXPECT_TRUE(dots.ok());
    std::vector<Vector2d> found, nodes;
    for (const Dot& d : *dots) {
      const Vector2d g = c.s.grid(c.s.ideal(corrected ? c.lens->distort(d.centre) : d.centre));
      found.push_back(d.centre);
      nodes.push_back(c.s.node(std::round(g.x()), std::round(g.y())));
    }
    return after_homography(nodes, found);
  };
  const auto [rms, worst] = check(out, true);
  const auto [raw_rms, raw_worst] = check(c.im, false);
  EXPECT_LT(rms, 0.05);
  EXPECT_LT(worst, 0.2);
  EXPECT_GT(raw_rms, 3.0);
  std::printf("[ lens ] remapped dots vs the ideal grid: RMS %.4f px, worst %.4f px (raw image RMS %.2f px)\n", rms,
              worst, raw_rms);
}

TEST(LensCorrection, IdentityChangesNothing) {
  const LensCorrection none;
  const Vector2d p(12.25, -3.5);
  EXPECT_EQ(none.correct(p), p);
  EXPECT_EQ(none.distort(p), p);
  Image im{3, 2, {1, 2, 3, 4, 5, 6}};
  auto out = none.remap(im.view());
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(*out, im.px);
}

TEST(LensCorrection, ErrorsSayWhatIsMissing) {
  const Image black{320, 240, std::vector<uint16_t>(320 * 240, 0)};
  auto lens = calibrate_lens(black.view());
  ASSERT_FALSE(lens.ok());
  EXPECT_EQ(lens.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(lens.status().message().find("no dots found"), std::string::npos) << lens.status().message();

  const Image white{320, 240, std::vector<uint16_t>(320 * 240, 200)};
  EXPECT_FALSE(calibrate_lens(white.view()).ok());

  // A 4 x 4 grid: indexed, but too few dots to pin the correction down.
  Synthetic few;
  few.w = 320, few.h = 240;
  for (int row = -10; row <= 10; ++row)
    for (int col = -10; col <= 10; ++col)
      if (std::abs(2 * col + 1) > 4 || std::abs(2 * row + 1) > 4) few.removed.insert({col, row});
  lens = calibrate_lens(few.render().view());
  ASSERT_FALSE(lens.ok());
  EXPECT_EQ(lens.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(lens.status().message().find("only 16 form a grid; at least 42"), std::string::npos)
      << lens.status().message();

  std::vector<GridDot> dots;
  for (int row = 0; row < 7; ++row)
    for (int col = 0; col < 7; ++col) dots.push_back({Vector2d(10.0 * col, 10.0 * row), col, row});
  dots[7].centre.x() = std::nan("");
  auto fitted = LensCorrection::fit(dots, 100, 100);
  ASSERT_FALSE(fitted.ok());
  EXPECT_EQ(fitted.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(fitted.status().message().find("not finite"), std::string::npos) << fitted.status().message();

  const LensCorrection& fitted_lens = *calibrated().lens;
  const Image small{10, 10, std::vector<uint16_t>(100, 0)};
  EXPECT_FALSE(fitted_lens.remap(small.view()).ok());
}

}  // namespace
}  // namespace bodyscan
