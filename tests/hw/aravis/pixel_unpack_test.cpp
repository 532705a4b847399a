#include "hw/aravis/pixel_unpack.hpp"

#include <gtest/gtest.h>

namespace bodyscan::hw::aravis {
namespace {

TEST(PixelUnpack, Mono12PackedIsGigEVisionsLayout) {
  // Pixels 0xABC and 0x123: byte 0 = 0xAB, byte 1 = low nibbles 0xC (p0) | 0x3 << 4 (p1), byte 2 = 0x12.
  const uint8_t data[] = {0xAB, 0x3C, 0x12, 0xFF, 0x0F, 0x00};
  std::vector<uint16_t> out;
  ASSERT_TRUE(unpack_mono(kPfncMono12Packed, data, sizeof data, 2, 2, out).ok());
  EXPECT_EQ(out, (std::vector<uint16_t>{0xABC, 0x123, 0xFFF, 0x000}));
}

TEST(PixelUnpack, Mono12pIsALittleEndianBitStream) {
  // 0xABC then 0x123 as a 24-bit little-endian stream: 0x123ABC -> BC 3A 12.
  const uint8_t data[] = {0xBC, 0x3A, 0x12};
  std::vector<uint16_t> out;
  ASSERT_TRUE(unpack_mono(kPfncMono12p, data, sizeof data, 2, 1, out).ok());
  EXPECT_EQ(out, (std::vector<uint16_t>{0xABC, 0x123}));
}

TEST(PixelUnpack, Mono10PackedAndUnpackedForms) {
  // 0x3FF and 0x001: byte 0 = 0xFF (p0 >> 2), byte 1 = 0x3 | (0x1 << 4), byte 2 = 0x00.
  const uint8_t packed[] = {0xFF, 0x13, 0x00};
  std::vector<uint16_t> out;
  ASSERT_TRUE(unpack_mono(kPfncMono10Packed, packed, sizeof packed, 2, 1, out).ok());
  EXPECT_EQ(out, (std::vector<uint16_t>{0x3FF, 0x001}));
  // Unpacked 16-bit containers keep only the significant bits.
  const uint8_t mono12[] = {0xBC, 0xFA, 0x01, 0x00};
  ASSERT_TRUE(unpack_mono(kPfncMono12, mono12, sizeof mono12, 2, 1, out).ok());
  EXPECT_EQ(out, (std::vector<uint16_t>{0xABC, 0x001}));
  const uint8_t mono16[] = {0x34, 0x12};
  ASSERT_TRUE(unpack_mono(kPfncMono16, mono16, sizeof mono16, 1, 1, out).ok());
  EXPECT_EQ(out[0], 0x1234);
}

TEST(PixelUnpack, ShortBuffersAndColourFormatsAreRefused) {
  const uint8_t data[4] = {};
  std::vector<uint16_t> out;
  const Status short_buf = unpack_mono(kPfncMono8, data, sizeof data, 3, 2, out);
  ASSERT_FALSE(short_buf.ok());
  EXPECT_NE(short_buf.message().find("needs 6 bytes"), std::string::npos) << short_buf.message();
  const Status colour = unpack_mono(0x02180014u /* RGB8 */, data, sizeof data, 1, 1, out);
  ASSERT_FALSE(colour.ok());
  EXPECT_NE(colour.message().find("monochrome"), std::string::npos);
}

}  // namespace
}  // namespace bodyscan::hw::aravis
