// PLY reading on malformed, truncated, lying and random input: every case must give
// an InvalidArgument naming the file and the place, never a crash, a hang or a huge
// allocation. Run under valgrind / sanitizers to make "never a crash" mean something.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>

#include "recon/io/ply.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

template <typename T>
void put_le(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";
const std::string kBinaryStart = "ply\nformat binary_little_endian 1.0\n";
const std::string kAsciiStart = "ply\nformat ascii 1.0\n";

// Parses `bytes` expecting failure; returns the message.
std::string error_of(const std::string& bytes) {
  auto data = parse_ply(bytes, "bad.ply");
  EXPECT_FALSE(data.ok()) << "parsed a bad file:\n" << bytes.substr(0, 400);
  if (data.ok()) return "";
  EXPECT_EQ(data.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(data.status().message().rfind("bad.ply: ", 0), 0u) << data.status().message();
  return data.status().message();
}

#define EXPECT_ERROR_CONTAINS(bytes, text)                         \
  do {                                                             \
    const std::string message_ = error_of(bytes);                  \
    EXPECT_NE(message_.find(text), std::string::npos) << message_; \
  } while (0)

// A small valid file exercising every reading path: normals, a camera element, a
// quad, an unknown element with a list.
std::string small_valid_binary() {
  PointCloud cloud;
  cloud.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 1, 0), Vec3f(0, 1, 0)};
  cloud.normals.assign(4, Vec3f(0, 0, 1));
  cloud.camera = {0, 1, kUnknownSource, 0};
  std::string s = kBinaryStart + "element vertex 4\n" + kXyz +
                  "property float nx\nproperty float ny\nproperty float nz\nproperty int camera\n"
                  "element face 2\nproperty list uchar int vertex_indices\n"
                  "element edge 1\nproperty list ushort short path\nproperty uchar tag\n"
                  "element camera 2\n" +
                  kXyz + "end_header\n";
  for (size_t i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) put_le(s, cloud.positions[i][k]);
    for (int k = 0; k < 3; ++k) put_le(s, cloud.normals[i][k]);
    put_le(s, cloud.camera[i]);
  }
  put_le(s, uint8_t{4});
  for (int32_t i : {0, 1, 2, 3}) put_le(s, i);
  put_le(s, uint8_t{3});
  for (int32_t i : {0, 2, 3}) put_le(s, i);
  put_le(s, uint16_t{2});
  put_le(s, int16_t{0});
  put_le(s, int16_t{3});
  put_le(s, uint8_t{1});
  for (float v : {10.0f, 20.0f, 30.0f, -10.0f, 20.0f, 30.0f}) put_le(s, v);
  return s;
}

TEST(PlyBadInputTest, SmallValidFileIsValid) {
  auto data = parse_ply(small_valid_binary());
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.size(), 4u);
  EXPECT_EQ(data->triangles.size(), 3u);
  EXPECT_EQ(data->cloud.camera_centres.size(), 2u);
}

TEST(PlyBadInputTest, EmptyFile) { EXPECT_ERROR_CONTAINS("", "empty file"); }

TEST(PlyBadInputTest, WrongMagic) {
  EXPECT_ERROR_CONTAINS("PLY\nformat ascii 1.0\n", "not a PLY file");
  EXPECT_ERROR_CONTAINS("ply", "not a PLY file");
  EXPECT_ERROR_CONTAINS("plyformat ascii 1.0\n", "not a PLY file");
  EXPECT_ERROR_CONTAINS("solid cube\nfacet normal 0 0 1\n", "not a PLY file");
  EXPECT_ERROR_CONTAINS(std::string("\x00\x01\x02\x03", 4), "not a PLY file");
}

TEST(PlyBadInputTest, NoEndHeader) {
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\n" + kXyz, "no end_header");
  EXPECT_ERROR_CONTAINS("ply\n", "no end_header");
  // Data where the header should have ended: the first data line is not a keyword.
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\n" + kXyz + "1 2 3\n",
                        "header line 7: unknown header keyword '1'");
}

