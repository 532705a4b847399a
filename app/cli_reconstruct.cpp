// bodyscan reconstruct: points (PLY) to a watertight mesh (PLY).
#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/command_line.hpp"
#include "pipeline/scan_job.hpp"
#include "recon/io/ply.hpp"
#include "recon/surface/reconstruct.hpp"
#include "storage/formats/draco_files.hpp"
#include "storage/formats/mesh_files.hpp"

namespace bodyscan::cli {

namespace {

constexpr const char* kUsage =
    "usage: bodyscan reconstruct IN.ply -o OUT.ply [options]\n"
    "\n"
    "Builds a watertight triangle mesh from a point cloud (PLY, ASCII or binary, with\n"
    "or without normals) by the thesis's anisotropic Gaussian implicit surface.\n"
    "Every option left out is chosen from the data (scale, density, noise).\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      output mesh: .ply, .glb (glTF binary, Draco, metres), .obj or .stl (mm)\n"
    "  --sigma S              tangential kernel size in units of the local point\n"
    "                         spacing (thesis sigma_user; default: from the noise)\n"
    "  --normal-sigma S       kernel size across the surface, same units (default: auto)\n"
    "  --sharpen S            curvature sharpening s of thesis eq. 3.24 (default 0)\n"
    "  --voxel V              grid spacing in the cloud's unit (default: auto)\n"
    "  --epsilon E            kernel cut-off tolerance, eq. 3.26 (default 0.001)\n"
    "  --normals SRC          auto | input | cameras | mst (default auto: the file's\n"
    "                         normals, else its cameras, else spanning-tree propagation)\n"
    "  --normal-k K           neighbours per PCA normal (default: from the noise)\n"
    "  --keep-fragments       keep small disconnected pieces (default: drop those under\n"
    "                         1% of the largest)\n"
    "  --body                 a body scan: the scan job's settings (every hole filled\n"
    "                         with a thin plate, the field kept down to 2 % of its\n"
    "                         median weight); the other options still apply\n"
    "  --keep-holes           leave the field's zero set open where it is (default: trim\n"
    "                         flaps past the data and fill every hole; filled vertices\n"
    "                         get confidence 0 in the output)\n"
    "  --trim-distance D      before filling, trim flaps whose vertices lie farther than\n"
    "                         D from every point (default: the median density sigma\n"
    "                         plus three noise sigmas)\n"
    "  --ascii                write ASCII PLY (default binary)\n"
    "  -q, --quiet            print only errors\n";

// A float option's value: finite, and positive or at least zero.
CommandLine::ValueParser float_into(float* out, bool positive) {
  return [out, positive](const std::string& v) -> std::string {
    const auto x = parse_double(v);
    if (!x || (positive && !(*x > 0)) || *x < 0)
      return std::string("expects a ") + (positive ? "positive" : "non-negative") + " number, got '" + v + "'";
    *out = static_cast<float>(*x);
    return "";
  };
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int run_reconstruct(int argc, char** argv) {
  std::string in, out;
  ReconstructOptions opt;
  // --body sets the base the other options change, wherever it stands.
  bool body = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--body") opt = pipeline::body_surface_options(), body = true;
  bool ascii = false, quiet = false;
  CommandLine cl("bodyscan reconstruct", kUsage);
  cl.positional("IN.ply", &in, /*required=*/false);
  cl.option("-o|--output", &out);
  cl.option("--sigma", float_into(&opt.sigma_scale, true));
  cl.option("--normal-sigma", float_into(&opt.normal_scale, true));
  cl.option("--sharpen", float_into(&opt.sharpening, false));
  cl.option("--voxel", float_into(&opt.voxel_size, true));
  cl.option("--epsilon", [&opt](const std::string& v) -> std::string {
    std::string error = float_into(&opt.epsilon, true)(v);
    if (error.empty() && opt.epsilon >= 1.f) error = "must be below 1";
    return error;
  });
  cl.option("--normal-k", [&opt](const std::string& v) -> std::string {
    const auto k = parse_integer(v);
    if (!k || *k <= 0) return "expects a positive integer, got '" + v + "'";
    opt.normal_k = static_cast<size_t>(*k);
    return "";
  });
  cl.option("--normals", [&opt](const std::string& v) -> std::string {
    if (!parse_normal_source(v.c_str(), &opt.normal_source))
      return "expects auto, input, cameras or mst, got '" + v + "'";
    return "";
  });
  bool keep_fragments = false, keep_holes = false, body_seen = false;
  cl.flag("--keep-fragments", &keep_fragments);
  cl.flag("--body", &body_seen);  // applied before parsing
  cl.flag("--keep-holes", &keep_holes);
  cl.option("--trim-distance", float_into(&opt.hole_trim_distance, true));
  cl.flag("--ascii", &ascii);
  cl.flag("-q|--quiet", &quiet);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (keep_fragments) opt.min_component_fraction = 0.0;
  if (keep_holes) opt.close_holes = false;
  if (in.empty() || out.empty()) return cl.fail("give IN.ply and -o OUT");
  if (!ends_with(out, ".ply") && !ends_with(out, ".glb") && !ends_with(out, ".obj") && !ends_with(out, ".stl"))
    return cl.fail("output '" + out + "' must end in .ply, .glb, .obj or .stl");

  const auto t0 = std::chrono::steady_clock::now();
  auto read = read_ply(in);
  if (!read.ok()) {
    std::fprintf(stderr, "bodyscan reconstruct: %s\n", read.status().message().c_str());
    return 1;
  }
  const PointCloud& cloud = read->cloud;

  // Progress on stderr: a line per stage and per 10% within long stages.
  const bool tty = isatty(STDERR_FILENO);
  std::string last_stage;
  int last_decile = -1;
  if (!quiet) {
    opt.progress = [&](std::string_view stage, double fraction) {
      const int decile = static_cast<int>(fraction * 10.0);
      if (stage != last_stage || decile != last_decile) {
        if (tty) {
          std::fprintf(stderr, "\r  %-12.*s %3d%%", static_cast<int>(stage.size()), stage.data(), decile * 10);
          if (stage == "done") std::fputc('\n', stderr);
        } else if (stage != last_stage) {
          std::fprintf(stderr, "  %.*s...\n", static_cast<int>(stage.size()), stage.data());
        }
        std::fflush(stderr);
        last_stage = std::string(stage);
        last_decile = decile;
      }
      return true;
    };
  }
  if (body) opt = pipeline::with_scan_normals(opt, cloud);  // as the scan job does
  auto rec = reconstruct_surface(cloud, opt);
  if (!rec.ok()) {
    std::fprintf(stderr, "bodyscan reconstruct: %s: %s\n", in.c_str(), rec.status().message().c_str());
    return 1;
  }
  Status written;
  std::string glb_note;
  if (ends_with(out, ".glb")) {
    auto glb = storage::write_glb(out, rec->mesh);
    if (glb.ok()) {
      char b[160];
      std::snprintf(b, sizeof b, " (%.2f MB, %d-bit positions, largest vertex error %.3f mm)",
                    static_cast<double>(glb->bytes.size()) / 1e6, glb->position_bits, glb->max_error_mm);
      glb_note = b;
    }
    written = glb.status();
  } else if (ends_with(out, ".obj")) {
    written = storage::write_obj(out, rec->mesh);
  } else if (ends_with(out, ".stl")) {
    written = storage::write_stl(out, rec->mesh);
  } else {
    written = write_ply(out, rec->mesh, ascii ? PlyFormat::kAscii : PlyFormat::kBinaryLittleEndian);
  }
  if (!written.ok()) {
    std::fprintf(stderr, "bodyscan reconstruct: %s\n", written.message().c_str());
    return 1;
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!quiet) {
    const ReconstructStats& s = rec->stats;
    std::printf("points      %zu (used %zu)\n", s.input_points, s.used_points);
    std::printf("triangles   %zu\nvertices    %zu\n", rec->mesh.num_triangles(), rec->mesh.num_vertices());
    std::printf("normals     %s\n", to_string(s.normals));
    std::printf("spacing     %.4g (median density sigma)\nnoise       %.4g (estimated)\n", s.median_density_sigma,
                s.noise_sigma);
    std::printf("parameters  sigma %.3g  normal-sigma %.3g  sharpen %.3g  voxel %.4g  normal-k %zu\n", s.sigma_scale,
                s.normal_scale, s.sharpening, s.voxel_size, s.normal_k);
    std::printf("field       %zu bricks, %.1f MB\n", s.bricks, static_cast<double>(s.field_bytes) / 1e6);
    const MeshTopology topology = analyze_topology(rec->mesh);
    std::printf("surface     %s, %zu component%s; %zu hole%s filled (%.4g square units), %zu flap triangles trimmed\n",
                topology.closed() ? "closed" : "open", topology.components, topology.components == 1 ? "" : "s",
                s.holes_filled, s.holes_filled == 1 ? "" : "s", s.hole_area, s.flap_triangles_trimmed);
    std::printf(
        "time        %.2f s total (neighbours %.2f, normals %.2f, orientation %.2f, "
        "kernels %.2f, field %.2f, mesh %.2f)\n",
        total, s.t_neighbours, s.t_normals, s.t_orientation, s.t_kernels, s.t_field, s.t_mesh);
    std::printf("wrote       %s%s\n", out.c_str(), glb_note.c_str());
  }
  return 0;
}

}  // namespace bodyscan::cli
