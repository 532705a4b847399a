#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "recon/io/ply.hpp"
#include "storage/formats/draco_files.hpp"
#include "storage/formats/mesh_files.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan::storage {
namespace {

TriangleMesh body() {
  auto m = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
  EXPECT_TRUE(m.ok()) << m.status().message();
  return *m;
}

// The JSON chunk of a glTF binary (the header, then a JSON chunk, then BIN).
nlohmann::json glb_json(const std::string& glb) {
  uint32_t magic = 0, version = 0, json_len = 0, json_type = 0;
  std::memcpy(&magic, glb.data(), 4);
  std::memcpy(&version, glb.data() + 4, 4);
  std::memcpy(&json_len, glb.data() + 12, 4);
  std::memcpy(&json_type, glb.data() + 16, 4);
  EXPECT_EQ(magic, 0x46546C67u);  // "glTF"
  EXPECT_EQ(version, 2u);
  EXPECT_EQ(json_type, 0x4E4F534Au);  // "JSON"
  return nlohmann::json::parse(glb.substr(20, json_len));
}

TEST(Glb, ABodyComesBackWithinHalfAMillimetre) {
  const TriangleMesh mesh = body();
  auto e = encode_glb(mesh);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_LE(e->max_error_mm, 0.5);
  EXPECT_GT(e->max_error_mm, 0.0);  // quantised, so something moved
  EXPECT_EQ(e->triangles, mesh.num_triangles());
  // The decoded mesh, independently of what encode_glb measured: every vertex has
  // its original within half a millimetre, and the triangles still face outward
  // (the same signed volume).
  auto back = decode_glb(e->bytes);
  ASSERT_TRUE(back.ok());
  auto volume = [](const TriangleMesh& m) {
    double v = 0;
    for (const Triangle& t : m.triangles)
      v += m.vertices[t[0]].cast<double>().dot(m.vertices[t[1]].cast<double>().cross(m.vertices[t[2]].cast<double>()));
    return v / 6;
  };
  EXPECT_NEAR(volume(*back) / volume(mesh), 1.0, 1e-3);
  Eigen::Vector3f lo = back->vertices[0], hi = lo, tlo = mesh.vertices[0], thi = tlo;
  for (const Vec3f& v : back->vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  for (const Vec3f& v : mesh.vertices) tlo = tlo.cwiseMin(v), thi = thi.cwiseMax(v);
  EXPECT_LE((lo - tlo).cwiseAbs().maxCoeff(), 0.5f);
  EXPECT_LE((hi - thi).cwiseAbs().maxCoeff(), 0.5f);
  // glTF: metres, Y up, the Draco extension required.
  const nlohmann::json j = glb_json(e->bytes);
  EXPECT_EQ(j["asset"]["version"], "2.0");
  ASSERT_TRUE(j.contains("extensionsRequired"));
  EXPECT_NE(std::find(j["extensionsRequired"].begin(), j["extensionsRequired"].end(), "KHR_draco_mesh_compression"),
            j["extensionsRequired"].end());
  const nlohmann::json& pos = j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>()];
  EXPECT_NEAR(pos["max"][1].get<double>(), thi.y() / 1000.0, 1e-3);  // metres
  EXPECT_NEAR(pos["min"][1].get<double>(), tlo.y() / 1000.0, 1e-3);
}

TEST(Glb, ATighterErrorTakesMoreBitsAndBytes) {
  const TriangleMesh mesh = body();
  DracoOptions fine;
  fine.max_error_mm = 0.05;
  auto a = encode_glb(mesh), b = encode_glb(mesh, fine);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LE(b->max_error_mm, 0.05);
  EXPECT_GT(b->position_bits, a->position_bits);
  EXPECT_GT(b->bytes.size(), a->bytes.size());
}

TEST(Glb, BadInputGetsAClearError) {
  EXPECT_EQ(encode_glb(TriangleMesh{}).status().code(), StatusCode::kInvalidArgument);
  TriangleMesh broken = testing::icosphere(1, 100);
  broken.triangles[0][0] = 99999;
  EXPECT_EQ(encode_glb(broken).status().code(), StatusCode::kInvalidArgument);
  auto junk = decode_glb("glTF but not really");
  ASSERT_FALSE(junk.ok());
  EXPECT_NE(junk.status().message().find("not a glTF binary"), std::string::npos) << junk.status().message();
  // A file cut short.
  auto e = encode_glb(testing::icosphere(3, 100));
  ASSERT_TRUE(e.ok());
  EXPECT_FALSE(decode_glb(std::string_view(e->bytes).substr(0, e->bytes.size() / 2)).ok());
}

TEST(Drc, ACloudComesBackWithinHalfAMillimetre) {
  const TriangleMesh mesh = body();
  PointCloud cloud;
  cloud.positions = mesh.vertices;
  cloud.normals = mesh.normals;
  auto e = encode_drc(cloud);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_LE(e->max_error_mm, 0.5);
  auto back = decode_drc(e->bytes);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), cloud.size());
  EXPECT_LT(e->bytes.size(), cloud.size() * 12 / 3);  // well under a third of raw float positions
  EXPECT_FALSE(decode_drc("DRACO?").ok());
  EXPECT_EQ(encode_drc(PointCloud{}).status().code(), StatusCode::kInvalidArgument);
}