TEST(PlyBadInputTest, BadHeaderLines) {
  EXPECT_ERROR_CONTAINS("ply\nformat binary_middle_endian 1.0\nend_header\n",
                        "header line 2: unsupported format 'binary_middle_endian'");
  EXPECT_ERROR_CONTAINS("ply\nformat ascii 2.0\nend_header\n", "unsupported PLY version");
  EXPECT_ERROR_CONTAINS("ply\nelement vertex 0\n" + kXyz + "end_header\n", "no format line");
  EXPECT_ERROR_CONTAINS(kAsciiStart + kAsciiStart.substr(4) + "end_header\n", "second format line");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex -3\n" + kXyz + "end_header\n",
                        "count '-3' is not a non-negative integer");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 18446744073709551616\n" + kXyz + "end_header\n",
                        "is not a non-negative integer");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\nproperty float32 x\nproperty float32 x\n",
                        "header line 5: element 'vertex' has two properties named 'x'");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "property float x\nend_header\n", "before any element");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\nproperty half x\nend_header\n",
                        "unknown property type 'half'");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element face 1\nproperty list float int vertex_indices\n",
                        "list count type 'float' is not an integer type");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 0\n" + kXyz + "element vertex 0\n" + kXyz + "end_header\n",
                        "declared twice");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\nproperty float x y\nend_header\n",
                        "expected 'property <type> <name>'");
}

TEST(PlyBadInputTest, MissingOrMisshapenVertexProperties) {
  EXPECT_ERROR_CONTAINS(kAsciiStart +
                            "element face 0\nproperty list uchar int vertex_indices\n"
                            "end_header\n",
                        "no 'vertex' element");
  EXPECT_ERROR_CONTAINS(kAsciiStart +
                            "element vertex 1\nproperty float x\nproperty float z\n"
                            "end_header\n1 2\n",
                        "has no property 'y'");
  EXPECT_ERROR_CONTAINS(kAsciiStart +
                            "element vertex 1\nproperty list uchar float x\n"
                            "property float y\nproperty float z\nend_header\n1 1 2 3\n",
                        "vertex property 'x' is a list");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\n" + kXyz + "property float nx\nend_header\n1 2 3 4\n",
                        "only some of the normal properties");
  EXPECT_ERROR_CONTAINS(
      kAsciiStart + "element vertex 1\n" + kXyz + "element face 1\nproperty int vertex_indices\nend_header\n1 2 3\n0\n",
      "must be a list");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\n" + kXyz +
                            "element face 1\nproperty list uchar float vertex_indices\n"
                            "end_header\n1 2 3\n3 0 0 0\n",
                        "vertex indices must be integers");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\n" + kXyz +
                            "element face 1\nproperty list uchar int corners\nend_header\n"
                            "1 2 3\n3 0 0 0\n",
                        "no 'vertex_indices' list");
}

// Every prefix of a valid binary file is a truncated file and must be refused.
TEST(PlyBadInputTest, TruncatedBinaryAtEveryLength) {
  const std::string full = small_valid_binary();
  for (size_t len = 0; len < full.size(); ++len) {
    auto data = parse_ply(std::string_view(full).substr(0, len), "cut.ply");
    ASSERT_FALSE(data.ok()) << "prefix of " << len << " bytes parsed";
    EXPECT_EQ(data.status().message().rfind("cut.ply: ", 0), 0u);
  }
}

// ASCII prefixes may be valid (cutting "1.25" to "1.2" leaves a number), so only
// require that none crashes and none claims more than the full file has.
TEST(PlyBadInputTest, TruncatedAsciiAtEveryLength) {
  PointCloud cloud;
  cloud.positions = {Vec3f(1.25f, 2, 3), Vec3f(4, 5, 6.5f)};
  cloud.camera = {0, 1};
  cloud.camera_centres = {Vec3f(1, 1, 1), Vec3f(2, 2, 2)};
  const std::string full = encode_ply(cloud, PlyFormat::kAscii);
  for (size_t len = 0; len < full.size(); ++len) {
    auto data = parse_ply(std::string_view(full).substr(0, len));
    if (data.ok()) {
      EXPECT_LE(data->cloud.size(), 2u);
      EXPECT_TRUE(data->cloud.is_consistent());
    }
  }
}

TEST(PlyBadInputTest, TruncationMessageNamesRecordAndOffset) {
  std::string s = kBinaryStart + "element vertex 5000\n" + kXyz + "end_header\n";
  const size_t header = s.size();
  s.append(12 * 1234 + 5, '\0');
  EXPECT_EQ(error_of(s), "bad.ply: truncated: vertex 1234 of 5000 needs 12 bytes at offset " +
                             std::to_string(header + 12 * 1234) + ", file has " + std::to_string(s.size()) + " bytes");
}

