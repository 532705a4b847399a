// What the customer waits for: the time from a scan's last frame to its
// measurements and to the screen's mesh, per stage, and the peak memory.
//
//   latency_benchmark SCAN_DIR... [--repeat N] [--json OUT.json]
//
// SCAN_DIR is a folder `bodyscan scan` wrote (or an archived scan's version). Its
// raw record holds every frame's stripes; the benchmark replays them as the scan
// job meets them during the scan, then times what only starts once the last frame
// is in: the cloud finished (sweeps merged, the sway undone), the surface, the
// automatic set, and the scan's files as the workstation archives them (the
// screen's mesh.glb among them). The replay itself is reported apart: in a live
// scan it runs frame by frame while the lasers move. Each stage is the best of N
// runs; the peak RSS is the whole process's.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "core/json_text.hpp"
#include "pipeline/scan_job.hpp"
#include "recon/io/atomic_file.hpp"

using namespace bodyscan;

namespace {

struct Stages {
  double replay = 1e300, cloud = 1e300, surface = 1e300, measurements = 1e300, files = 1e300;
  void keep_best(const Stages& o) {
    replay = std::min(replay, o.replay);
    cloud = std::min(cloud, o.cloud);
    surface = std::min(surface, o.surface);
    measurements = std::min(measurements, o.measurements);
    files = std::min(files, o.files);
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> dirs;
  int repeat = 1;
  std::string json_out;
  CommandLine cl("latency_benchmark", "usage: latency_benchmark SCAN_DIR... [--repeat N] [--json OUT.json]\n");
  cl.rest("SCAN_DIR", &dirs);
  cl.option("--repeat", integer_between(1, 100, [&repeat](long long n) { repeat = static_cast<int>(n); }));
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (dirs.empty()) return cl.fail("name at least one SCAN_DIR");
  const nlohmann::json run_info = bench::run_record(argc, argv);
  nlohmann::json records = nlohmann::json::array();
  std::printf("%-28s %9s %8s %8s %9s %8s %8s | %12s %9s %9s\n", "scan", "points", "replay", "cloud", "surface",
              "measure", "files", "measurements", "mesh.glb", "triangles");
  for (const std::string& dir : dirs) {
    nlohmann::json record;
    std::string stripes;
    if (const Status raw = pipeline::read_raw_record(dir, &record, &stripes); !raw.ok()) {
      std::fprintf(stderr, "latency_benchmark: %s\n", raw.message().c_str());
      return 1;
    }
    Stages best;
    size_t points = 0, triangles = 0;
    for (int i = 0; i < repeat; ++i) {
      auto r = pipeline::reprocess_scan(record, stripes);
      if (!r.ok()) {
        std::fprintf(stderr, "latency_benchmark: %s: %s\n", dir.c_str(), r.status().message().c_str());
        return 1;
      }
      if (!r->surface_error.empty() || !r->body) {
        std::fprintf(stderr, "latency_benchmark: %s: no surface or measurements (%s%s)\n", dir.c_str(),
                     r->surface_error.c_str(), r->measure_error.c_str());
        return 1;
      }
      const auto t0 = std::chrono::steady_clock::now();
      auto files = pipeline::scan_result_files(*r, pipeline::SurfaceFile::kArchiveDraco);
      const double files_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!files.ok()) {
        std::fprintf(stderr, "latency_benchmark: %s: %s\n", dir.c_str(), files.status().message().c_str());
        return 1;
      }
      best.keep_best({r->scan_seconds - r->finish_seconds, r->finish_seconds, r->surface_seconds, r->measure_seconds,
                      files_seconds});
      points = r->cloud.size();
      triangles = r->mesh.triangles.size();
    }
    const double to_measurements = best.cloud + best.surface + best.measurements;
    const double to_glb = to_measurements + best.files;
    const std::string name = std::filesystem::path(dir).filename().string();
    std::printf("%-28s %9zu %7.2fs %7.2fs %8.2fs %7.2fs %7.2fs | %11.2fs %8.2fs %9zu\n", name.c_str(), points,
                best.replay, best.cloud, best.surface, best.measurements, best.files, to_measurements, to_glb,
                triangles);
    records.push_back({{"scan", name},
                       {"points", points},
                       {"triangles", triangles},
                       {"replay_seconds", best.replay},
                       {"after_last_frame_seconds",
                        {{"cloud", best.cloud},
                         {"surface", best.surface},
                         {"measurements", best.measurements},
                         {"files", best.files}}},
                       {"to_measurements_seconds", to_measurements},
                       {"to_glb_seconds", to_glb}});
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double peak_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
  std::printf("peak memory %.0f MB (whole process)\n", peak_mb);
  for (auto& r : records) r["peak_mb"] = peak_mb;
  return json_out.empty() || bench::write_figures(json_out, run_info, records) ? 0 : 1;
}
