#include "recon/scan/stripe.hpp"

#include <gtest/gtest.h>

#include "tests/test_image.hpp"

#include <cmath>
#include <random>

namespace bodyscan {
namespace {

using testing::Image;

// A stripe with a Gaussian cross profile centred at x = c(y), over a flat base.
Image stripe_image(int w, int h, double amplitude, double sigma, uint16_t base, double (*centre)(int)) {
  Image im{w, h, std::vector<uint16_t>(static_cast<size_t>(w) * h, base)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double d = x - centre(y);
      im.px[static_cast<size_t>(y) * w + x] = static_cast<uint16_t>(
          std::min(255.0, std::round(base + amplitude * std::exp(-0.5 * d * d / (sigma * sigma)))));
    }
  return im;
}

TEST(StripeExtraction, FindsTheSubPixelCentreOfEachRow) {
  auto centre = [](int y) { return 100.0 + 0.37 * y; };  // a slanted stripe
  const Image frame = stripe_image(640, 200, 180, 1.2, 10, centre);
  const Image base{640, 200, std::vector<uint16_t>(640 * 200, 10)};
  auto s = extract_stripe(frame.view(), base.view());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->size(), 200u);
  double worst = 0;
  for (const StripeSample& p : *s) worst = std::max(worst, std::abs(p.column - centre(p.row)));
  // Rounding the profile to integers is the only error.
  EXPECT_LT(worst, 0.02);
  EXPECT_EQ((*s)[0].peak, 180);
  EXPECT_FALSE((*s)[0].saturated);
}

TEST(StripeExtraction, ThresholdBaseAndSaturation) {
  auto centre = [](int) { return 50.0; };
  Image frame = stripe_image(100, 10, 255, 1.5, 0, centre);  // saturated core
  Image base{100, 10, std::vector<uint16_t>(1000, 0)};
  // Ambient light in the base is subtracted: a bright lamp elsewhere in both frames
  // does not win.
  for (int y = 0; y < 10; ++y) {
    frame.px[static_cast<size_t>(y) * 100 + 10] = 250;
    base.px[static_cast<size_t>(y) * 100 + 10] = 250;
  }
  auto s = extract_stripe(frame.view(), base.view(), {.threshold = 20, .radius = 4});
  ASSERT_TRUE(s.ok());
  ASSERT_EQ(s->size(), 10u);
  EXPECT_NEAR((*s)[3].column, 50.0, 0.01);
  EXPECT_TRUE((*s)[3].saturated);
  // Rows whose stripe is below the threshold give no sample.
  const Image faint = stripe_image(100, 10, 15, 1.5, 5, centre);
  const Image faint_base{100, 10, std::vector<uint16_t>(1000, 5)};
  auto none = extract_stripe(faint.view(), faint_base.view(), {.threshold = 20, .radius = 4});
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
  // A frame darker than its base everywhere (a light went out) gives nothing, not garbage.
  auto dark = extract_stripe(faint_base.view(), faint.view());
  ASSERT_TRUE(dark.ok());
  EXPECT_TRUE(dark->empty());
}

TEST(StripeExtraction, BadInputIsAnError) {
  const Image a{10, 10, std::vector<uint16_t>(100, 0)}, b{10, 9, std::vector<uint16_t>(90, 0)};
  auto s = extract_stripe(a.view(), b.view());
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("10x9"), std::string::npos);
  EXPECT_FALSE(extract_stripe(a.view(), a.view(), {.threshold = 0}).ok());
  EXPECT_FALSE(extract_stripe(ImageView{}, ImageView{}).ok());
}

TEST(StripeExtraction, WindowsKeepTheSearchWhereTheyAllow) {
  // Two stripes per row; the brighter one at x = 300 lies outside the window.
  Image frame{400, 20, std::vector<uint16_t>(400 * 20, 5)};
  for (int y = 0; y < 20; ++y) {
    frame.px[static_cast<size_t>(y) * 400 + 100] = 120;
    frame.px[static_cast<size_t>(y) * 400 + 300] = 250;
  }
  const Image base{400, 20, std::vector<uint16_t>(400 * 20, 5)};
  std::vector<ColumnRange> windows(20, ColumnRange{50, 200});
  windows[7] = {0, 0};  // a row with nothing to search
  auto s = extract_stripe(frame.view(), base.view(), {}, 255, &windows);
  ASSERT_TRUE(s.ok());
  ASSERT_EQ(s->size(), 19u);
  for (const StripeSample& p : *s) {
    EXPECT_NEAR(p.column, 100, 1e-6);
    EXPECT_NE(p.row, 7);
  }
  std::vector<ColumnRange> wrong(3);
  EXPECT_FALSE(extract_stripe(frame.view(), base.view(), {}, 255, &wrong).ok());
}

