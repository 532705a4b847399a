// PLY reading and writing on valid input: round trips, every encoding and scalar
// type, the shipped fixtures, and the layouts other writers produce.
#include "recon/io/ply.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

// Builds binary PLY bodies value by value in either byte order.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_endian_(big_endian) {}
  template <typename T>
  Bytes& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    const bool swap = big_endian_ == (std::endian::native == std::endian::little);
    if (swap) std::reverse(b, b + sizeof(T));
    data_.append(b, sizeof(T));
    return *this;
  }
  const std::string& str() const { return data_; }

 private:
  bool big_endian_;
  std::string data_;
};

PointCloud make_cloud_with_all_attributes() {
  PointCloud cloud;
  const int n = 50;
  for (int i = 0; i < n; ++i) {
    const float t = static_cast<float>(i);
    // Values that need all of a float's digits, to catch lossy ASCII formatting.
    cloud.positions.emplace_back(t * 1.1f + 0.1f, 1000.0f / (t + 3.0f), -t * 0.333333f);
    cloud.normals.push_back(Vec3f(std::sin(t), std::cos(t), 0.5f).normalized());
    cloud.intensity.push_back(t / 7.0f);
    cloud.confidence.push_back(1.0f / (1.0f + t));
    cloud.camera.push_back(i % 4 == 3 ? kUnknownSource : i % 3);
    cloud.laser.push_back(i % 5);
    cloud.frame.push_back(1000000 + i);
  }
  cloud.camera_centres = {Vec3f(1500.5f, 1200.25f, -30.0f), Vec3f(-1500.0f, 1100.0f, 20.0f),
                          Vec3f(0.0f, 2300.0f, 1700.125f)};
  return cloud;
}

void expect_same_cloud(const PointCloud& a, const PointCloud& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.confidence, b.confidence);
  EXPECT_EQ(a.camera, b.camera);
  EXPECT_EQ(a.laser, b.laser);
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.camera_centres, b.camera_centres);
}

TriangleMesh make_tetrahedron_with_normals() {
  TriangleMesh mesh;
  mesh.vertices = {Vec3f(0, 0, 0), Vec3f(10.5f, 0, 0), Vec3f(0, 10.25f, 0), Vec3f(0, 0, 10.125f)};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  mesh.normals = compute_vertex_normals(mesh);
  return mesh;
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  return names;
}

class PlyRoundTrip : public ::testing::TestWithParam<PlyFormat> {};

TEST_P(PlyRoundTrip, CloudWithEveryAttributeIsExact) {
  const PointCloud cloud = make_cloud_with_all_attributes();
  ASSERT_TRUE(cloud.is_consistent());
  auto data = parse_ply(encode_ply(cloud, GetParam()));
  ASSERT_TRUE(data.ok()) << data.status().message();
  expect_same_cloud(cloud, data->cloud);
  EXPECT_TRUE(data->triangles.empty());
}

TEST_P(PlyRoundTrip, CloudWithPositionsOnly) {
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3), Vec3f(-4.5f, 5e-8f, 6e20f)};
  auto data = parse_ply(encode_ply(cloud, GetParam()));
  ASSERT_TRUE(data.ok()) << data.status().message();
  expect_same_cloud(cloud, data->cloud);
}

TEST_P(PlyRoundTrip, EmptyCloud) {
  auto data = parse_ply(encode_ply(PointCloud{}, GetParam()));
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_TRUE(data->cloud.empty());
}

TEST_P(PlyRoundTrip, MeshWithNormalsThroughDisk) {
  const TriangleMesh mesh = make_tetrahedron_with_normals();
  const std::string dir = testing::temp_dir();
  const std::string path = dir + "/tetra.ply";
  ASSERT_TRUE(write_ply(path, mesh, GetParam()).ok());
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"tetra.ply"});  // no temporary left
  auto read = read_ply_mesh(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->vertices, mesh.vertices);
  EXPECT_EQ(read->triangles, mesh.triangles);
  EXPECT_EQ(read->normals, mesh.normals);
}

