// Hole filling on a real open surface (issue 5: the square rig's feet).
//
//   hole_fill_benchmark IN.ply [--max-dp N ...] [--membrane] [--repeat R]
//                       [--save-open OPEN.ply] [--out FILLED.ply] [--min-weight W] [--json OUT.json]
//
// IN.ply is either a scan's point cloud, e.g. from
//   bodyscan scan --rig square --body male_average.ply --out S --no-surface
// which is surfaced as a scan's is (the body options) up to the holes: the field's
// zero set with its flaps trimmed back to the data, saved with --save-open (W:
// ReconstructOptions::min_relative_weight, to see what the weight cut opens); or
// such an open mesh (a PLY with faces), filled directly.
// For each --max-dp limit (the longest loop the minimum-dihedral programme takes
// whole; several may be given, compared in one run) it fills a fresh copy of the
// mesh R times and prints the best wall time, the loops, what was added, and a
// checksum of the result (equal checksums: the same triangulation), so a faster
// programme can be shown to fill exactly as before. --json also writes each limit's
// figures (bench/json_figures.hpp) for bench/tables.py.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "pipeline/scan_job.hpp"
#include "recon/geometry/fill_holes.hpp"
#include "recon/io/ply.hpp"
#include "recon/surface/reconstruct.hpp"

using namespace bodyscan;

namespace {

// FNV-1a over the triangles and the vertex positions' bits.
uint64_t checksum(const TriangleMesh& mesh) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* data, size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  mix(mesh.triangles.data(), mesh.triangles.size() * sizeof(Triangle));
  mix(mesh.vertices.data(), mesh.vertices.size() * sizeof(Vec3f));
  return h;
}

// The scan's surface before fill_holes: reconstruct_surface with the body options,
// its flaps trimmed and its holes left open.
StatusOr<TriangleMesh> open_surface(const PointCloud& cloud, float min_relative_weight) {
  ReconstructOptions ro = pipeline::with_scan_normals(pipeline::body_surface_options(), cloud);
  if (min_relative_weight >= 0.f) ro.min_relative_weight = min_relative_weight;
  ro.leave_trimmed_holes_open = true;
  ro.min_component_fraction = 0.0;  // after the filling, as in the pipeline
  ASSIGN_OR_RETURN(ReconstructResult r, reconstruct_surface(cloud, ro));
  std::printf("surfaced %zu points at %.2f voxels in %.1f s; %zu flap triangles trimmed\n", cloud.size(),
              r.stats.voxel_size, r.stats.total_seconds(), r.stats.flap_triangles_trimmed);
  return std::move(r.mesh);
}

}  // namespace

int main(int argc, char** argv) {
  std::string in, out, save_open, json_out;
  std::vector<size_t> limits;
  int repeat = 1;
  float min_weight = -1.f;  // the body options' own
  HoleFillOptions options;
  options.fairing = pipeline::body_surface_options().hole_fairing;
  bool membrane = false;
  CommandLine cl("hole_fill_benchmark",
                 "usage: hole_fill_benchmark IN.ply [--max-dp N ...] [--membrane] [--repeat R] [--save-open "
                 "OPEN.ply] [--out FILLED.ply] [--min-weight W] [--json OUT]\n");
  cl.positional("IN.ply", &in, /*required=*/false);
  cl.option("--max-dp",
            integer_between(1, 1LL << 40, [&limits](long long n) { limits.push_back(static_cast<size_t>(n)); }));
  cl.option("--repeat", integer_between(1, 1000000, [&repeat](long long n) { repeat = static_cast<int>(n); }));
  cl.flag("--membrane", &membrane);
  cl.option("--out", &out);
  cl.option("--save-open", &save_open);
  cl.option("--min-weight", &min_weight);
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);  // the tree as the run starts
  if (membrane) options.fairing = HoleFairing::kMembrane;
  if (in.empty()) {
    std::fprintf(stderr, "hole_fill_benchmark: no input mesh\n");
    return 2;
  }
  if (limits.empty()) limits.push_back(HoleFillOptions{}.max_dp_edges);
  auto loaded = read_ply(in);
  if (!loaded.ok()) {
    std::fprintf(stderr, "hole_fill_benchmark: %s\n", loaded.status().message().c_str());
    return 1;
  }
  TriangleMesh open;
  if (loaded->triangles.empty()) {
    auto surfaced = open_surface(loaded->cloud, min_weight);
    if (!surfaced.ok()) {
      std::fprintf(stderr, "hole_fill_benchmark: %s\n", surfaced.status().message().c_str());
      return 1;
    }
    open = std::move(surfaced).value();
    if (!save_open.empty()) {
      const Status s = write_ply(save_open, open);
      if (!s.ok()) std::fprintf(stderr, "hole_fill_benchmark: %s\n", s.message().c_str());
    }
  } else {
    open.vertices = std::move(loaded->cloud.positions);
    open.triangles = std::move(loaded->triangles);
  }
  std::printf("%s: %zu vertices, %zu triangles\n", in.c_str(), open.num_vertices(), open.num_triangles());
  const float weight = min_weight >= 0.f ? min_weight : pipeline::body_surface_options().min_relative_weight;
  nlohmann::json records = nlohmann::json::array();
  for (size_t limit : limits) {
    options.max_dp_edges = limit;
    double best = 1e300;
    TriangleMesh filled;
    HoleFillStats stats;
    for (int r = 0; r < repeat; ++r) {
      filled = open;
      const auto t0 = std::chrono::steady_clock::now();
      stats = fill_holes(filled, options);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf(
        "max_dp %5zu: %8.3f s  loops %zu filled %zu longest %zu  +%zu triangles +%zu vertices  "
        "area %.0f  checksum %016llx\n",
        limit, best, stats.holes, stats.holes_filled, stats.largest_hole_edges, stats.triangles_added,
        stats.vertices_added, stats.area_added, static_cast<unsigned long long>(checksum(filled)));
    records.push_back({{"input", std::filesystem::path(in).filename().string()},
                       {"surfaced", loaded->triangles.empty()},
                       {"min_relative_weight", weight},
                       {"open_triangles", open.num_triangles()},
                       {"max_dp", limit},
                       {"repeat", repeat},
                       {"seconds", best},
                       {"loops", stats.holes},
                       {"filled", stats.holes_filled},
                       {"longest_edges", stats.largest_hole_edges},
                       {"triangles_added", stats.triangles_added},
                       {"area_mm2", stats.area_added}});
    if (!out.empty() && limit == limits.back()) {
      const Status s = write_ply(out, filled);
      if (!s.ok()) {
        std::fprintf(stderr, "hole_fill_benchmark: %s\n", s.message().c_str());
        return 1;
      }
    }
  }
  if (!json_out.empty() && !bench::write_figures(json_out, run_info, records)) return 1;
  return 0;
}
