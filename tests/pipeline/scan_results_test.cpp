// What the scan job leaves on disk: the measurements document beside the mesh, and
// the cloud kept when the surface fails.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pipeline/scan_job.hpp"
#include "recon/io/ply.hpp"
#include "storage/formats/draco_files.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::pipeline {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(ScanResults, MeasurementsSitBesideTheMesh) {
  auto body = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
  ASSERT_TRUE(body.ok());
  ScanJobResult r;
  r.cloud.positions = body->vertices;  // any cloud will do
  r.mesh = *body;
  BodyMeasureOptions mo;
  mo.floor_y = -2;
  auto m = measure_body(r.mesh, mo);
  ASSERT_TRUE(m.ok()) << m.status().message();
  r.body = *m;
  const std::string dir = testing::temp_dir() + "/scan";
  ASSERT_TRUE(write_scan_results(r, dir).ok());
  const nlohmann::json j = read_json(dir + "/measurements.json");
  EXPECT_EQ(j["schema"], "bodyscan.measurements/1");
  EXPECT_EQ(j["file"], "mesh.ply");
  EXPECT_NEAR(j["floor_y_mm"].get<double>(), -2.0, 1e-9);
  ASSERT_EQ(j["measurements"].size(), m->measurements.size());
  for (size_t i = 0; i < m->measurements.size(); ++i) {
    EXPECT_EQ(j["measurements"][i]["name"], m->measurements[i].name);
    EXPECT_DOUBLE_EQ(j["measurements"][i]["value_mm"].get<double>(), m->measurements[i].value_mm);
  }
  EXPECT_EQ(j["landmarks"].size(), m->landmarks.size());
  EXPECT_TRUE(std::filesystem::exists(dir + "/mesh.ply"));
  EXPECT_FALSE(read_json(dir + "/scan.json").contains("surface_error"));
  // The browser's copy: a Draco glTF binary, checked on the way out.
  auto glb = storage::decode_glb(slurp(dir + "/mesh.glb"));
  ASSERT_TRUE(glb.ok()) << glb.status().message();
  EXPECT_EQ(glb->num_triangles(), body->num_triangles());
  const nlohmann::json info = read_json(dir + "/scan.json")["mesh_glb"];
  EXPECT_EQ(info["bytes"].get<size_t>(), std::filesystem::file_size(dir + "/mesh.glb"));
  EXPECT_LE(info["max_error_mm"].get<double>(), 0.5);
  EXPECT_EQ(info["triangles"].get<size_t>(), body->num_triangles());

  // A surface larger than the screen's budget is decimated for mesh.glb only.
  auto small = scan_result_files(r, SurfaceFile::kPly, 20000);
  ASSERT_TRUE(small.ok()) << small.status().message();
  auto shown = storage::decode_glb(small->results.at("mesh.glb"));
  ASSERT_TRUE(shown.ok()) << shown.status().message();
  EXPECT_LE(shown->num_triangles(), 20000u);
  EXPECT_GT(shown->num_triangles(), 18000u);
  EXPECT_TRUE(analyze_topology(*shown).closed());
  const nlohmann::json small_info = nlohmann::json::parse(small->results.at("scan.json"))["mesh_glb"];
  EXPECT_EQ(small_info["triangles"].get<size_t>(), shown->num_triangles());
  EXPECT_EQ(small_info["surface_triangles"].get<size_t>(), body->num_triangles());
  auto surface = parse_ply(small->results.at("mesh.ply"));
  ASSERT_TRUE(surface.ok());
  EXPECT_EQ(surface->triangles.size(), body->num_triangles()) << "the kept surface is the full one";
}

TEST(ScanResults, AFailedSurfaceKeepsTheCloudAndSaysWhy) {
  ScanJobResult r;
  r.cloud.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  r.surface_error = "the surface needs 31693330 bricks";
  r.measure_error = "";
  const std::string dir = testing::temp_dir() + "/scan";
  ASSERT_TRUE(write_scan_results(r, dir).ok());
  EXPECT_TRUE(std::filesystem::exists(dir + "/points.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/mesh.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/measurements.json"));
  const nlohmann::json s = read_json(dir + "/scan.json");
  EXPECT_EQ(s["surface_error"], r.surface_error);
  auto back = read_ply(dir + "/points.ply");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->cloud.positions.size(), 3u);
}

TEST(ScanResults, TheRawRecordReadsBackOrSaysWhatIsWrong) {
  ScanJobResult r;
  r.cloud.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  r.raw_record = {{"rig", "tiered"}, {"frames", 3}};
  r.raw_stripes = std::string("\x01\x00\x02stripes", 10);
  const std::string dir = testing::temp_dir() + "/scan";
  ASSERT_TRUE(write_scan_results(r, dir).ok());
  nlohmann::json record;
  std::string stripes;
  const Status back = read_raw_record(dir, &record, &stripes);
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(record, r.raw_record);
  EXPECT_EQ(stripes, r.raw_stripes);

  const Status none = read_raw_record(testing::temp_dir() + "/nowhere", &record, &stripes);
  EXPECT_EQ(none.code(), StatusCode::kNotFound);
  EXPECT_NE(none.message().find("no raw record"), std::string::npos);
  std::ofstream(dir + "/raw/" + kRawRecordFile, std::ios::trunc) << "{\"rig\": ";
  const Status torn = read_raw_record(dir, &record, &stripes);
  EXPECT_EQ(torn.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(torn.message().find("not JSON"), std::string::npos);
}

}  // namespace
}  // namespace bodyscan::pipeline
