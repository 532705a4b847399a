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
        if (d < r + 1) im.px[static_cast<size_t>(y) * w + x] = static_cast<uint16_t>(bg + 200 * std::clamp(r + 0.5 - d, 0.0, 1.0));
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