TEST_P(PlyRoundTrip, CloudThroughDiskOverwritesOldFile) {
  const std::string dir = testing::temp_dir();
  const std::string path = dir + "/points.ply";
  PointCloud first;
  first.positions = {Vec3f(1, 1, 1)};
  ASSERT_TRUE(write_ply(path, first, GetParam()).ok());
  const PointCloud second = make_cloud_with_all_attributes();
  ASSERT_TRUE(write_ply(path, second, GetParam()).ok());
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"points.ply"});
  auto read = read_ply(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  expect_same_cloud(second, read->cloud);
}

INSTANTIATE_TEST_SUITE_P(PlyFormats, PlyRoundTrip, ::testing::Values(PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii),
                         [](const auto& param_info) {
                           return param_info.param == PlyFormat::kAscii ? "Ascii" : "Binary";
                         });

TEST(PlyTest, EncodesTheDocumentedHeader) {
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3)};
  cloud.confidence = {0.5f};
  cloud.camera = {0};
  cloud.camera_centres = {Vec3f(0, 0, 0)};
  const std::string ascii = encode_ply(cloud, PlyFormat::kAscii);
  EXPECT_EQ(ascii,
            "ply\nformat ascii 1.0\ncomment bodyscan point cloud, mm, Y up\n"
            "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
            "property float confidence\nproperty int camera\n"
            "element camera 1\nproperty float x\nproperty float y\nproperty float z\n"
            "end_header\n1 2 3 0.5 0\n0 0 0\n");

  TriangleMesh mesh;
  mesh.vertices = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  mesh.triangles = {{0, 1, 2}};
  const std::string binary = encode_ply(mesh, PlyFormat::kBinaryLittleEndian);
  const std::string header =
      "ply\nformat binary_little_endian 1.0\n"
      "comment bodyscan mesh, mm, Y up, counter-clockwise seen from outside\n"
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  ASSERT_EQ(binary.substr(0, header.size()), header);
  EXPECT_EQ(binary.size(), header.size() + 3 * 12 + 13);
}

TEST(PlyTest, ReadsTheMaleBody) {
  auto mesh = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply");
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->num_vertices(), 53514u);
  EXPECT_EQ(mesh->num_triangles(), 107024u);
  EXPECT_TRUE(mesh->normals.empty());
  EXPECT_TRUE(mesh->is_consistent());
  // The README's stature: soles on Y = 0, top of the head at 1729.3 mm.
  float min_y = 1e9f, max_y = -1e9f;
  for (const Vec3f& v : mesh->vertices) {
    min_y = std::min(min_y, v.y());
    max_y = std::max(max_y, v.y());
  }
  EXPECT_NEAR(min_y, 0.0f, 0.05f);
  EXPECT_NEAR(max_y, 1729.3f, 0.05f);
}

TEST(PlyTest, ReadsTheBunny) {
  auto data = read_ply(testing::data_path("bunny.ply"));
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.size(), 1839u);
  EXPECT_EQ(data->triangles.size(), 3674u);
  for (const Triangle& t : data->triangles) {
    for (uint32_t i : t) EXPECT_LT(i, 1839u);
  }
}

TEST(PlyTest, MissingFileIsNotFound) {
  auto data = read_ply(testing::temp_dir() + "/no-such-file.ply");
  ASSERT_FALSE(data.ok());
  EXPECT_EQ(data.status().code(), StatusCode::kNotFound);
  EXPECT_NE(data.status().message().find("no-such-file.ply"), std::string::npos);
}

TEST(PlyTest, MeshReaderRejectsPointCloud) {
  const std::string path = testing::temp_dir() + "/cloud.ply";
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3)};
  ASSERT_TRUE(write_ply(path, cloud).ok());
  auto mesh = read_ply_mesh(path);
  ASSERT_FALSE(mesh.ok());
  EXPECT_NE(mesh.status().message().find("no faces"), std::string::npos);
}

