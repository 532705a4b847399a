// `bodyscan sim render`: the images the simulated rig's cameras take during one
// calibration and one full scan, as PNG files with a JSON index, so a person can
// look at what the cameras see.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

#include "app/cli_subject.hpp"
#include "pipeline/acquire.hpp"
#include "pipeline/rig_backend.hpp"
#include "recon/io/atomic_file.hpp"
#include "recon/io/png_image.hpp"

namespace bodyscan::cli {

namespace {

std::string usage() {
  return std::string(
             "usage: bodyscan sim render --rig RIG --out DIR [options]\n"
             "\n"
             "Renders what the simulated rig's cameras see during one calibration (the\n"
             "dot-grid target before each camera, room lights, frame lights off, on, front\n"
             "poles only, each laser alone) and one full scan (per laser group: a base frame\n"
             "with the lasers off, then every step with the group's lasers on), as PNG\n"
             "images in DIR with DIR/index.json listing them.\n"
             "\n"
             "  --rig RIG        thesis, square, tiered, or a rig description file (JSON)\n") +
         kSubjectOptionsHelp +
         "  --out DIR        output folder (created)\n"
         "  --every N        render every Nth laser step only (default 1)\n"
         "  -q, --quiet      print only errors\n";
}

}  // namespace

int run_sim(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) != "render") {
    CommandLine sim("bodyscan sim", usage());
    if (argc >= 2 && argv[1][0] != '-')
      return sim.fail(std::string("unknown subcommand '") + argv[1] + "' (known: render)");
    const auto exit = sim.parse(argc, argv);  // --help; anything else is an error
    return exit ? *exit : sim.fail("give a subcommand (render)");
  }
  CommandLine cl("bodyscan sim render", usage());
  pipeline::SimulatedSubject subject;
  std::string rig_arg, out;
  int every = 1;
  bool quiet = false;
  cl.option("--rig", &rig_arg);
  add_subject_options(&cl, &subject);
  cl.option("--out", &out);
  cl.option("--every", integer_between(1, 1000000, [&every](long long n) { every = static_cast<int>(n); }));
  cl.flag("-q|--quiet", &quiet);
  // argv[1] is "render"; its options follow.
  if (const auto exit = cl.parse(argc - 1, argv + 1)) return *exit;
  if (rig_arg.empty() || out.empty()) return cl.fail("--rig and --out are required");
  auto made = pipeline::open_simulated_rig(rig_arg, subject);
  if (!made.ok()) {
    std::fprintf(stderr, "bodyscan sim render: %s\n", made.status().message().c_str());
    return 1;
  }
  hw::sim::SimulatedRig& rig = **made;
  const hw::RigDescription& desc = rig.description();
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "bodyscan sim render: cannot create '%s': %s\n", out.c_str(), ec.message().c_str());
    return 1;
  }

  nlohmann::json index;
  index["rig"] = desc.name;
  index["cameras"] = nlohmann::json::array();
  for (size_t c = 0; c < rig.num_cameras(); ++c) {
    index["cameras"].push_back({{"id", rig.camera(c).info().id},
                                {"width", rig.camera(c).info().width},
                                {"height", rig.camera(c).info().height}});
  }
  index["images"] = nlohmann::json::array();
  size_t written = 0;
  std::vector<size_t> identify_bases(rig.num_cameras(), 0);
  // Every shot of the two sequences becomes a PNG and an index entry.
  auto write_shot = [&](const std::string& phase, pipeline::Shot&& shot) -> Status {
    const std::string& camera = rig.camera(shot.camera).info().id;
    std::string name = pipeline::to_string(shot.kind);
    nlohmann::json lasers = nlohmann::json::array();
    for (const pipeline::LaserState& l : shot.lasers) {
      lasers.push_back({{"id", desc.lasers[static_cast<size_t>(l.laser)].id}, {"step", l.step}});
    }
    if (shot.kind == pipeline::ShotKind::kScanStep) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "group%d_step%04d", shot.group, shot.step_index);
      name = buf;
    } else if (shot.kind == pipeline::ShotKind::kLaserBase && shot.group >= 0) {
      name = "group" + std::to_string(shot.group) + "_base";
    } else if (!shot.lasers.empty()) {
      name += "_" + desc.lasers[static_cast<size_t>(shot.lasers[0].laser)].id + "_step" +
              std::to_string(shot.lasers[0].step);
    } else if (shot.kind == pipeline::ShotKind::kLaserBase) {
      // Calibration takes one before each laser is identified, in laser order.
      const size_t k = identify_bases[shot.camera]++;
      name += "_" + (k < desc.lasers.size() ? desc.lasers[k].id : std::to_string(k));
    }
    const std::string file = phase + "/" + camera + "/" + name + ".png";
    std::filesystem::create_directories(std::filesystem::path(out) / phase / camera, ec);
    hw::Frame& f = shot.frame;
    GrayImage img{f.width, f.height, hw::bits_per_pixel(f.format) > 8 ? 16 : 8, std::move(f.pixels)};
    RETURN_IF_ERROR(write_png((std::filesystem::path(out) / file).string(), img));
    index["images"].push_back({{"file", file},
                               {"camera", camera},
                               {"phase", phase},
                               {"name", name},
                               {"lasers", lasers},
                               {"frame_id", f.frame_id},
                               {"timestamp_ns", f.timestamp_ns}});
    ++written;
    return {};
  };
  const pipeline::Rig handle = pipeline::rig_handle(rig);
  ProgressFn progress;
  if (!quiet) {
    progress = [](std::string_view stage, double fraction) {
      std::fprintf(stderr, "\r  %-28.*s %3d%%", static_cast<int>(stage.size()), stage.data(),
                   static_cast<int>(fraction * 100));
      return true;
    };
  }
  Status s = pipeline::acquire_calibration(
      handle, [&](pipeline::Shot&& shot) { return write_shot("calibration", std::move(shot)); }, progress);
  if (s.ok()) {
    s = pipeline::acquire_scan(
        handle, [&](pipeline::Shot&& shot) { return write_shot("scan", std::move(shot)); }, every, progress);
  }
  if (!quiet) std::fprintf(stderr, "\n");
  if (!s.ok()) {
    std::fprintf(stderr, "bodyscan sim render: %s\n", s.message().c_str());
    return 1;
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