TEST(MeshDrc, TheArchivedSurfaceKeepsItsShapeAndConfidence) {
  TriangleMesh mesh = body();
  mesh.confidence.resize(mesh.num_vertices());
  for (size_t i = 0; i < mesh.num_vertices(); ++i) mesh.confidence[i] = static_cast<float>(i % 101) / 100.f;
  DracoOptions keep;
  keep.max_error_mm = 0.01;
  auto e = encode_mesh_drc(mesh, keep);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_LE(e->max_error_mm, 0.01);
  EXPECT_LT(e->bytes.size(), encode_ply(mesh, PlyFormat::kBinaryLittleEndian).size() / 5);
  auto back = decode_mesh_drc(e->bytes);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->num_triangles(), mesh.num_triangles());
  ASSERT_EQ(back->confidence.size(), back->num_vertices());
  // Confidence survives to 8 bits: match each decoded vertex to its original by position.
  std::map<std::tuple<int, int, int>, float> by_place;
  for (size_t i = 0; i < mesh.num_vertices(); ++i)
    by_place[{static_cast<int>(std::lround(mesh.vertices[i].x() * 10)),
              static_cast<int>(std::lround(mesh.vertices[i].y() * 10)),
              static_cast<int>(std::lround(mesh.vertices[i].z() * 10))}] = mesh.confidence[i];
  size_t matched = 0;
  for (size_t i = 0; i < back->num_vertices(); ++i) {
    const Vec3f& v = back->vertices[i];
    auto it = by_place.find({static_cast<int>(std::lround(v.x() * 10)), static_cast<int>(std::lround(v.y() * 10)),
                             static_cast<int>(std::lround(v.z() * 10))});
    if (it == by_place.end()) continue;
    ++matched;
    EXPECT_NEAR(back->confidence[i], it->second, 1.0 / 255 + 1e-6);
  }
  EXPECT_GT(matched, back->num_vertices() * 9 / 10);
  EXPECT_FALSE(decode_mesh_drc("not draco").ok());
}

TEST(MeshFiles, ObjAndStlCarryTheMeshExactly) {
  TriangleMesh m = testing::icosphere(2, 123.25);
  const std::string obj = encode_obj(m);
  std::istringstream in(obj);
  std::string line;
  size_t v = 0, f = 0;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) == 0) {
      float x, y, z;
      ASSERT_EQ(std::sscanf(line.c_str(), "v %f %f %f", &x, &y, &z), 3);
      EXPECT_EQ(Vec3f(x, y, z), m.vertices[v]);  // exact: the text round-trips the float
      ++v;
    } else if (line.rfind("f ", 0) == 0) {
      unsigned a, b, c;
      ASSERT_EQ(std::sscanf(line.c_str(), "f %u %u %u", &a, &b, &c), 3);
      EXPECT_EQ((Triangle{a - 1, b - 1, c - 1}), m.triangles[f]);
      ++f;
    }
  }
  EXPECT_EQ(v, m.num_vertices());
  EXPECT_EQ(f, m.num_triangles());

  const std::string stl = encode_stl(m);
  ASSERT_EQ(stl.size(), 84 + 50 * m.num_triangles());
  uint32_t n = 0;
  std::memcpy(&n, stl.data() + 80, 4);
  EXPECT_EQ(n, m.num_triangles());
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    float rec[12];
    std::memcpy(rec, stl.data() + 84 + 50 * t, sizeof rec);
    const Vec3f normal(rec[0], rec[1], rec[2]), a(rec[3], rec[4], rec[5]);
    EXPECT_EQ(a, m.vertices[m.triangles[t][0]]);
    EXPECT_NEAR(normal.norm(), 1.f, 1e-5f);
    EXPECT_GT(normal.dot(a), 0.f);  // a sphere's faces look outward
  }
  const std::string dir = ::testing::TempDir() + "/formats_test";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(write_obj(dir + "/m.obj", m).ok());
  ASSERT_TRUE(write_stl(dir + "/m.stl", m).ok());
  EXPECT_EQ(std::filesystem::file_size(dir + "/m.stl"), stl.size());
  EXPECT_FALSE(write_stl("/nonexistent-dir/m.stl", m).ok());
}