// The same quad-and-triangle mesh in big-endian binary with double coordinates and
// in ASCII must read identically.
TEST(PlyTest, BigEndianMatchesAscii) {
  const double xyz[5][3] = {{0, 0, 0}, {1.5, 0, 0}, {1.5, 2.25, 0}, {0, 2.25, 0}, {0.75, 3, -1}};
  Bytes be(/*big_endian=*/true);
  for (const auto& p : xyz) be.put(p[0]).put(p[1]).put(p[2]).put(static_cast<int16_t>(-7));
  be.put(uint16_t{4}).put(int32_t{0}).put(int32_t{1}).put(int32_t{2}).put(int32_t{3});
  be.put(uint16_t{3}).put(int32_t{3}).put(int32_t{2}).put(int32_t{4});
  const std::string props =
      "property double x\nproperty double y\nproperty double z\nproperty short extra\n"
      "element face 2\nproperty list ushort int vertex_indices\nend_header\n";
  const std::string big = "ply\nformat binary_big_endian 1.0\nelement vertex 5\n" + props + be.str();
  const std::string ascii = "ply\nformat ascii 1.0\nelement vertex 5\n" + props +
                            "0 0 0 -7\n1.5 0 0 -7\n1.5 2.25 0 -7\n0 2.25 0 -7\n0.75 3 -1 -7\n4 0 1 2 3\n3 3 2 4\n";
  auto a = parse_ply(big, "big.ply");
  auto b = parse_ply(ascii, "ascii.ply");
  ASSERT_TRUE(a.ok()) << a.status().message();
  ASSERT_TRUE(b.ok()) << b.status().message();
  ASSERT_EQ(a->cloud.size(), 5u);
  EXPECT_EQ(a->cloud.positions, b->cloud.positions);
  EXPECT_EQ(a->triangles, b->triangles);
  EXPECT_EQ(a->cloud.positions[2], Vec3f(1.5f, 2.25f, 0.0f));
  const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}};
  EXPECT_EQ(a->triangles, expected);
}

TEST(PlyTest, PolygonsAreFanTriangulated) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 2 0\n-0.5 1.5 0\n"
      "4 0 1 2 3\n"
      "5 3 2 4 5 0\n";
  auto data = parse_ply(ply);
  ASSERT_TRUE(data.ok()) << data.status().message();
  const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}, {3, 4, 5}, {3, 5, 0}};
  EXPECT_EQ(data->triangles, expected);
}

// Every scalar type under both its names, with unknown properties, an unknown
// element with lists before the vertices, and comments, obj_info and CRLF lines.
TEST(PlyTest, EveryScalarTypeAndSkippedData) {
  const std::string header =
      "ply\r\n"
      "format binary_little_endian 1.0\r\n"
      "comment made by hand\r\n"
      "obj_info scanner test rig\r\n"
      "element material 2\r\n"
      "property uchar red\r\n"
      "property list uint double weights\r\n"
      "property list int8 uint16 tags\r\n"
      "element vertex 2\r\n"
      "property char x\r\n"
      "property uint8 y\r\n"
      "property short z\r\n"
      "property int16 a\r\n"
      "property ushort nx\r\n"
      "property uint16 ny\r\n"
      "property int32 nz\r\n"
      "property int b\r\n"
      "property uint intensity\r\n"
      "property uint32 c\r\n"
      "property float32 confidence\r\n"
      "property float d\r\n"
      "property float64 laser\r\n"
      "property double e\r\n"
      "property int8 camera\r\n"
      "property list uchar float normals_history\r\n"
      "property uint16 frame\r\n"
      "comment trailing comment\r\n"
      "end_header\r\n";
  Bytes b;
  // material 0: 2 weights, 1 tag; material 1: empty lists.
  b.put(uint8_t{9}).put(uint32_t{2}).put(1.0).put(2.0).put(int8_t{1}).put(uint16_t{7});
  b.put(uint8_t{10}).put(uint32_t{0}).put(int8_t{0});
  for (int i = 0; i < 2; ++i) {
    b.put(static_cast<int8_t>(-100 + i)).put(static_cast<uint8_t>(200 + i));
    b.put(static_cast<int16_t>(-30000 + i)).put(int16_t{5});
    b.put(uint16_t{1}).put(uint16_t{0}).put(int32_t{0}).put(int32_t{-5});
    b.put(static_cast<uint32_t>(4000000000u + i)).put(uint32_t{6});
    b.put(0.25f).put(7.0f).put(3.0).put(8.0).put(static_cast<int8_t>(i - 1));
    b.put(uint8_t{2}).put(1.0f).put(2.0f).put(static_cast<uint16_t>(65535 - i));
  }
  auto data = parse_ply(header + b.str());
  ASSERT_TRUE(data.ok()) << data.status().message();
  const PointCloud& c = data->cloud;
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.positions[0], Vec3f(-100, 200, -30000));
  EXPECT_EQ(c.positions[1], Vec3f(-99, 201, -29999));
  EXPECT_EQ(c.normals[1], Vec3f(1, 0, 0));
  EXPECT_EQ(c.intensity[0], 4000000000.0f);
  EXPECT_EQ(c.confidence, (std::vector<float>{0.25f, 0.25f}));
  EXPECT_EQ(c.laser, (std::vector<int32_t>{3, 3}));
  EXPECT_EQ(c.camera, (std::vector<int32_t>{-1, 0}));
  EXPECT_EQ(c.frame, (std::vector<int32_t>{65535, 65534}));
  EXPECT_TRUE(c.camera_centres.empty());
}