// A header claiming 2^40 records in a tiny file must be refused before anything is
// allocated for them (an allocation that size would throw or be killed).
TEST(PlyBadInputTest, HugeCountsInATinyFile) {
  const auto start = std::chrono::steady_clock::now();
  std::string tail(24, '\0');
  EXPECT_ERROR_CONTAINS(kBinaryStart + "element vertex 1099511627776\n" + kXyz + "end_header\n" + tail,
                        "truncated: vertex 2 of 1099511627776 needs 12 bytes");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1099511627776\n" + kXyz + "end_header\n" + "1 2 3\n",
                        "header declares 1099511627776 vertex records");
  // Faces and skipped elements are read record by record up to the first one cut off.
  std::string faces = kBinaryStart + "element vertex 1\n" + kXyz +
                      "element face 1099511627776\nproperty list uchar int vertex_indices\n"
                      "end_header\n" +
                      std::string(12, '\0');
  faces += std::string("\x03", 1) + std::string(12, '\0');
  EXPECT_ERROR_CONTAINS(faces, "face 1 of 1099511627776, property 'vertex_indices': truncated");
  EXPECT_ERROR_CONTAINS(kBinaryStart +
                            "element blob 18446744073709551615\n"
                            "property list uint uchar data\nelement vertex 0\n" +
                            kXyz + "end_header\n" + tail,
                        "blob 6 of 18446744073709551615, property 'data': truncated");
  EXPECT_ERROR_CONTAINS(
      kBinaryStart + "element camera 1099511627776\n" + kXyz + "element vertex 0\n" + kXyz + "end_header\n" + tail,
      "camera 2 of 1099511627776");
  // Failing fast is the point: far below what touching terabytes would take.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

std::string binary_triangle_file(int32_t a, int32_t b, int32_t c) {
  std::string s = kBinaryStart + "element vertex 3\n" + kXyz +
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) put_le(s, static_cast<float>(i));
  put_le(s, uint8_t{3});
  put_le(s, a);
  put_le(s, b);
  put_le(s, c);
  return s;
}

TEST(PlyBadInputTest, FaceIndexOutOfRange) {
  EXPECT_TRUE(parse_ply(binary_triangle_file(0, 1, 2)).ok());
  EXPECT_ERROR_CONTAINS(binary_triangle_file(0, 1, 3),
                        "face 0 of 1, property 'vertex_indices': vertex index 3 at offset");
  EXPECT_ERROR_CONTAINS(binary_triangle_file(0, -1, 2), "vertex index -1");
  EXPECT_ERROR_CONTAINS(binary_triangle_file(0, 1, 2147483647), "out of range");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 3\n" + kXyz +
                            "element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
                        "vertex index 7 on line 13 is out of range: the file has 3 vertices");
}

TEST(PlyBadInputTest, FacesWithTooFewCorners) {
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 3\n" + kXyz +
                            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                        "a face needs at least 3 corners, this one has 2");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 3\n" + kXyz +
                            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n0\n",
                        "this one has 0");
}

TEST(PlyBadInputTest, NegativeListCount) {
  std::string s = kBinaryStart + "element vertex 3\n" + kXyz +
                  "element face 1\nproperty list char int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) put_le(s, 0.0f);
  put_le(s, int8_t{-1});
  s.append(12, '\0');
  EXPECT_ERROR_CONTAINS(s, "negative list count -1");
  EXPECT_ERROR_CONTAINS(
      kAsciiStart + "element vertex 0\n" + kXyz + "element tags 1\nproperty list int uchar t\nend_header\n-5 1 2\n",
      "negative list count -5 on line 10");
}

TEST(PlyBadInputTest, ListCountLargerThanTheFile) {
  std::string s = kBinaryStart + "element vertex 3\n" + kXyz +
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) put_le(s, 0.0f);
  put_le(s, uint8_t{255});
  s.append(12, '\0');
  EXPECT_ERROR_CONTAINS(s, "truncated: a list of 255 int needs 1020 bytes");
  // The same on a list nobody reads, and in ASCII.
  std::string skipped =
      kBinaryStart + "element vertex 0\n" + kXyz + "element junk 1\nproperty list uint double j\nend_header\n";
  put_le(skipped, uint32_t{4000000000u});
  skipped.append(16, '\0');
  EXPECT_ERROR_CONTAINS(skipped, "truncated: a list of 4000000000 double");
  EXPECT_ERROR_CONTAINS(
      kAsciiStart + "element vertex 0\n" + kXyz + "element junk 1\nproperty list uchar int j\nend_header\n255 1 2 3\n",
      "cannot fit");
}

