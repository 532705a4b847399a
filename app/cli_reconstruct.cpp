// bodyscan reconstruct: points (PLY) to a watertight mesh (PLY).
#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pipeline/scan_job.hpp"
#include "recon/io/ply.hpp"
#include "recon/surface/reconstruct.hpp"
#include "storage/formats/draco_files.hpp"
#include "storage/formats/mesh_files.hpp"

namespace bodyscan::cli {

namespace {

void usage(FILE* out) {
  std::fputs(
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
      "  -q, --quiet            print only errors\n",
      out);
}

bool parse_float(const char* s, float* out) {
  char* end = nullptr;
  const float v = std::strtof(s, &end);
  if (end == s || *end != '\0' || !std::isfinite(v)) return false;
  *out = v;
  return true;
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
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bodyscan reconstruct: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    auto number = [&](const char* name, float* dst, bool positive) {
      const char* v = value(name);
      if (!parse_float(v, dst) || (positive && !(*dst > 0.f)) || *dst < 0.f) {
        std::fprintf(stderr, "bodyscan reconstruct: %s expects a %s number, got '%s'\n", name,
                     positive ? "positive" : "non-negative", v);
        std::exit(2);
      }
    };
    if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else if (a == "-o" || a == "--output") {
      out = value("-o");
    } else if (a == "--sigma") {
      number("--sigma", &opt.sigma_scale, true);
    } else if (a == "--normal-sigma") {
      number("--normal-sigma", &opt.normal_scale, true);
    } else if (a == "--sharpen") {
      number("--sharpen", &opt.sharpening, false);
    } else if (a == "--voxel") {
      number("--voxel", &opt.voxel_size, true);
    } else if (a == "--epsilon") {
      number("--epsilon", &opt.epsilon, true);
      if (opt.epsilon >= 1.f) {
        std::fputs("bodyscan reconstruct: --epsilon must be below 1\n", stderr);
        return 2;
      }
    } else if (a == "--normal-k") {
      float k = 0;
      number("--normal-k", &k, true);
      opt.normal_k = static_cast<size_t>(k);
    } else if (a == "--normals") {
      const char* v = value("--normals");
      if (!parse_normal_source(v, &opt.normal_source)) {
        std::fprintf(stderr, "bodyscan reconstruct: --normals expects auto, input, cameras or mst, got '%s'\n", v);
        return 2;
      }
    } else if (a == "--keep-fragments") {
      opt.min_component_fraction = 0.0;
    } else if (a == "--body") {
      // applied before the loop
    } else if (a == "--keep-holes") {
      opt.close_holes = false;
    } else if (a == "--trim-distance") {
      number("--trim-distance", &opt.hole_trim_distance, true);
    } else if (a == "--ascii") {
      ascii = true;
    } else if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "bodyscan reconstruct: unknown option '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    } else if (in.empty()) {
      in = a;
    } else {
      std::fprintf(stderr, "bodyscan reconstruct: more than one input file ('%s')\n", a.c_str());
      return 2;
    }
  }
  if (in.empty() || out.empty()) {
    usage(stderr);
    return 2;
  }
  if (!ends_with(out, ".ply") && !ends_with(out, ".glb") && !ends_with(out, ".obj") && !ends_with(out, ".stl")) {
    std::fprintf(stderr, "bodyscan reconstruct: output '%s' must end in .ply, .glb, .obj or .stl\n", out.c_str());
    return 2;
  }

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