TEST(PlyTest, VertexIndexAliasAndSignedCountType) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list char short vertex_index\n"
      "property uchar flags\nend_header\n"
      "0 0 0\n\n1 0 0\n0 1 0\n"  // blank lines between records are fine
      "3 2 1 0 255\n";
  auto data = parse_ply(ply);
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->triangles, (std::vector<Triangle>{{2, 1, 0}}));
}

TEST(PlyTest, AsciiNumberSpellings) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty float y\n"
      "property float z\nproperty int camera\nend_header\n"
      "+1.5 -2e3\t3E-2 +4\n"
      "1e-320 0.000001 -0 1e2\n";
  auto data = parse_ply(ply);
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.positions[0], Vec3f(1.5f, -2000.0f, 0.03f));
  EXPECT_EQ(data->cloud.positions[1].x(), 0.0f);  // underflows to zero in float
  EXPECT_EQ(data->cloud.camera, (std::vector<int32_t>{4, 100}));
}

TEST(PlyTest, CameraElementGivesCentres) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar camera\n"
      "element camera 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "0 0 0 1\n1 1 1 0\n"
      "100 200 300\n-100 200 300\n";
  auto data = parse_ply(ply);
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.camera_centres, (std::vector<Vec3f>{Vec3f(100, 200, 300), Vec3f(-100, 200, 300)}));
  EXPECT_TRUE(data->cloud.has_cameras());
}

// VCG/MeshLab write a `camera` element with other properties; it is not ours.
TEST(PlyTest, ForeignCameraElementIsSkipped) {
  const std::string ply =
      "ply\nformat ascii 1.0\n"
      "element camera 1\nproperty float view_px\nproperty float view_py\nproperty float view_pz\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "1 2 3\n4 5 6\n";
  auto data = parse_ply(ply);
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_TRUE(data->cloud.camera_centres.empty());
  EXPECT_EQ(data->cloud.positions[0], Vec3f(4, 5, 6));
}

TEST(PlyTest, ZeroCountsAndHeaderOnlyFiles) {
  auto data = parse_ply(
      "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
      "property float y\nproperty float z\nelement face 0\n"
      "property list uchar int vertex_indices\nend_header");
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_TRUE(data->cloud.empty());
  EXPECT_TRUE(data->triangles.empty());
}

// Elements with no properties have zero-byte records: a huge count costs nothing.
TEST(PlyTest, ElementWithoutPropertiesIsSkipped) {
  Bytes b;
  b.put(1.0f).put(2.0f).put(3.0f);
  auto data = parse_ply(
      "ply\nformat binary_little_endian 1.0\nelement nothing 1099511627776\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n" +
      b.str());
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.positions[0], Vec3f(1, 2, 3));
}

TEST(PlyTest, TrailingBytesAfterTheLastElementAreIgnored) {
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3)};
  auto data = parse_ply(encode_ply(cloud, PlyFormat::kBinaryLittleEndian) + "\n");
  ASSERT_TRUE(data.ok()) << data.status().message();
  EXPECT_EQ(data->cloud.positions, cloud.positions);
}

TEST(PlyTest, RefusesToWriteInconsistentData) {
  const std::string dir = testing::temp_dir();
  PointCloud cloud;
  cloud.positions = {Vec3f(1, 2, 3), Vec3f(4, 5, 6)};
  cloud.intensity = {1.0f};
  Status st = write_ply(dir + "/cloud.ply", cloud);
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  TriangleMesh mesh;
  mesh.vertices = {Vec3f(0, 0, 0)};
  mesh.triangles = {{0, 0, 1}};
  st = write_ply(dir + "/mesh.ply", mesh);
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(files_in(dir).empty());
}

}  // namespace
}  // namespace bodyscan
