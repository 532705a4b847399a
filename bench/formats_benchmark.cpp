// What a body mesh costs on disk and on the wire, format by format (docs/benchmarks.md
// §8): binary PLY, OBJ, STL, the served glTF binary with Draco (vertex error <= 0.5 mm,
// measured by decoding), and the archive's Draco copy (<= 0.01 mm), with encode and
// decode times.
//
//   formats_benchmark MESH.ply... [--repeat N] [--level 0..10] [--normals]
//
// --level and --normals change the served GLB only.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "recon/io/ply.hpp"
#include "storage/formats/draco_files.hpp"
#include "storage/formats/mesh_files.hpp"

using namespace bodyscan;
using Clock = std::chrono::steady_clock;

namespace {
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

template <typename F>
double best_of(int n, F&& f) {
  double best = 1e30;
  for (int i = 0; i < n; ++i) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, since(t0));
  }
  return best;
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  int repeat = 3;
  storage::DracoOptions served;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc)
      repeat = std::max(1, std::atoi(argv[++i]));
    else if (a == "--level" && i + 1 < argc)
      served.compression_level = std::atoi(argv[++i]);
    else if (a == "--normals")
      served.normals = true;
    else
      files.push_back(a);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: formats_benchmark MESH.ply... [--repeat N]\n");
    return 2;
  }
  std::printf("%-40s %10s %9s %8s %8s %8s | %8s %4s %7s %7s %7s | %8s %4s %7s %7s %7s\n", "mesh", "triangles", "ply MB",
              "obj MB", "stl MB", "", "glb MB", "bits", "err mm", "enc s", "dec s", "drc MB", "bits", "err mm", "enc s",
              "dec s");
  for (const std::string& f : files) {
    auto mesh = read_ply_mesh(f);
    if (!mesh.ok()) return std::fprintf(stderr, "%s\n", mesh.status().message().c_str()), 1;
    const double ply = static_cast<double>(encode_ply(*mesh, PlyFormat::kBinaryLittleEndian).size()) / 1e6;
    const double obj = static_cast<double>(storage::encode_obj(*mesh).size()) / 1e6;
    const double stl = static_cast<double>(storage::encode_stl(*mesh).size()) / 1e6;
    StatusOr<storage::DracoEncoded> glb = internal_error("not run");
    const double glb_enc = best_of(repeat, [&] { glb = storage::encode_glb(*mesh, served); });
    if (!glb.ok()) return std::fprintf(stderr, "%s\n", glb.status().message().c_str()), 1;
    const double glb_dec = best_of(repeat, [&] { (void)storage::decode_glb(glb->bytes); });
    storage::DracoOptions keep;
    keep.max_error_mm = 0.01;
    StatusOr<storage::DracoEncoded> drc = internal_error("not run");
    const double drc_enc = best_of(repeat, [&] { drc = storage::encode_mesh_drc(*mesh, keep); });
    if (!drc.ok()) return std::fprintf(stderr, "%s\n", drc.status().message().c_str()), 1;
    const double drc_dec = best_of(repeat, [&] { (void)storage::decode_mesh_drc(drc->bytes); });
    std::string name = f.size() > 40 ? "..." + f.substr(f.size() - 37) : f;
    std::printf("%-40s %10zu %9.2f %8.2f %8.2f %8s | %8.3f %4d %7.3f %7.3f %7.3f | %8.3f %4d %7.4f %7.3f %7.3f\n",
                name.c_str(), mesh->num_triangles(), ply, obj, stl, "", static_cast<double>(glb->bytes.size()) / 1e6,
                glb->position_bits, glb->max_error_mm, glb_enc, glb_dec, static_cast<double>(drc->bytes.size()) / 1e6,
                drc->position_bits, drc->max_error_mm, drc_enc, drc_dec);
  }
  std::printf("(encode times include the check: every encoding is decoded again and its vertices compared)\n");
  return 0;
}