TEST(StripeSmoothing, AveragesNoiseAlongTheStripeAndStopsAtItsEnds) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.1);
  std::vector<StripeSample> s;
  auto truth = [](int y) { return y < 60 ? 200.0 + 0.3 * y : 400.0; };  // a jump at row 60
  for (int y = 0; y < 100; ++y) s.push_back({y, static_cast<float>(truth(y) + noise(rng)), 100, false});
  const std::vector<StripeSample> raw = s;
  smooth_stripe(s);
  double raw_ss = 0, smooth_ss = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    raw_ss += std::pow(raw[i].column - truth(raw[i].row), 2);
    smooth_ss += std::pow(s[i].column - truth(s[i].row), 2);
  }
  // Eleven samples per parabola: the noise falls by about sqrt(0.21) in the middle
  // of a run, less at its ends.
  EXPECT_LT(std::sqrt(smooth_ss / s.size()), 0.6 * std::sqrt(raw_ss / s.size()));
  // The jump is not smeared: each side keeps its own level.
  EXPECT_NEAR(s[59].column, truth(59), 0.3);
  EXPECT_NEAR(s[60].column, 400, 0.3);
}

// A stripe curves round the body it lies on. A straight line fitted over the
// window reads the window's mean at its middle, toward the curve's inside (0.1 px
// here, 0.06-0.10 mm inside the skin on a scan); a parabola reads the curve.
TEST(StripeSmoothing, ACurvedStripeIsNotPulledToItsInside) {
  std::vector<StripeSample> s;
  auto truth = [](int y) { return 200.0 + 0.01 * (y - 50) * (y - 50) + 0.2 * y; };
  for (int y = 0; y < 100; ++y) s.push_back({y, static_cast<float>(truth(y)), 100, false});
  smooth_stripe(s);
  for (size_t i = 2; i + 2 < s.size(); ++i) EXPECT_NEAR(s[i].column, truth(s[i].row), 2e-3) << "row " << s[i].row;
}

// A sample that no neighbouring row continues (a stripe glimpsed for one row) goes;
// runs of two rows or more stay whole, and a jump of more than 1.5 px per row
// starts a new run.
TEST(StripeRuns, LoneSamplesAreDroppedAndRunsKept) {
  std::vector<StripeSample> s;
  for (int y = 10; y < 20; ++y) s.push_back({y, 100.0f + 0.5f * (y - 10), 80, false});  // a run of 10
  s.push_back({20, 120.0f, 30, false});  // continues row 19 but 15.5 px across: alone
  s.push_back({25, 300.0f, 90, false});  // a gap of rows before and after: alone
  s.push_back({30, 50.0f, 70, false});   // a run of two
  s.push_back({31, 51.0f, 70, false});
  std::vector<StripeSample> kept = s;
  EXPECT_EQ(drop_short_runs(kept), 2u);
  ASSERT_EQ(kept.size(), 12u);
  for (size_t i = 0; i < 10; ++i) EXPECT_EQ(kept[i].row, s[i].row);
  EXPECT_EQ(kept[10].row, 30);
  EXPECT_EQ(kept[11].row, 31);
  // Three rows at least: the pair goes too. One row: everything stays.
  kept = s;
  EXPECT_EQ(drop_short_runs(kept, 3), 4u);
  EXPECT_EQ(kept.size(), 10u);
  kept = s;
  EXPECT_EQ(drop_short_runs(kept, 1), 0u);
  EXPECT_EQ(kept.size(), s.size());
  std::vector<StripeSample> none;
  EXPECT_EQ(drop_short_runs(none), 0u);
}

}  // namespace
}  // namespace bodyscan
