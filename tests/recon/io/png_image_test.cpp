#include "recon/io/png_image.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

uint32_t crc32_of(const std::string& bytes, size_t begin, size_t end) {
  uint32_t crc = 0xffffffffu;
  for (size_t i = begin; i < end; ++i) {
    crc ^= static_cast<uint8_t>(bytes[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// Rewrites the CRC of the chunk whose type starts at `type_at`, so that the chunk
// passes libpng's CRC check with whatever its data now holds.
void fix_crc(std::string& png, size_t type_at) {
  const auto b = [&](size_t i) { return static_cast<uint32_t>(static_cast<uint8_t>(png[i])); };
  const uint32_t length = b(type_at - 4) << 24 | b(type_at - 3) << 16 | b(type_at - 2) << 8 | b(type_at - 1);
  const size_t crc_at = type_at + 4 + length;
  const uint32_t crc = crc32_of(png, type_at, crc_at);
  for (int k = 0; k < 4; ++k) png[crc_at + k] = static_cast<char>(crc >> (24 - 8 * k));
}

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

// Errors inside libpng come back by longjmp; these reach it after the image's
// storage is allocated (a zlib stream that breaks off inside the rows) and before
// (a header that is valid but not gray), with chunk CRCs that check out.
TEST(PngImage, DamagedImageDataIsACorruptPngError) {
  const std::string dir = testing::temp_dir();
  ASSERT_TRUE(write_png(dir + "/ok.png", ramp(16)).ok());
  std::ifstream in(dir + "/ok.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);

  int refused = 0;
  for (int round = 0; round < 20; ++round) {
    std::string damaged = bytes;
    // Inside the deflate stream, past its 2-byte zlib header: a different byte at a
    // different place each round.
    damaged[idat + 4 + 2 + static_cast<size_t>(round) * 7] ^= static_cast<char>(0x55 + round);
    fix_crc(damaged, idat);
    std::ofstream(dir + "/damaged.png", std::ios::binary) << damaged;
    auto r = read_png(dir + "/damaged.png");
    if (r.ok()) {
      // A flip can leave a valid deflate stream; then the pixels differ, the size not.
      EXPECT_EQ(r->width, 37);
      continue;
    }
    ++refused;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find("corrupt PNG: "), std::string::npos) << r.status().message();
  }
  EXPECT_GT(refused, 10);

  std::string rgb = bytes;
  rgb[8 + 8 + 9] = 2;  // IHDR's colour type: truecolour
  fix_crc(rgb, 12);
  std::ofstream(dir + "/rgb.png", std::ios::binary) << rgb;
  auto r = read_png(dir + "/rgb.png");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("only 8- and 16-bit grayscale"), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace bodyscan