TEST(MeshFiles, AnObjInMetresIsTheSameMeshScaled) {
  const TriangleMesh m = testing::icosphere(1, 250);
  const std::string obj = encode_obj(m, ModelUnit::kMetre);
  EXPECT_EQ(obj.rfind("# bodyscan mesh, metres, Y up\n", 0), 0u);
  std::istringstream in(obj);
  std::string line;
  size_t v = 0;
  while (std::getline(in, line))
    if (line.rfind("v ", 0) == 0) {
      float x, y, z;
      ASSERT_EQ(std::sscanf(line.c_str(), "v %f %f %f", &x, &y, &z), 3);
      EXPECT_LT((1000.f * Vec3f(x, y, z) - m.vertices[v]).norm(), 1e-3f);
      ++v;
    }
  EXPECT_EQ(v, m.num_vertices());
}

TEST(PlainGlb, ABodyComesBackExactlyInPlainAccessors) {
  TriangleMesh mesh = body();
  mesh.normals = compute_vertex_normals(mesh);
  auto glb = encode_plain_glb(mesh);
  ASSERT_TRUE(glb.ok()) << glb.status().message();
  ASSERT_EQ(glb->size() % 4, 0u);
  uint32_t total = 0;
  std::memcpy(&total, glb->data() + 8, 4);
  EXPECT_EQ(total, glb->size());
  const nlohmann::json j = glb_json(*glb);
  EXPECT_EQ(j["asset"]["version"], "2.0");
  const nlohmann::json& prim = j["meshes"][0]["primitives"][0];
  EXPECT_FALSE(prim.contains("extensions"));  // no Draco: CAD tools read it
  EXPECT_FALSE(j.contains("extensionsRequired"));
  // The bounds glTF requires on positions, in metres.
  const nlohmann::json& pos = j["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const Vec3f& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(pos["min"][k].get<float>(), 0.001f * lo[k]);
    EXPECT_FLOAT_EQ(pos["max"][k].get<float>(), 0.001f * hi[k]);
  }
  auto back = decode_glb(*glb);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->num_vertices(), mesh.num_vertices());
  ASSERT_EQ(back->triangles, mesh.triangles);
  ASSERT_EQ(back->normals.size(), mesh.normals.size());
  float worst = 0;
  for (size_t i = 0; i < mesh.num_vertices(); ++i)
    worst = std::max(worst, (back->vertices[i] - mesh.vertices[i]).norm());
  EXPECT_LT(worst, 1e-3f);  // float metres and back
  EXPECT_FALSE(encode_plain_glb(TriangleMesh{}).ok());
  // A vertex without a normal (its triangles degenerate): the file carries none.
  TriangleMesh no_normal = mesh;
  no_normal.normals[0] = Vec3f::Zero();
  auto plain = encode_plain_glb(no_normal);
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(glb_json(*plain)["meshes"][0]["primitives"][0]["attributes"].contains("NORMAL"));
  // A plain GLB whose indices run past the vertices is refused, not read.
  std::string bad = *glb;
  const size_t indices_at = bad.size() - 12 * mesh.num_triangles();
  const uint32_t huge = 0xfffffff0u;
  std::memcpy(bad.data() + indices_at, &huge, 4);
  EXPECT_FALSE(decode_glb(bad).ok());
}

}  // namespace
}  // namespace bodyscan::storage
