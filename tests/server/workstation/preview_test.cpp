// The station's camera thumbnails: a dark scan frame with a thin laser line must
// show both the line and the body, not a black square.
#include <gtest/gtest.h>

#include <algorithm>

#include "server/workstation/preview.hpp"

namespace bodyscan::testing {
namespace {

// 1280×1024, 12 bits: a dim background (20), a dim body (60 in a box), and a
// bright vertical laser line two pixels wide (3000) across it.
hw::Frame scan_frame() {
  hw::Frame f;
  f.width = 1280;
  f.height = 1024;
  f.format = hw::PixelFormat::kMono12;
  f.pixels.assign(static_cast<size_t>(f.width) * f.height, 20);
  for (int y = 200; y < 900; ++y)
    for (int x = 500; x < 800; ++x) f.pixels[static_cast<size_t>(y) * f.width + x] = 60;
  for (int y = 150; y < 950; ++y)
    for (int x = 641; x < 643; ++x) f.pixels[static_cast<size_t>(y) * f.width + x] = 3000;
  return f;
}

TEST(Preview, KeepsTheLaserLineAndShowsTheDimBody) {
  auto img = server::preview_image(scan_frame(), 160);
  ASSERT_TRUE(img.ok()) << img.status().message();
  ASSERT_EQ(img->width, 160);
  ASSERT_EQ(img->height, 128);
  EXPECT_EQ(img->bit_depth, 8);
  auto at = [&](int x, int y) { return img->pixels[static_cast<size_t>(y) * img->width + x]; };
  // The line (1280/160 = 8-pixel blocks: x 641-642 is in block 80) stays bright.
  EXPECT_GE(at(80, 64), 200);
  // A plain 8×8 mean would give (2×3000 + 62×60)/64 ≈ 152 of 4095, under 10 of 255.
  // The body is well clear of the background, and the background is near black.
  EXPECT_GT(at(70, 64), at(20, 20) + 100);
  EXPECT_LE(at(20, 20), 20);
}

TEST(Preview, AFlatFrameStaysFlatAndEmptyFramesAreRefused) {
  hw::Frame flat;
  flat.width = 640;
  flat.height = 480;
  flat.format = hw::PixelFormat::kMono8;
  flat.pixels.assign(static_cast<size_t>(flat.width) * flat.height, 30);
  auto img = server::preview_image(flat, 160);
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img->width, 160);
  const auto [lo, hi] = std::minmax_element(img->pixels.begin(), img->pixels.end());
  EXPECT_EQ(*lo, *hi);  // no noise amplified out of nothing
  EXPECT_FALSE(server::preview_image(hw::Frame{}, 160).ok());
  EXPECT_FALSE(server::preview_image(flat, 0).ok());
  auto png = server::preview_png(scan_frame(), 160);
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(png->substr(1, 3), "PNG");
}

}  // namespace
}  // namespace bodyscan::testing
