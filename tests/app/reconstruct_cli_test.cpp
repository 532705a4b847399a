// `bodyscan reconstruct` as a user runs it: the built executable, its exit codes,
// what it prints, and the mesh it writes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "recon/geometry/mesh_distance.hpp"
#include "recon/geometry/sample_surface.hpp"
#include "recon/io/ply.hpp"
#include "storage/formats/draco_files.hpp"
#include "tests/app/cli_runner.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

class ReconstructCli : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(BODYSCAN_BIN)) << "build the bodyscan target first: " << BODYSCAN_BIN;
    dir_ = testing::temp_dir();
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(ReconstructCli, ReconstructsASphere) {
  // 1000 points on a sphere of radius 50 mm, no normals, ASCII (as a user might hand in).
  PointCloud cloud = fibonacci_sphere(1000, 50.0);
  cloud.normals.clear();
  ASSERT_TRUE(write_ply(path("sphere.ply"), cloud, PlyFormat::kAscii).ok());
  const CliResult r = bodyscan("reconstruct " + quote(path("sphere.ply")) + " -o " + quote(path("mesh.ply")), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("points      1000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("normals     mst"), std::string::npos) << r.out;
  auto mesh = read_ply_mesh(path("mesh.ply"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  const MeshTopology t = analyze_topology(*mesh);
  EXPECT_TRUE(t.closed());
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 2);
  // The sphere's volume within 2%, wound outward.
  const double ball = 4.0 / 3.0 * std::numbers::pi * 50.0 * 50.0 * 50.0;
  EXPECT_NEAR(signed_volume(*mesh), ball, 0.02 * ball);
  // The printed triangle count is the file's.
  EXPECT_NE(r.out.find("triangles   " + std::to_string(mesh->num_triangles())), std::string::npos) << r.out;
  // Written with vertex normals, binary by default.
  EXPECT_EQ(mesh->normals.size(), mesh->vertices.size());
  EXPECT_NE(slurp(path("mesh.ply")).find("binary_little_endian"), std::string::npos);
}

TEST_F(ReconstructCli, ReconstructsTheShippedBody) {
  // The demo body as a bare cloud: 150k points, 0.5 mm noise, no normals.
  auto truth = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  PointCloud cloud = sample_mesh_uniform(*truth, 150000, 7, /*with_normals=*/false);
  add_gaussian_noise(cloud, 0.5, 8);
  ASSERT_TRUE(write_ply(path("body.ply"), cloud).ok());
  const CliResult r = bodyscan("reconstruct " + quote(path("body.ply")) + " -o " + quote(path("body_mesh.ply")), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("surface     closed, 1 component;"), std::string::npos) << r.out;
  auto mesh = read_ply_mesh(path("body_mesh.ply"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(analyze_topology(*mesh).closed());
  // Filled vertices are marked in the file.
  ASSERT_EQ(mesh->confidence.size(), mesh->vertices.size());
  // Within the noise of the truth over most of the skin (measured: RMS 0.39 mm,
  // 95th percentile 0.45 mm out->truth at this density).
  const MeshComparison d = compare_meshes(*mesh, *truth, 100000, 3);
  EXPECT_LT(d.output_to_truth.p95, 0.7);
  EXPECT_LT(d.truth_to_output.rms, 0.6);
  EXPECT_LT(std::abs(signed_volume(*mesh) / signed_volume(*truth) - 1.0), 0.02);

  // --keep-holes leaves the field's flaps open.
  const CliResult open =
      bodyscan("reconstruct " + quote(path("body.ply")) + " -o " + quote(path("open.ply")) + " --keep-holes", dir_);
  ASSERT_EQ(open.exit_code, 0) << open.err;
  EXPECT_NE(open.out.find("surface     open"), std::string::npos) << open.out;
}

TEST_F(ReconstructCli, QuietAsciiAndOptions) {
  PointCloud cloud = fibonacci_sphere(500, 1.0);
  ASSERT_TRUE(write_ply(path("s.ply"), cloud).ok());
  const CliResult r =
      bodyscan("reconstruct " + quote(path("s.ply")) + " --output " + quote(path("m.ply")) +
                   " --ascii -q --sigma 1.2 --normal-sigma 0.6 --normals mst --normal-k 15 --voxel 0.06",
               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_EQ(slurp(path("m.ply")).rfind("ply\nformat ascii 1.0", 0), 0u);
  auto mesh = read_ply_mesh(path("m.ply"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(analyze_topology(*mesh).closed());
}

TEST_F(ReconstructCli, BodyTakesTheScanJobsSettings) {
  // A sphere with its top quarter unseen (y > 0.5: 25 % of the area). The library's
  // default takes an opening that large for the surface's real edge and leaves it;
  // --body, like the scan job, fills every hole.
  PointCloud full = fibonacci_sphere(4000, 100.0);
  PointCloud cloud;
  for (size_t i = 0; i < full.size(); ++i) {
    if (full.positions[i].y() > 50.f) continue;
    cloud.positions.push_back(full.positions[i]);
    if (full.has_normals()) cloud.normals.push_back(full.normals[i]);
  }
  ASSERT_TRUE(write_ply(path("cap.ply"), cloud).ok());
  const CliResult plain = bodyscan("reconstruct " + quote(path("cap.ply")) + " -o " + quote(path("plain.ply")), dir_);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("surface     open"), std::string::npos) << plain.out;
  const CliResult body =
      bodyscan("reconstruct " + quote(path("cap.ply")) + " --body -o " + quote(path("body.ply")), dir_);
  ASSERT_EQ(body.exit_code, 0) << body.err;
  EXPECT_NE(body.out.find("surface     closed"), std::string::npos) << body.out;
  auto mesh = read_ply_mesh(path("body.ply"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(analyze_topology(*mesh).closed());
  // The thin plate continues the sphere over the cap: its top within 10 % of the radius.
  float top = -1e9f;
  for (const Vec3f& v : mesh->vertices) top = std::max(top, v.y());
  EXPECT_NEAR(top, 100.f, 10.f);

  // --trim-distance sets how far from every point a flap's vertex must lie to be
  // peeled before the filling: nearer, more of the flaps goes.
  auto trimmed = [&](const std::string& d) {
    const CliResult r = bodyscan(
        "reconstruct " + quote(path("cap.ply")) + " --body --trim-distance " + d + " -o " + quote(path("t.ply")), dir_);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("surface     closed"), std::string::npos) << r.out;
    const size_t at = r.out.find(" flap triangles trimmed");
    const size_t from = r.out.rfind(' ', at - 1);
    return at == std::string::npos ? -1L : std::stol(r.out.substr(from + 1, at - from - 1));
  };
  const long near = trimmed("0.5"), far = trimmed("50");
  EXPECT_GT(near, far);
  EXPECT_GE(far, 0);
  const CliResult bad =
      bodyscan("reconstruct " + quote(path("cap.ply")) + " --trim-distance 0 -o " + quote(path("t.ply")), dir_);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--trim-distance expects a positive number"), std::string::npos) << bad.err;
}

TEST_F(ReconstructCli, MissingInputNamesTheFile) {
  const std::string missing = path("no-such-cloud.ply");
  const CliResult r = bodyscan("reconstruct " + quote(missing) + " -o " + quote(path("out.ply")), dir_);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.exit_code, -1) << "did not exit normally";
  EXPECT_NE(r.err.find("no-such-cloud.ply"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
}

TEST_F(ReconstructCli, GarbageInputIsAnError) {
  {
    std::ofstream f(path("garbage.ply"), std::ios::binary);
    f << "this is not a PLY file\n\x01\x02\x03";
  }
  const CliResult r = bodyscan("reconstruct " + quote(path("garbage.ply")) + " -o " + quote(path("out.ply")), dir_);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.exit_code, -1) << "did not exit normally (crash?)";
  EXPECT_FALSE(r.err.empty());
  EXPECT_NE(r.err.find("garbage.ply"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
}

TEST_F(ReconstructCli, TooFewPointsIsAnError) {
  PointCloud cloud = fibonacci_sphere(5, 1.0);
  ASSERT_TRUE(write_ply(path("five.ply"), cloud).ok());
  const CliResult r = bodyscan("reconstruct " + quote(path("five.ply")) + " -o " + quote(path("out.ply")), dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("8 points"), std::string::npos) << r.err;
}

TEST_F(ReconstructCli, BadOptionValuesExitTwo) {
  PointCloud cloud = fibonacci_sphere(100, 1.0);
  ASSERT_TRUE(write_ply(path("s.ply"), cloud).ok());
  const std::string io = quote(path("s.ply")) + " -o " + quote(path("m.ply"));
  for (const std::string bad : {"--sigma abc", "--sigma -1", "--sigma 0", "--voxel nan", "--epsilon 1", "--epsilon 2",
                                "--normals sideways", "--sharpen -0.5", "--sigma 1x"}) {
    const CliResult r = bodyscan("reconstruct " + io + " " + bad, dir_);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_FALSE(r.err.empty()) << bad;
  }
  const CliResult r = bodyscan("reconstruct " + io + " --sigma abc", dir_);
  EXPECT_NE(r.err.find("--sigma"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("abc"), std::string::npos) << r.err;
  // A value missing at the end of the line.
  EXPECT_EQ(bodyscan("reconstruct " + io + " --sigma", dir_).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(path("m.ply")));
}

TEST_F(ReconstructCli, UsageErrorsExitTwo) {
  PointCloud cloud = fibonacci_sphere(100, 1.0);
  ASSERT_TRUE(write_ply(path("s.ply"), cloud).ok());
  const std::string in = quote(path("s.ply"));
  {
    const CliResult r = bodyscan("reconstruct " + in + " -o " + quote(path("m.ply")) + " --frobnicate", dir_);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--frobnicate"), std::string::npos) << r.err;
  }
  EXPECT_EQ(bodyscan("reconstruct " + in, dir_).exit_code, 2);                       // no output
  EXPECT_EQ(bodyscan("reconstruct -o " + quote(path("m.ply")), dir_).exit_code, 2);  // no input
  EXPECT_EQ(bodyscan("reconstruct " + in + " -o " + quote(path("m.off")), dir_).exit_code, 2);
  EXPECT_EQ(bodyscan("reconstruct " + in + " " + in + " -o " + quote(path("m.ply")), dir_).exit_code, 2);
  EXPECT_EQ(bodyscan("frobnicate", dir_).exit_code, 2);  // unknown command
  EXPECT_EQ(bodyscan("", dir_).exit_code, 2);            // no command
  EXPECT_FALSE(std::filesystem::exists(path("m.ply")));
}

TEST_F(ReconstructCli, WritesGlbObjAndStl) {
  PointCloud cloud = fibonacci_sphere(1000, 50.0);
  ASSERT_TRUE(write_ply(path("sphere.ply"), cloud).ok());
  const std::string in = quote(path("sphere.ply"));
  const CliResult ply = bodyscan("reconstruct " + in + " -q -o " + quote(path("m.ply")), dir_);
  ASSERT_EQ(ply.exit_code, 0) << ply.err;
  auto mesh = read_ply_mesh(path("m.ply"));
  ASSERT_TRUE(mesh.ok());
  const CliResult glb = bodyscan("reconstruct " + in + " -o " + quote(path("m.glb")), dir_);
  ASSERT_EQ(glb.exit_code, 0) << glb.err;
  EXPECT_NE(glb.out.find("largest vertex error"), std::string::npos) << glb.out;
  auto back = storage::decode_glb(slurp(path("m.glb")));
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->num_triangles(), mesh->num_triangles());
  // Half a millimetre of rounding on a 50 mm ball: the volume within 0.5 %.
  EXPECT_NEAR(signed_volume(*back), signed_volume(*mesh), 5e-3 * signed_volume(*mesh));
  for (const char* ext : {"obj", "stl"}) {
    const CliResult r = bodyscan("reconstruct " + in + " -q -o " + quote(path(std::string("m.") + ext)), dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_GT(std::filesystem::file_size(path(std::string("m.") + ext)), 10000u) << ext;
  }
  EXPECT_EQ(std::filesystem::file_size(path("m.stl")), 84 + 50 * mesh->num_triangles());
}

TEST_F(ReconstructCli, HelpExitsZero) {
  {
    const CliResult r = bodyscan("reconstruct --help", dir_);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("usage: bodyscan reconstruct"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--sigma"), std::string::npos);
  }
  {
    const CliResult r = bodyscan("--help", dir_);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("reconstruct"), std::string::npos) << r.out;
  }
  EXPECT_EQ(bodyscan("reconstruct -h", dir_).exit_code, 0);
}

}  // namespace
}  // namespace bodyscan
