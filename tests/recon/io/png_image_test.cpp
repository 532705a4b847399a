#include "recon/io/png_image.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

GrayImage ramp(int bits) {
  GrayImage g;
  g.width = 37;
  g.height = 11;
  g.bit_depth = bits;
  std::mt19937 rng(5);
  for (int i = 0; i < g.width * g.height; ++i) g.pixels.push_back(static_cast<uint16_t>(rng() % (1u << bits)));
  return g;
}

TEST(PngImage, RoundTripsEightAndSixteenBits) {
  const std::string dir = testing::temp_dir();
  for (int bits : {8, 16}) {
    const GrayImage a = ramp(bits);
    const std::string path = dir + "/r" + std::to_string(bits) + ".png";
    ASSERT_TRUE(write_png(path, a).ok());
    auto b = read_png(path);
    ASSERT_TRUE(b.ok()) << b.status().message();
    EXPECT_EQ(b->width, a.width);
    EXPECT_EQ(b->height, a.height);
    EXPECT_EQ(b->bit_depth, bits);
    EXPECT_EQ(b->pixels, a.pixels);
  }
}

TEST(PngImage, BadFilesAndBadImagesAreClearErrors) {
  const std::string dir = testing::temp_dir();
  GrayImage bad = ramp(8);
  bad.pixels.pop_back();
  EXPECT_EQ(write_png(dir + "/bad.png", bad).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(read_png(dir + "/missing.png").status().code(), StatusCode::kNotFound);
  ASSERT_TRUE(write_png(dir + "/ok.png", ramp(16)).ok());
  std::ifstream in(dir + "/ok.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t cut : {size_t{4}, size_t{30}, bytes.size() / 2, bytes.size() - 5}) {
    std::ofstream(dir + "/cut.png", std::ios::binary) << bytes.substr(0, cut);
    auto r = read_png(dir + "/cut.png");
    EXPECT_FALSE(r.ok()) << "cut at " << cut;
  }
  std::string flipped = bytes;
  flipped[40] ^= 0x5a;  // inside the header chunk: its CRC no longer matches
  std::ofstream(dir + "/flip.png", std::ios::binary) << flipped;
  auto r = read_png(dir + "/flip.png");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("corrupt PNG"), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace bodyscan
