// How fast the simulated rig renders a full scan: the scan sequence of
// pipeline/acquire (every laser group swept step by step, every camera
// grabbing each step; the frames are made and dropped, as a scan streams them), and
// separately the calibration sequence (the dot grid before each camera, the frame
// lights, each laser alone).
//
//   render_benchmark [--rig thesis|square|FILE] [--every N] [--sway MM] [--json OUT.json]
//
// --sway makes the subject sway (docs/simulated-rig.md), so every frame is posed
// and cast anew.
//
// Prints frames, wall time, frames per second and the time for the whole scan;
// --json also writes them (bench/json_figures.hpp) for bench/tables.py.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "hw/sim/sim_rig.hpp"
#include "pipeline/acquire.hpp"
#include "pipeline/rig_backend.hpp"

using namespace bodyscan;

int main(int argc, char** argv) {
  std::string rig_name = "thesis";
  int every = 1;
  double sway = 0;
  std::string json_out;
  CommandLine cl("render_benchmark",
                 "usage: render_benchmark [--rig thesis|square|FILE] [--every N] [--sway MM] [--json OUT]\n");
  cl.option("--rig", &rig_name);
  cl.option("--every", integer_between(1, 1000000, [&every](long long n) { every = static_cast<int>(n); }));
  cl.option("--sway", &sway);
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);  // the tree as the run starts
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto sim = pipeline::open_simulated_rig(rig_name);
  if (!sim.ok()) return std::fprintf(stderr, "%s\n", sim.status().message().c_str()), 1;
  if (sway > 0) {
    // The same description, its subject swaying.
    auto path = rig_name.find('/') == std::string::npos && rig_name.find(".json") == std::string::npos
                    ? hw::shipped_rig_path(rig_name)
                    : StatusOr<std::string>(rig_name);
    if (!path.ok()) return std::fprintf(stderr, "%s\n", path.status().message().c_str()), 1;
    auto d = hw::load_rig_description(*path);
    if (!d.ok()) return std::fprintf(stderr, "%s\n", d.status().message().c_str()), 1;
    d->simulation.motion.sway_mm = sway;
    sim = hw::sim::SimulatedRig::create(*d);
    if (!sim.ok()) return std::fprintf(stderr, "%s\n", sim.status().message().c_str()), 1;
  }
  const pipeline::Rig rig = pipeline::rig_handle(**sim);
  const hw::RigDescription& desc = *rig.description;
  size_t frames = 0;
  uint64_t checksum = 0;
  const pipeline::ShotSink count = [&](pipeline::Shot&& s) {
    checksum += s.frame.pixels[s.frame.pixels.size() / 2];
    ++frames;
    return Status();
  };
  const auto t1 = Clock::now();
  Status s = pipeline::acquire_calibration(rig, count);
  if (!s.ok()) return std::fprintf(stderr, "%s\n", s.message().c_str()), 1;
  const size_t calibration_frames = frames;
  const auto t2 = Clock::now();
  s = pipeline::acquire_scan(rig, count, every);
  if (!s.ok()) return std::fprintf(stderr, "%s\n", s.message().c_str()), 1;
  const auto t3 = Clock::now();
  auto secs = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  const size_t scan_frames = frames - calibration_frames;
  const auto& cam = desc.cameras[0];
  if (sway > 0) std::printf("the subject sways %.1f mm\n", sway);
  std::printf("rig %s: %zu cameras of %dx%d, %zu lasers in %zu groups, %.0f frames/s cameras\n", desc.name.c_str(),
              desc.cameras.size(), cam.width, cam.height, desc.lasers.size(), desc.laser_groups.size(),
              desc.simulation.frame_rate_hz);
  std::printf("set-up (subject, scene, pixel rays) %.2f s\n", secs(t0, t1));
  std::printf("calibration: %zu frames in %.2f s (dot grids at 4 x 4 rays per pixel)\n", calibration_frames,
              secs(t1, t2));
  std::printf("scan: %zu frames in %.2f s: %.1f frames/s, %.1f Mpixel/s; the cameras take %.1f s (checksum %llu)\n",
              scan_frames, secs(t2, t3), scan_frames / secs(t2, t3),
              scan_frames * cam.width * cam.height / secs(t2, t3) / 1e6,
              scan_frames / static_cast<double>(desc.cameras.size()) / desc.simulation.frame_rate_hz,
              static_cast<unsigned long long>(checksum));
  const nlohmann::json record = {
      {"rig", desc.name},
      {"every", every},
      {"sway_mm", sway},
      {"calibration_frames", calibration_frames},
      {"calibration_seconds", secs(t1, t2)},
      {"scan_frames", scan_frames},
      {"scan_seconds", secs(t2, t3)},
      {"cameras_seconds", scan_frames / static_cast<double>(desc.cameras.size()) / desc.simulation.frame_rate_hz}};
  if (!json_out.empty() && !bench::write_figures(json_out, run_info, nlohmann::json::array({record}))) return 1;
  return 0;
}