TEST(PlyBadInputTest, AsciiNonNumberToken) {
  const std::string head = kAsciiStart + "element vertex 2\n" + kXyz +
                           "property uchar camera\n"
                           "end_header\n";
  EXPECT_ERROR_CONTAINS(head + "1 2 3 0\n4 five 6 0\n",
                        "vertex 1 of 2, property 'y': 'five' on line 10 is not a number");
  EXPECT_ERROR_CONTAINS(head + "1 2 3 0\n4 5 6,5 0\n", "'6,5' on line 10 is not a number");
  EXPECT_ERROR_CONTAINS(head + "1 2 3 0.5\n4 5 6 0\n", "'0.5' on line 9 is not an integer");
  EXPECT_ERROR_CONTAINS(head + "1 2 3 256\n4 5 6 0\n", "does not fit the property's type uchar");
  EXPECT_ERROR_CONTAINS(head + "1 2 3 -1\n4 5 6 0\n", "does not fit");
  EXPECT_ERROR_CONTAINS(head + "1 2 3e999 0\n4 5 6 0\n", "'3e999' on line 9 is out of range");
  EXPECT_ERROR_CONTAINS(head + "1 2 3 0\n4 5 6 0 \x01\n", "extra value '\\x01'");
}

TEST(PlyBadInputTest, AsciiTooFewOrTooManyValues) {
  const std::string head = kAsciiStart + "element vertex 2\n" + kXyz + "end_header\n";
  EXPECT_ERROR_CONTAINS(head + "1 2\n3 4 5\n", "vertex 0 of 2, property 'z': line 8 ends before all values were read");
  // Fewer records than declared: refused before the vertices are allocated.
  EXPECT_ERROR_CONTAINS(head + "1 2 3\n",
                        "truncated: the header declares 2 vertex records of at least 5 bytes "
                        "each, but only 6 bytes are left");
  EXPECT_ERROR_CONTAINS(head + "1 2 3\n\n\n\n\n\n", "vertex 1 of 2, property 'x': unexpected end of file on line 14");
  EXPECT_ERROR_CONTAINS(head + "1 2 3\n4 5 6 7\n", "vertex 1 of 2: unexpected extra value '7' on line 9");
}

TEST(PlyBadInputTest, NonFiniteCoordinates) {
  const std::string head = kAsciiStart + "element vertex 1\n" + kXyz + "end_header\n";
  EXPECT_ERROR_CONTAINS(head + "1 nan 3\n", "vertex 0 of 1, property 'y': NaN on line 8");
  EXPECT_ERROR_CONTAINS(head + "1 2 -inf\n", "property 'z': infinite value");
  EXPECT_ERROR_CONTAINS(kAsciiStart +
                            "element vertex 1\nproperty double x\nproperty double y\n"
                            "property double z\nend_header\n1e300 0 0\n",
                        "outside float range");
  std::string s = kBinaryStart + "element vertex 2\n" + kXyz + "end_header\n";
  for (int i = 0; i < 4; ++i) put_le(s, 1.0f);
  put_le(s, std::numeric_limits<float>::quiet_NaN());
  put_le(s, 1.0f);
  EXPECT_ERROR_CONTAINS(s, "vertex 1 of 2, property 'y': NaN at offset");
  std::string n = kBinaryStart + "element vertex 1\n" + kXyz +
                  "property float nx\nproperty float ny\nproperty float nz\nend_header\n";
  for (float v : {1.0f, 2.0f, 3.0f, 0.0f, std::numeric_limits<float>::infinity(), 0.0f}) {
    put_le(n, v);
  }
  EXPECT_ERROR_CONTAINS(n, "property 'ny': infinite value");
}

TEST(PlyBadInputTest, CameraIdsMustIndexTheCentres) {
  const std::string head = kAsciiStart + "element vertex 2\n" + kXyz + "property int camera\n";
  EXPECT_ERROR_CONTAINS(head + "element camera 1\n" + kXyz + "end_header\n1 2 3 0\n1 2 3 1\n0 0 0\n",
                        "vertex 1 has camera id 1, but the file has 1 camera centres");
  EXPECT_ERROR_CONTAINS(head + "end_header\n1 2 3 0\n1 2 3 -2\n", "camera id -2");
  EXPECT_ERROR_CONTAINS(kAsciiStart + "element vertex 1\n" + kXyz + "property double camera\nend_header\n1 2 3 1.5\n",
                        "not a 32-bit integer");
}

TEST(PlyBadInputTest, BinaryIdsMustBe32BitIntegers) {
  std::string s = kBinaryStart + "element vertex 2\n" + kXyz + "property uint frame\nend_header\n";
  for (uint32_t frame : {7u, 3000000000u}) {
    for (int k = 0; k < 3; ++k) put_le(s, 1.0f);
    put_le(s, frame);
  }
  EXPECT_ERROR_CONTAINS(s,
                        "vertex 1 of 2, property 'frame': value 3000000000 is not a 32-bit "
                        "integer at offset " +
                            std::to_string(s.size() - 4));
  std::string d = kBinaryStart + "element vertex 1\n" + kXyz + "property double laser\nend_header\n";
  for (int k = 0; k < 3; ++k) put_le(d, 1.0f);
  put_le(d, 2.5);
  EXPECT_ERROR_CONTAINS(d, "property 'laser': value 2.5 is not a 32-bit integer");
}

