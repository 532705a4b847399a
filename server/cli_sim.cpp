// `bodyscan sim render`: the images the simulated rig's cameras take during one
// calibration and one full scan, as PNG files with a JSON index, so a person can
// look at what the cameras see.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

#include "hw/controller.hpp"
#include "hw/sim/sim_rig.hpp"
#include "recon/io/atomic_file.hpp"
#include "recon/io/png_image.hpp"
#include "recon/io/ply.hpp"

namespace bodyscan::cli {

namespace {

void usage(FILE* out) {
  std::fputs(
      "usage: bodyscan sim render --rig RIG --out DIR [options]\n"
      "\n"
      "Renders what the simulated rig's cameras see during one calibration (the\n"
      "dot-grid target before each camera, room lights, frame lights off and on) and\n"
      "one full scan (per laser group: a base frame with the lasers off, then every\n"
      "step with the group's lasers on), as PNG images in DIR with DIR/index.json\n"
      "listing them.\n"
      "\n"
      "  --rig RIG        thesis, square, or a rig description file (JSON)\n"
      "  --body BODY.ply  the subject (default: the rig description's)\n"
      "  --out DIR        output folder (created)\n"
      "  --every N        render every Nth laser step only (default 1)\n"
      "  -q, --quiet      print only errors\n",
      out);
}

}  // namespace

int run_sim(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (std::string(argv[1]) != "render") {
    std::fprintf(stderr, "bodyscan sim: unknown subcommand '%s' (known: render)\n", argv[1]);
    return 2;
  }
  std::string rig_arg, body, out;
  int every = 1;
  bool quiet = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bodyscan sim render: %s needs a value\n", a.c_str());
        return nullptr;
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--rig") {
      const char* v = value();
      if (!v) return 2;
      rig_arg = v;
    } else if (a == "--body") {
      const char* v = value();
      if (!v) return 2;
      body = v;
    } else if (a == "--out") {
      const char* v = value();
      if (!v) return 2;
      out = v;
    } else if (a == "--every") {
      const char* v = value();
      if (!v) return 2;
      every = std::atoi(v);
      if (every < 1) {
        std::fprintf(stderr, "bodyscan sim render: --every expects a positive integer, got '%s'\n", v);
        return 2;
      }
    } else if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else {
      std::fprintf(stderr, "bodyscan sim render: unknown option '%s'\n", a.c_str());
      return 2;
    }
  }
  if (rig_arg.empty() || out.empty()) {
    std::fprintf(stderr, "bodyscan sim render: --rig and --out are required\n");
    usage(stderr);
    return 2;
  }
  std::string rig_path = rig_arg;
  if (rig_arg.find('/') == std::string::npos && rig_arg.find(".json") == std::string::npos) {
    auto shipped = hw::shipped_rig_path(rig_arg == "sim" ? "thesis" : rig_arg);
    if (!shipped.ok()) {
      std::fprintf(stderr, "bodyscan sim render: %s\n", shipped.status().message().c_str());
      return 1;
    }
    rig_path = *shipped;
  }
  auto desc = hw::load_rig_description(rig_path);
  if (!desc.ok()) {
    std::fprintf(stderr, "bodyscan sim render: %s\n", desc.status().message().c_str());
    return 1;
  }
  StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> made = [&]() -> StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> {
    if (body.empty()) return hw::sim::SimulatedRig::create(*desc);
    ASSIGN_OR_RETURN(TriangleMesh mesh, read_ply_mesh(body));
    return hw::sim::SimulatedRig::create(*desc, mesh);
  }();
  if (!made.ok()) {
    std::fprintf(stderr, "bodyscan sim render: %s\n", made.status().message().c_str());
    return 1;
  }
  hw::sim::SimulatedRig& rig = **made;
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "bodyscan sim render: cannot create '%s': %s\n", out.c_str(), ec.message().c_str());
    return 1;
  }

  hw::Controller& ctl = rig.controller();
  hw::LasersOff lasers_off(ctl);  // whatever happens below
  nlohmann::json index;
  index["rig"] = desc->name;
  index["cameras"] = nlohmann::json::array();
  for (size_t c = 0; c < rig.num_cameras(); ++c) {
    index["cameras"].push_back({{"id", rig.camera(c).info().id},
                                {"width", rig.camera(c).info().width},
                                {"height", rig.camera(c).info().height}});
  }
  index["images"] = nlohmann::json::array();
  size_t written = 0;
  // Grabs camera c and writes its frame; false after printing an error.
  auto grab_one = [&](size_t c, const std::string& phase, const std::string& name, const nlohmann::json& lasers) {
    hw::Camera& cam = rig.camera(c);
    auto frame = cam.grab();
    if (!frame.ok()) {
      std::fprintf(stderr, "bodyscan sim render: %s\n", frame.status().message().c_str());
      return false;
    }
    const std::string file = phase + "/" + cam.info().id + "/" + name + ".png";
    std::filesystem::create_directories(std::filesystem::path(out) / phase / cam.info().id, ec);
    GrayImage img{frame->width, frame->height, hw::bits_per_pixel(frame->format) > 8 ? 16 : 8, std::move(frame->pixels)};
    const Status w = write_png((std::filesystem::path(out) / file).string(), img);
    if (!w.ok()) {
      std::fprintf(stderr, "bodyscan sim render: %s\n", w.message().c_str());
      return false;
    }
    index["images"].push_back({{"file", file},
                               {"camera", cam.info().id},
                               {"phase", phase},
                               {"name", name},
                               {"lasers", lasers},
                               {"frame_id", frame->frame_id},
                               {"timestamp_ns", frame->timestamp_ns}});
    ++written;
    return true;
  };
  auto grab_all = [&](const std::string& phase, const std::string& name, const nlohmann::json& lasers) {
    for (size_t c = 0; c < rig.num_cameras(); ++c)
      if (!grab_one(c, phase, name, lasers)) return false;
    return true;
  };
  auto check = [&](const Status& s) {
    if (!s.ok()) std::fprintf(stderr, "bodyscan sim render: %s\n", s.message().c_str());
    return s.ok();
  };

  // Calibration: the dot grid held before each camera in turn (thesis §3.1.1), the
  // room, then the frame lights off and on (thesis §3.1.2).
  if (!check(ctl.set_room_lights(true))) return 1;
  for (size_t c = 0; c < rig.num_cameras(); ++c) {
    rig.hold_dot_grid(c, true);
    const bool ok = grab_one(c, "calibration", "dot_grid", nlohmann::json::array());
    rig.hold_dot_grid(c, false);
    if (!ok) return 1;
  }
  if (!check(ctl.set_room_lights(true)) || !grab_all("calibration", "room", nlohmann::json::array())) return 1;
  if (!check(ctl.set_room_lights(false)) || !check(ctl.set_frame_lights(false)) ||
      !grab_all("calibration", "frame_lights_off", nlohmann::json::array()))
    return 1;
  if (!check(ctl.set_frame_lights(true)) || !grab_all("calibration", "frame_lights_on", nlohmann::json::array())) return 1;
  if (!check(ctl.set_frame_lights(false))) return 1;

  // The scan: per group, a base frame, then the group's lasers stepping together.
  for (size_t g = 0; g < desc->laser_groups.size(); ++g) {
    std::vector<int> ids;
    int steps = 0;
    for (const std::string& id : desc->laser_groups[g]) {
      for (size_t i = 0; i < desc->lasers.size(); ++i)
        if (desc->lasers[i].id == id) ids.push_back(static_cast<int>(i));
    }
    for (int i : ids) {
      if (!check(ctl.home(i))) return 1;
      steps = std::max(steps, desc->lasers[static_cast<size_t>(i)].max_step - desc->lasers[static_cast<size_t>(i)].min_step + 1);
    }
    const std::string group = "group" + std::to_string(g);
    if (!check(ctl.all_lasers_off()) || !grab_all("scan", group + "_base", nlohmann::json::array())) return 1;
    for (int k = 0; k < steps; k += every) {
      nlohmann::json lasers = nlohmann::json::array();
      for (int i : ids) {
        const hw::LaserDescription& l = desc->lasers[static_cast<size_t>(i)];
        const int step = std::min(l.max_step, l.min_step + k);
        if (!check(ctl.move_to(i, step)) || !check(ctl.set_laser(i, true))) return 1;
        lasers.push_back({{"id", l.id}, {"step", step}});
      }
      char name[64];
      std::snprintf(name, sizeof name, "%s_step%04d", group.c_str(), k);
      if (!grab_all("scan", name, lasers)) return 1;
      if (!quiet) std::fprintf(stderr, "\r  %s: %d/%d steps", group.c_str(), k + 1, steps);
    }
    if (!check(ctl.all_lasers_off())) return 1;
    if (!quiet) std::fprintf(stderr, "\n");
  }
  const Status w = write_file_atomically((std::filesystem::path(out) / "index.json").string(), index.dump(2));
  if (!w.ok()) {
    std::fprintf(stderr, "bodyscan sim render: %s\n", w.message().c_str());
    return 1;
  }
  if (!quiet) std::printf("wrote %zu images and %s/index.json\n", written, out.c_str());
  return 0;
}

}  // namespace bodyscan::cli
