// `bodyscan scan`: calibrate the rig, scan the body, build the surface, and write
// the results - the very pipeline the server runs.
#include <cstdio>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>

#include "app/cli_subject.hpp"
#include "core/command_line.hpp"
#include "core/json_text.hpp"
#include "hw/rig_description.hpp"
#include "pipeline/archive_scan.hpp"
#include "pipeline/rig_backend.hpp"
#include "pipeline/scan_job.hpp"
#include "recon/io/atomic_file.hpp"

namespace bodyscan::cli {

namespace {

std::string usage() {
  return std::string(
             "usage: bodyscan scan --rig RIG --out DIR [options]\n"
             "\n"
             "Calibrates the rig from what its cameras see (dot grid, frame lights, lasers on\n"
             "the frame's poles), scans the subject, turns the laser stripes into one point\n"
             "cloud, reconstructs a closed surface and measures it. Writes DIR/points.ply,\n"
             "DIR/mesh.ply, DIR/mesh.glb, DIR/measurements.json (docs/measurements.md),\n"
             "DIR/calibration.json, DIR/scan.json and DIR/raw/ (the raw record that\n"
             "`bodyscan reprocess` makes the scan again from).\n"
             "\n"
             "  --rig RIG        sim (the thesis rig and the demo body), thesis, square, tiered,\n"
             "                   or a rig description file (JSON)\n") +
         kSubjectOptionsHelp +
         "  --out DIR        output folder (created)\n"
         "  --every N        scan every Nth laser step only (default 1: all)\n"
         "  --method M       homography (default: the thesis's image-to-laser-plane\n"
         "                   transform, eq. 3.6) or ray (the pixel's two-plane ray met\n"
         "                   with the laser plane)\n"
         "  --max-view DEG   drop points their camera saw more than DEG from the\n"
         "                   surface normal (grazing views put points inside the\n"
         "                   body; default: the rig description's processing\n"
         "                   .max_view_deg, else 90: keep them all)\n"
         "  --no-surface     stop at the point cloud\n"
         "  --keep-sway      keep every point where it was measured (default: the\n"
         "                   subject's sway between sweeps is estimated from the\n"
         "                   cloud and undone; scan.json \"sway\" has its path)\n"
         "  --archive DIR    also store the scan in the archive in DIR (created;\n"
         "                   docs/archive.md); --out is then optional\n"
         "  --customer ID    the archived scan's customer (default: a new one)\n"
         "  --new-customer NAME  a new customer with this name\n"
         "  --operator NAME  who runs the scan (the archive's audit log)\n"
         "  --operator-dot-grid  ask on the terminal for the lens board before the\n"
         "                   simulated cameras too, as for real ones (a line on\n"
         "                   standard input answers each request)\n"
         "  -q, --quiet      print only errors\n"
         "\n"
         "Before each real camera a person holds the lens dot-grid board: the request\n"
         "is printed, and Enter (a line on standard input) answers it.\n";
}

// The processing options `scan` and `reprocess` share.
void add_processing_options(CommandLine* cl, pipeline::ScanJobOptions* options, bool* no_surface, bool* keep_sway) {
  cl->option("--method", [options](const std::string& v) -> std::string {
    if (v == "ray")
      options->scan.triangulate.method = TriangulationMethod::kTwoPlaneRay;
    else if (v == "homography")
      options->scan.triangulate.method = TriangulationMethod::kLaserHomography;
    else
      return "is ray or homography, not '" + v + "'";
    return "";
  });
  cl->option("--max-view", [options](const std::string& v) -> std::string {
    const auto deg = parse_double(v);
    if (!deg || !(*deg > 0 && *deg <= 90)) return "expects degrees in (0, 90], got '" + v + "'";
    options->max_view_deg = *deg;
    return "";
  });
  cl->flag("--no-surface", no_surface);
  cl->flag("--keep-sway", keep_sway);
}

// What the sway estimate found (pipeline::ScanOptions::compensate_sway).
void print_sway(const pipeline::ScanStats& scan) {
  if (!scan.sway.empty() && scan.sway.regularization.still) {
    std::printf(
        "sway: none; where sweeps meet they differ by %.2f mm RMS, and no path explains skin it was not "
        "fitted to better\n",
        scan.sway.rms_before_mm);
  } else if (!scan.sway.empty()) {
    std::printf("sway: up to %.1f mm, undone; where sweeps meet they differ by %.2f mm RMS (%.2f as measured)\n",
                scan.sway.peak_mm, scan.sway.rms_after_mm, scan.sway.rms_before_mm);
  } else if (!scan.sway_not_estimated.empty()) {
    std::printf("sway: not estimated (%s); the cloud is as measured\n", scan.sway_not_estimated.c_str());
  }
}

}  // namespace

int run_scan(int argc, char** argv) {
  pipeline::SimulatedSubject subject;
  std::string rig_arg, out, archive_dir, customer_id, new_customer, operator_name = "cli";
  pipeline::ScanJobOptions options;
  bool quiet = false, operator_dot_grid = false;
  bool no_surface = false, keep_sway = false;
  CommandLine cl("bodyscan scan", usage());
  cl.option("--rig", &rig_arg);
  add_subject_options(&cl, &subject);
  cl.option("--out", &out);
  cl.option("--every", integer_between(1, 1000000, [&options](long long n) { options.every = static_cast<int>(n); }));
  add_processing_options(&cl, &options, &no_surface, &keep_sway);
  cl.option("--archive", &archive_dir);
  cl.option("--customer", &customer_id);
  cl.option("--new-customer", &new_customer);
  cl.option("--operator", &operator_name);
  cl.flag("--operator-dot-grid", &operator_dot_grid);
  cl.flag("-q|--quiet", &quiet);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (no_surface) options.reconstruct = false;
  if (keep_sway) options.scan.compensate_sway = false;
  if (rig_arg.empty() || (out.empty() && archive_dir.empty()))
    return cl.fail("--rig and --out (or --archive) are required");
  if (archive_dir.empty() && (!customer_id.empty() || !new_customer.empty()))
    return cl.fail("--customer and --new-customer go with --archive");
  auto sim = pipeline::open_rig(rig_arg, subject);
  if (!sim.ok()) {
    std::fprintf(stderr, "bodyscan scan: %s\n", sim.status().message().c_str());
    return 1;
  }
  // Into the archive: the scan is recorded as running before the rig moves, so
  // that a crash leaves a scan the next start marks failed, never a silent gap.
  std::unique_ptr<storage::Archive> archive;
  std::string scan_id;
  if (!archive_dir.empty()) {
    auto opened = storage::Archive::open(archive_dir);
    if (!opened.ok()) {
      std::fprintf(stderr, "bodyscan scan: %s\n", opened.status().message().c_str());
      return 1;
    }
    archive = std::move(*opened);
    if (customer_id.empty()) {
      auto c = archive->add_customer(new_customer.empty() ? std::nullopt : std::optional<std::string>(new_customer),
                                     std::nullopt, operator_name);
      if (!c.ok()) {
        std::fprintf(stderr, "bodyscan scan: %s\n", c.status().message().c_str());
        return 1;
      }
      customer_id = c->id;
    }
    auto id = archive->begin_scan(customer_id, operator_name,
                                  nlohmann::json::parse(hw::to_json((*sim)->description()), nullptr, false), "");
    if (!id.ok()) {
      std::fprintf(stderr, "bodyscan scan: %s\n", id.status().message().c_str());
      return 1;
    }
    scan_id = *id;
  }
  auto fail_archived = [&](const std::string& why) {
    if (archive) archive->end_scan(scan_id, storage::ScanStatus::kFailed, why);
  };
  std::string last_stage;
  int last_percent = -1;
  if (!quiet) {
    options.progress = [&](std::string_view stage, double fraction) {
      const int percent = static_cast<int>(fraction * 100);
      if (stage != last_stage) {
        if (!last_stage.empty()) std::fprintf(stderr, "\n");
        last_stage = std::string(stage);
        last_percent = -1;
      }
      if (percent != last_percent) {
        std::fprintf(stderr, "\r  %-28s %3d%%", last_stage.c_str(), percent);
        last_percent = percent;
      }
      return true;
    };
  }
  // The person at the rig answers on the terminal.
  auto ask = [&](const pipeline::OperatorRequest& r) -> Status {
    if (!last_stage.empty()) std::fprintf(stderr, "\n");
    if (!r.why.empty()) std::fprintf(stderr, "The last picture could not be used: %s\n", r.why.c_str());
    std::fprintf(stderr, "%s\n  [Enter when done] ", r.text().c_str());
    std::fflush(stderr);
    for (int c = std::getchar();; c = std::getchar()) {
      if (c == EOF) return cancelled("nobody answered on standard input to hold the dot-grid board");
      if (c == '\n') break;
    }
    last_percent = -1;
    return Status::Ok();
  };
  auto result = pipeline::run_scan_job(pipeline::rig_handle(**sim, ask, operator_dot_grid), options);
  if (!quiet && !last_stage.empty()) std::fprintf(stderr, "\n");
  if (!result.ok()) {
    fail_archived(result.status().message());
    std::fprintf(stderr, "bodyscan scan: %s\n", result.status().message().c_str());
    return 1;
  }
  if (!out.empty()) {
    const Status w = pipeline::write_scan_results(*result, out);
    if (!w.ok()) {
      fail_archived("could not write the results: " + w.message());
      std::fprintf(stderr, "bodyscan scan: %s\n", w.message().c_str());
      return 1;
    }
  }
  if (archive) {
    // The calibration this scan ran on, as its own record (the server calibrates
    // once and scans many times against it).
    auto cal = archive->add_calibration(nlohmann::json::parse(hw::to_json((*sim)->description()), nullptr, false),
                                        pipeline::to_json(result->calibration), operator_name);
    if (cal.ok()) archive->set_scan_calibration(scan_id, *cal);
    const Status stored = pipeline::archive_scan(*archive, scan_id, *result, options);
    if (!stored.ok()) {
      fail_archived("could not store the results: " + stored.message());
      std::fprintf(stderr, "bodyscan scan: %s\n", stored.message().c_str());
      return 1;
    }
  }
  if (!quiet) {
    for (const CameraCalibration& c : result->calibration.cameras) {
      std::printf(
          "camera %-12s %s side, centre (%.0f, %.0f, %.0f) mm, lens held-out %.3f px, rays meet within %.2f mm\n",
          c.camera_id.c_str(), to_string(c.side), c.centre.x(), c.centre.y(), c.centre.z(), c.lens.held_out_rms_px(),
          c.ray_spread_mm);
    }
    std::printf("scan: %zu points from %zu frames (%zu without a laser plane), processing %.2f s\n",
                result->cloud.size(), result->scan.frames, result->scan.frames_without_plane,
                result->scan.processing_seconds);
    print_sway(result->scan);
    if (!result->mesh.triangles.empty()) {
      std::printf("surface: %zu vertices, %zu triangles in %.1f s\n", result->mesh.vertices.size(),
                  result->mesh.triangles.size(), result->surface.total_seconds());
    }
    if (result->body) {
      std::printf("measurements: %zu taken (%zu skipped), %zu landmarks\n", result->body->measurements.size(),
                  result->body->skipped.size(), result->body->landmarks.size());
    }
    if (!out.empty())
      std::printf("wrote %s/points.ply%s%s, calibration.json, scan.json, raw/\n", out.c_str(),
                  result->mesh.triangles.empty() ? "" : ", mesh.ply, mesh.glb",
                  result->body ? ", measurements.json" : "");
    if (archive)
      std::printf("archived scan %s for customer %s in %s\n", scan_id.c_str(), customer_id.c_str(),
                  archive_dir.c_str());
  }
  if (!result->measure_error.empty()) {
    std::fprintf(stderr, "bodyscan scan: warning: no automatic measurements: %s\n", result->measure_error.c_str());
  }
  if (!result->surface_error.empty()) {
    std::fprintf(stderr, "bodyscan scan: the point cloud is saved in %s, but the surface failed: %s\n", out.c_str(),
                 result->surface_error.c_str());
    return 1;
  }
  return 0;
}

int run_reprocess(int argc, char** argv) {
  std::string in, out;
  pipeline::ScanJobOptions options;
  bool no_surface = false, keep_sway = false;
  CommandLine cl("bodyscan reprocess",
                 "usage: bodyscan reprocess SCAN_DIR --out DIR [--method ray|homography] [--max-view DEG] "
                 "[--no-surface]\n"
                 "                         [--keep-sway]\n"
                 "\n"
                 "Makes a scan again from the raw record `bodyscan scan` left in SCAN_DIR/raw\n"
                 "(calibration and stripe samples; no camera frames), with today's processing,\n"
                 "and writes the results into DIR as `bodyscan scan` does. Archived scans:\n"
                 "`bodyscan archive DIR reprocess SCAN`.\n");
  cl.positional("SCAN_DIR", &in);
  cl.option("--out", &out);
  add_processing_options(&cl, &options, &no_surface, &keep_sway);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (no_surface) options.reconstruct = false;
  if (keep_sway) options.scan.compensate_sway = false;
  if (out.empty()) return cl.fail("--out is required");
  nlohmann::json record;
  std::string stripes;
  if (const Status raw = pipeline::read_raw_record(in, &record, &stripes); !raw.ok()) {
    std::fprintf(stderr, "bodyscan reprocess: %s\n", raw.message().c_str());
    return 1;
  }
  auto result = pipeline::reprocess_scan(record, stripes, options);
  if (!result.ok()) {
    std::fprintf(stderr, "bodyscan reprocess: %s\n", result.status().message().c_str());
    return 1;
  }
  const Status w = pipeline::write_scan_results(*result, out);
  if (!w.ok()) {
    std::fprintf(stderr, "bodyscan reprocess: %s\n", w.message().c_str());
    return 1;
  }
  print_sway(result->scan);
  std::printf("reprocessed: %zu points%s, written to %s\n", result->cloud.size(),
              result->mesh.triangles.empty()
                  ? ""
                  : (", " + std::to_string(result->mesh.num_triangles()) + " triangles").c_str(),
              out.c_str());
  if (!result->surface_error.empty()) {
    std::fprintf(stderr, "bodyscan reprocess: the surface failed: %s\n", result->surface_error.c_str());
    return 1;
  }
  return 0;
}

}  // namespace bodyscan::cli
