// How fast the simulated rig renders a full scan: every laser group of a shipped
// rig swept step by step, every camera grabbing each step (the frames are made and
// dropped, as a scan streams them), plus the calibration frames.
//
//   render_benchmark [--rig thesis|square|FILE] [--every N]
//
// Prints frames, wall time, frames per second and the time for the whole scan.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "hw/sim/sim_rig.hpp"

using namespace bodyscan;
using namespace bodyscan::hw;

int main(int argc, char** argv) {
  std::string rig_name = "thesis";
  int every = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--rig" && i + 1 < argc) rig_name = argv[++i];
    else if (a == "--every" && i + 1 < argc) every = std::max(1, std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "usage: render_benchmark [--rig thesis|square|FILE] [--every N]\n");
      return 2;
    }
  }
  auto path = rig_name.find(".json") != std::string::npos ? StatusOr<std::string>(rig_name) : shipped_rig_path(rig_name);
  if (!path.ok()) return std::fprintf(stderr, "%s\n", path.status().message().c_str()), 1;
  auto desc = load_rig_description(*path);
  if (!desc.ok()) return std::fprintf(stderr, "%s\n", desc.status().message().c_str()), 1;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto made = sim::SimulatedRig::create(*desc);
  if (!made.ok()) return std::fprintf(stderr, "%s\n", made.status().message().c_str()), 1;
  sim::SimulatedRig& rig = **made;
  Controller& ctl = rig.controller();
  LasersOff off(ctl);
  const auto t1 = Clock::now();
  size_t frames = 0;
  uint64_t checksum = 0;
  auto grab_all = [&] {
    for (size_t c = 0; c < rig.num_cameras(); ++c) {
      auto f = rig.camera(c).grab();
      if (!f.ok()) {
        std::fprintf(stderr, "%s\n", f.status().message().c_str());
        std::exit(1);
      }
      checksum += f->pixels[f->pixels.size() / 2];
      ++frames;
    }
  };
  (void)ctl.set_room_lights(true);
  grab_all();
  (void)ctl.set_room_lights(false);
  grab_all();
  (void)ctl.set_frame_lights(true);
  grab_all();
  (void)ctl.set_frame_lights(false);
  for (const auto& group : desc->laser_groups) {
    std::vector<int> ids;
    int steps = 0;
    for (const std::string& id : group)
      for (size_t i = 0; i < desc->lasers.size(); ++i)
        if (desc->lasers[i].id == id) {
          ids.push_back(static_cast<int>(i));
          (void)ctl.home(static_cast<int>(i));
          steps = std::max(steps, desc->lasers[i].max_step - desc->lasers[i].min_step + 1);
        }
    (void)ctl.all_lasers_off();
    grab_all();
    for (int k = 0; k < steps; k += every) {
      for (int i : ids) {
        const LaserDescription& l = desc->lasers[static_cast<size_t>(i)];
        (void)ctl.move_to(i, std::min(l.max_step, l.min_step + k));
        (void)ctl.set_laser(i, true);
      }
      grab_all();
    }
  }
  const auto t2 = Clock::now();
  const double setup = std::chrono::duration<double>(t1 - t0).count();
  const double scan = std::chrono::duration<double>(t2 - t1).count();
  const auto& cam = desc->cameras[0];
  std::printf("rig %s: %zu cameras of %dx%d, %zu lasers in %zu groups\n", desc->name.c_str(), desc->cameras.size(),
              cam.width, cam.height, desc->lasers.size(), desc->laser_groups.size());
  std::printf("set-up (subject, scene, pixel rays) %.2f s\n", setup);
  std::printf("%zu frames in %.2f s: %.1f frames/s, %.1f Mpixel/s (checksum %llu)\n", frames, scan, frames / scan,
              frames * cam.width * cam.height / scan / 1e6, static_cast<unsigned long long>(checksum));
  return 0;
}