// The first refused value in file order is reported, whichever property it is in.
TEST(PlyBadInputTest, FirstBadValueInFileOrderIsReported) {
  std::string s = kBinaryStart + "element vertex 3\n" + kXyz + "end_header\n";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (float v : {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, nan, 1.0f, nan, 1.0f}) put_le(s, v);
  EXPECT_ERROR_CONTAINS(s, "vertex 1 of 3, property 'z': NaN");
}

// Random corruption of a valid file: any outcome but a crash is acceptable, and
// whatever parses must be internally consistent.
TEST(PlyBadInputTest, RandomByteFlips) {
  const std::string valid = small_valid_binary();
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<size_t> position(0, valid.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> flips(1, 4);
  int parsed = 0;
  for (int iteration = 0; iteration < 2000; ++iteration) {
    std::string bytes = valid;
    for (int f = flips(rng); f > 0; --f) bytes[position(rng)] = static_cast<char>(byte(rng));
    auto data = parse_ply(bytes, "flipped.ply");
    if (!data.ok()) {
      EXPECT_EQ(data.status().message().rfind("flipped.ply: ", 0), 0u);
      continue;
    }
    ++parsed;
    EXPECT_TRUE(data->cloud.is_consistent());
    for (const Triangle& t : data->triangles) {
      for (uint32_t i : t) ASSERT_LT(i, data->cloud.size());
    }
  }
  // Flips inside float payloads leave the file valid; the test must reach both outcomes.
  EXPECT_GT(parsed, 0);
  EXPECT_LT(parsed, 2000);
}

// A header of `lines` element, property and comment lines after a vertex element,
// then end_header; every count is 0, so the file is valid whatever its length.
std::string long_header(int lines) {
  std::string s = kBinaryStart + "element vertex 0\n" + kXyz;
  for (int i = 0; i < lines; ++i) {
    if (i % 3 == 0)
      s += "element e" + std::to_string(i) + " 0\n";
    else if (i % 3 == 1)
      s += "property float p" + std::to_string(i) + "\n";
    else
      s += "comment line " + std::to_string(i) + "\n";
  }
  return s + "end_header\n";
}

TEST(PlyBadInputTest, OverlongHeaderIsRefused) {
  EXPECT_ERROR_CONTAINS(long_header(100000),
                        "header line 10001: no end_header within 10000 lines: the header is longer than any "
                        "real PLY file's");
}

TEST(PlyBadInputTest, LongHeaderUnderTheCapIsReadWithItsDuplicatesFound) {
  // 9,990 lines, under the cap: valid, and the duplicate checks still see names
  // declared thousands of lines apart.
  auto data = parse_ply(long_header(9980), "long.ply");
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.size(), 0u);

  std::string many = kBinaryStart + "element vertex 0\n" + kXyz + "element wide 0\n";
  for (int i = 0; i < 9000; ++i) many += "property uchar p" + std::to_string(i) + "\n";
  EXPECT_TRUE(parse_ply(many + "end_header\n").ok());
  // Line 9008 follows ply, format, vertex and its three properties, 'wide' (line 7)
  // and its 9,000 properties.
  EXPECT_ERROR_CONTAINS(many + "property int p17\nend_header\n",
                        "header line 9008: element 'wide' has two properties named 'p17'");
  // A property of the same name in another element is no duplicate.
  EXPECT_TRUE(parse_ply(many + "element other 0\nproperty int p17\nend_header\n").ok());
  EXPECT_ERROR_CONTAINS(many + "element wide 0\nend_header\n",
                        "header line 9008: element 'wide' is declared twice (also on line 7)");
}

TEST(PlyBadInputTest, WriteIntoMissingDirectory) {
  const std::string dir = testing::temp_dir();
  const std::string path = dir + "/missing/sub/points.ply";
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3)};
  Status st = write_ply(path, cloud);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), StatusCode::kIoError);
  EXPECT_NE(st.message().find(path), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("No such file or directory"), std::string::npos) << st.message();
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(PlyBadInputTest, ReadingADirectoryIsAnError) {
  auto data = read_ply(testing::temp_dir());
  ASSERT_FALSE(data.ok());
  EXPECT_EQ(data.status().code(), StatusCode::kIoError);
}

}  // namespace
}  // namespace bodyscan
