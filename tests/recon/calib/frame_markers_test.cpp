#include "recon/calib/frame_markers.hpp"

#include <gtest/gtest.h>

#include "tests/test_image.hpp"

#include <cmath>

namespace bodyscan {
namespace {

using testing::Image;

// Soft discs of radius r at the given centres on a flat background.
Image discs(int w, int h, const std::vector<Eigen::Vector2d>& centres, double r, uint16_t bg) {
  Image im{w, h, std::vector<uint16_t>(static_cast<size_t>(w) * h, bg)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (const auto& c : centres) {
        const double d = (Eigen::Vector2d(x, y) - c).norm();
        if (d < r + 1)
          im.px[static_cast<size_t>(y) * w + x] = static_cast<uint16_t>(bg + 200 * std::clamp(r + 0.5 - d, 0.0, 1.0));
      }
  return im;
}

std::vector<Eigen::Vector2d> eight() {
  std::vector<Eigen::Vector2d> c;
  for (int i = 0; i < 4; ++i) c.emplace_back(50.3 + 60 * i, 30.7 + 3 * i);   // top row, slightly slanted
  for (int i = 0; i < 4; ++i) c.emplace_back(40.1 + 70 * i, 180.2 - 4 * i);  // bottom row
  return c;
}

TEST(FrameMarkers, FindsAndOrdersEightLights) {
  const auto truth = eight();
  const Image on = discs(300, 220, truth, 4.0, 10), off{300, 220, std::vector<uint16_t>(300 * 220, 10)};
  auto m = find_markers(on.view(), off.view());
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(m->size(), 8u);
  auto f = order_frame_markers(*m);
  ASSERT_TRUE(f.ok()) << f.status().message();
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT((f->top[i] - truth[i]).norm(), 0.05);
    EXPECT_LT((f->bottom[i] - truth[4 + i]).norm(), 0.05);
  }
}

TEST(FrameMarkers, ALightsCentreCountsItsWholeSpot) {
  // A light as a camera sees it: a disc of radius 3.5 px, spread by the lens
  // (Gaussian, sigma 1.2 px) and bright enough to saturate (255) in the middle,
  // over a background of 10. The threshold (40 above the background) cuts off the
  // spread's tail, and where it cuts depends on where the centre falls within its
  // pixel: those centroids were 0.04-0.06 px off on the simulated rigs' cameras.
  // Counting the whole spot, every centre is within 0.01 px, at 25 sub-pixel places.
  const int w = 64, h = 64;
  for (int k = 0; k < 25; ++k) {
    const Eigen::Vector2d c(30.0 + 0.2 * (k % 5) + 0.03 * k, 31.0 + 0.2 * (k / 5.0) - 0.017 * k);
    Image on{w, h, std::vector<uint16_t>(static_cast<size_t>(w) * h, 10)};
    const Image off{w, h, std::vector<uint16_t>(static_cast<size_t>(w) * h, 10)};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        // The pixel's light: the disc convolved with the Gaussian, over the pixel's
        // area (8 x 8 samples, each the spread disc's value there, 16 x 16 over the disc).
        double v = 0;
        for (int j = 0; j < 8; ++j)
          for (int i = 0; i < 8; ++i) {
            const Eigen::Vector2d p(x - 0.5 + (i + 0.5) / 8, y - 0.5 + (j + 0.5) / 8);
            const double r = (p - c).norm();
            // The disc spread by the lens, radially: the mean of a unit Gaussian's
            // tail across the edge (erfc), a close stand-in for the exact convolution.
            v += 0.5 * std::erfc((r - 3.5) / (1.2 * std::sqrt(2.0))) / 64;
          }
        on.px[static_cast<size_t>(y) * w + x] = static_cast<uint16_t>(std::min(255.0, std::round(10 + 400 * v)));
      }
    auto m = find_markers(on.view(), off.view());
    ASSERT_TRUE(m.ok());
    ASSERT_EQ(m->size(), 1u);
    EXPECT_LT((m->front().centre - c).norm(), 0.01) << "centre " << c.transpose();
  }
}

TEST(FrameMarkers, MissingOrExtraLightsAreNamed) {
  auto truth = eight();
  truth.pop_back();  // a light that never turns on
  const Image on = discs(300, 220, truth, 4.0, 10), off{300, 220, std::vector<uint16_t>(300 * 220, 10)};
  auto m = find_markers(on.view(), off.view());
  ASSERT_TRUE(m.ok());
  auto f = order_frame_markers(*m);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.status().message().find("found 7 frame lights"), std::string::npos) << f.status().message();
  // A black "lights on" image: nothing found, an error, no garbage.
  auto none = find_markers(off.view(), off.view());
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
  EXPECT_FALSE(order_frame_markers(*none).ok());
  const Image small{10, 10, std::vector<uint16_t>(100, 0)};
  EXPECT_FALSE(find_markers(on.view(), small.view()).ok());
}

}  // namespace
}  // namespace bodyscan
