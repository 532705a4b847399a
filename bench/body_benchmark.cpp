// Body-scale reconstruction benchmark (issue figures 2 and 3).
//
//   body_benchmark --body MESH.ply [--points N] [--noise MM] [--seed S]
//                  [--cloud-out PTS.ply] [--mesh-out OUT.ply] [--voxel V]
//   body_benchmark --body MESH.ply --evaluate OTHER.ply   (accuracy of any mesh)
//   ... [--json OUT.json]   the figures also as JSON (bench/json_figures.hpp)
//
// Samples N points uniformly by area from the true mesh, adds isotropic Gaussian
// noise, reconstructs with the defaults (no input normals), and reports wall time
// per stage, peak memory, and the distances output -> truth and truth -> output
// (mean, RMS, 95th percentile, max), plus the mesh's topology.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "recon/geometry/mesh_distance.hpp"
#include "recon/geometry/sample_surface.hpp"
#include "recon/io/ply.hpp"
#include "recon/surface/reconstruct.hpp"

using namespace bodyscan;

namespace {

// Prints the mesh's distances to the truth both ways and its topology, and adds them
// to record.
void print_accuracy(const TriangleMesh& mesh, const TriangleMesh& truth, nlohmann::json& record) {
  const MeshComparison c = compare_meshes(mesh, truth, 1'000'000, 12345);
  auto row = [&record](const char* name, const char* key, const DistanceStats& d) {
    std::printf("%-16s mean %.3f  rms %.3f  p95 %.3f  p99 %.3f  max %.3f mm\n", name, d.mean, d.rms, d.p95, d.p99,
                d.max);
    record[key] = {{"mean", d.mean}, {"rms", d.rms}, {"p95", d.p95}, {"p99", d.p99}, {"max", d.max}};
  };
  row("output->truth", "output_to_truth_mm", c.output_to_truth);
  row("truth->output", "truth_to_output_mm", c.truth_to_output);
  const MeshTopology t = analyze_topology(mesh);
  std::printf(
      "topology        %zu vertices, %zu triangles, %zu components, %zu boundary edges, "
      "%zu non-manifold edges, Euler %ld\n",
      mesh.num_vertices(), mesh.num_triangles(), t.components, t.boundary_edges, t.non_manifold_edges,
      t.euler_characteristic);
  record["triangles"] = mesh.num_triangles();
  record["components"] = t.components;
  record["boundary_edges"] = t.boundary_edges;
  record["non_manifold_edges"] = t.non_manifold_edges;
  record["euler"] = t.euler_characteristic;
}

}  // namespace

int main(int argc, char** argv) {
  std::string body, cloud_out, mesh_out, evaluate, json_out;
  size_t points = 1'000'000;
  double noise = 0.5;
  uint64_t seed = 1;
  ReconstructOptions opt;
  CommandLine cl("body_benchmark",
                 "usage: body_benchmark --body MESH.ply [--points N] [--noise MM] [--seed S] [--cloud-out F] "
                 "[--mesh-out F] [--evaluate MESH.ply] [--voxel V] [--sigma S] [--normal-sigma S] [--json OUT]\n");
  cl.option("--body", &body);
  cl.option("--points", integer_between(1, 1LL << 40, [&points](long long n) { points = static_cast<size_t>(n); }));
  cl.option("--noise", &noise);
  cl.option("--seed", &seed);
  cl.option("--cloud-out", &cloud_out);
  cl.option("--mesh-out", &mesh_out);
  cl.option("--evaluate", &evaluate);
  cl.option("--voxel", &opt.voxel_size);
  cl.option("--sigma", &opt.sigma_scale);
  cl.option("--normal-sigma", &opt.normal_scale);
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);  // the tree as the run starts
  nlohmann::json record;
  const auto write = [&] {
    return json_out.empty() || bench::write_figures(json_out, run_info, nlohmann::json::array({record})) ? 0 : 1;
  };
  if (body.empty()) {
    std::fprintf(stderr, "body_benchmark: --body is required\n");
    return 2;
  }
  auto truth = read_ply_mesh(body);
  if (!truth.ok()) {
    std::fprintf(stderr, "body_benchmark: %s\n", truth.status().message().c_str());
    return 1;
  }
  if (!evaluate.empty()) {
    auto other = read_ply_mesh(evaluate);
    if (!other.ok()) {
      std::fprintf(stderr, "body_benchmark: %s\n", other.status().message().c_str());
      return 1;
    }
    std::printf("mesh            %s\n", evaluate.c_str());
    record["mesh"] = std::filesystem::path(evaluate).filename().string();
    print_accuracy(*other, *truth, record);
    return write();
  }

  PointCloud cloud = sample_mesh_uniform(*truth, points, seed, false);
  add_gaussian_noise(cloud, noise, seed + 1);
  if (!cloud_out.empty()) {
    const Status s = write_ply(cloud_out, cloud);
    if (!s.ok()) {
      std::fprintf(stderr, "body_benchmark: %s\n", s.message().c_str());
      return 1;
    }
  }
  std::printf("input           %zu points from %s, noise %.2f mm (per axis), no normals\n", cloud.size(), body.c_str(),
              noise);
  const auto t0 = std::chrono::steady_clock::now();
  auto r = reconstruct_surface(cloud, opt);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.ok()) {
    std::fprintf(stderr, "body_benchmark: %s\n", r.status().message().c_str());
    return 1;
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const ReconstructStats& s = r->stats;
  std::printf(
      "wall time       %.2f s (neighbours %.2f, normals %.2f, orientation %.2f, kernels %.2f, "
      "field %.2f, mesh %.2f)\n",
      wall, s.t_neighbours, s.t_normals, s.t_orientation, s.t_kernels, s.t_field, s.t_mesh);
  std::printf("peak memory     %.0f MB (whole process, includes the input and the truth mesh)\n",
              static_cast<double>(ru.ru_maxrss) / 1024.0);
  std::printf(
      "parameters      spacing %.3f mm, noise estimate %.3f mm, sigma %.2f, normal-sigma %.2f, "
      "voxel %.3f mm, normal-k %zu, %zu bricks (%.0f MB)\n",
      s.median_density_sigma, s.noise_sigma, s.sigma_scale, s.normal_scale, s.voxel_size, s.normal_k, s.bricks,
      static_cast<double>(s.field_bytes) / 1e6);
  record = {{"mesh", "bodyscan"},
            {"points", cloud.size()},
            {"noise_mm", noise},
            {"seconds", wall},
            {"stages_seconds",
             {{"neighbours", s.t_neighbours},
              {"normals", s.t_normals},
              {"orientation", s.t_orientation},
              {"kernels", s.t_kernels},
              {"field", s.t_field},
              {"mesh", s.t_mesh}}},
            {"peak_mb", static_cast<double>(ru.ru_maxrss) / 1024.0},
            {"spacing_mm", s.median_density_sigma},
            {"noise_estimate_mm", s.noise_sigma},
            {"voxel_mm", s.voxel_size},
            {"bricks", s.bricks},
            {"field_mb", static_cast<double>(s.field_bytes) / 1e6}};
  print_accuracy(r->mesh, *truth, record);
  if (!mesh_out.empty()) {
    const Status st = write_ply(mesh_out, r->mesh);
    if (!st.ok()) {
      std::fprintf(stderr, "body_benchmark: %s\n", st.message().c_str());
      return 1;
    }
  }
  return write();
}
