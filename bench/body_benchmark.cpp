// Body-scale reconstruction benchmark (issue figures 2 and 3).
//
//   body_benchmark --body MESH.ply [--points N] [--noise MM] [--seed S]
//                  [--cloud-out PTS.ply] [--mesh-out OUT.ply] [--voxel V]
//   body_benchmark --body MESH.ply --evaluate OTHER.ply   (accuracy of any mesh)
//   body_benchmark --body MESH.ply [--points N ...] --oriented-out PTS.ply
//   body_benchmark --cloud SCAN.ply --oriented-out PTS.ply
//   ... [--json OUT.json]   the figures also as JSON (bench/json_figures.hpp)
//
// Samples N points uniformly by area from the true mesh, adds isotropic Gaussian
// noise, reconstructs with the defaults (no input normals), and reports wall time
// per stage, peak memory, and the distances output -> truth and truth -> output
// (mean, RMS, 95th percentile, max), plus the mesh's topology.
//
// --oriented-out writes the cloud (the sampled one, or --cloud's) with PCA normals
// of its 20 nearest neighbours, oriented as a scanner orients them: toward the
// camera that saw each point, or for a sampled cloud to the true surface's side;
// then stops. It is what a reconstruction that needs oriented normals (Screened
// Poisson) starts from; the time it takes is reported for that side's total.
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
#include "recon/spatial/knn_index.hpp"
#include "recon/surface/estimate_normals.hpp"
#include "recon/surface/orient_normals.hpp"
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

// Replaces cloud.normals by PCA normals of k = 20 neighbours, each turned toward
// the camera that saw its point, else to the side of `sides` (the true normals of
// a sampled cloud), and returns the seconds it took.
double orient_like_a_scanner(PointCloud& cloud, const std::vector<Vec3f>& sides) {
  const auto t0 = std::chrono::steady_clock::now();
  const KnnIndex index(cloud.positions);
  LocalFrames frames = estimate_normals(cloud.positions, index, NeighborGraph{}, EstimateNormalsOptions{.k = 20});
  if (cloud.has_cameras()) {
    orient_normals_toward_cameras(cloud, frames);
  } else {
    for (size_t i = 0; i < frames.normals.size() && i < sides.size(); ++i)
      if (frames.normals[i].dot(sides[i]) < 0) flip_frame(frames, i);
  }
  cloud.normals = std::move(frames.normals);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Writes the cloud; false (and says why) where it could not.
bool write_cloud(const std::string& path, const PointCloud& cloud) {
  const Status st = write_ply(path, cloud);
  if (!st.ok()) std::fprintf(stderr, "body_benchmark: %s\n", st.message().c_str());
  return st.ok();
}

}  // namespace

int main(int argc, char** argv) {
  std::string body, cloud_in, cloud_out, oriented_out, mesh_out, evaluate, json_out;
  size_t points = 1'000'000;
  double noise = 0.5;
  uint64_t seed = 1;
  ReconstructOptions opt;
  CommandLine cl("body_benchmark",
                 "usage: body_benchmark --body MESH.ply [--points N] [--noise MM] [--seed S] [--cloud-out F] "
                 "[--mesh-out F] [--evaluate MESH.ply] [--voxel V] [--sigma S] [--normal-sigma S] [--json OUT]\n"
                 "       body_benchmark (--body MESH.ply [--points N ...] | --cloud SCAN.ply) --oriented-out F\n");
  cl.option("--body", &body);
  cl.option("--points", integer_between(1, 1LL << 40, [&points](long long n) { points = static_cast<size_t>(n); }));
  cl.option("--noise", &noise);
  cl.option("--seed", &seed);
  cl.option("--cloud", &cloud_in);
  cl.option("--cloud-out", &cloud_out);
  cl.option("--oriented-out", &oriented_out);
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
  if (!cloud_in.empty()) {
    if (oriented_out.empty()) {
      std::fprintf(stderr, "body_benchmark: --cloud goes with --oriented-out\n");
      return 2;
    }
    auto scan = read_ply(cloud_in);
    if (!scan.ok() || !scan->cloud.has_cameras()) {
      std::fprintf(
          stderr, "body_benchmark: %s\n",
          scan.ok() ? "--cloud needs a scan's points (each with its camera)" : scan.status().message().c_str());
      return 1;
    }
    PointCloud& cloud = scan->cloud;
    record = {{"cloud", std::filesystem::path(cloud_in).filename().string()},
              {"points", cloud.size()},
              {"normals_seconds", orient_like_a_scanner(cloud, {})}};
    std::printf("normals         %zu points, PCA of 20 neighbours toward their cameras: %.2f s\n", cloud.size(),
                record["normals_seconds"].get<double>());
    return write_cloud(oriented_out, cloud) ? write() : 1;
  }
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

  PointCloud cloud = sample_mesh_uniform(*truth, points, seed, true);
  const std::vector<Vec3f> true_normals = std::move(cloud.normals);
  cloud.normals.clear();  // the reconstruction estimates its own
  add_gaussian_noise(cloud, noise, seed + 1);
  if (!cloud_out.empty() && !write_cloud(cloud_out, cloud)) return 1;
  if (!oriented_out.empty()) {
    PointCloud oriented = cloud;
    record = {{"cloud", "sampled"},
              {"points", cloud.size()},
              {"noise_mm", noise},
              {"normals_seconds", orient_like_a_scanner(oriented, true_normals)}};
    std::printf("normals         %zu points, PCA of 20 neighbours to the true side: %.2f s\n", oriented.size(),
                record["normals_seconds"].get<double>());
    return write_cloud(oriented_out, oriented) ? write() : 1;
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
