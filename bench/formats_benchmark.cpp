// What a body mesh costs on disk and on the wire, format by format (docs/benchmarks.md
// §8): binary PLY, OBJ, STL, the served glTF binary with Draco (vertex error <= 0.5 mm,
// measured by decoding), and the archive's Draco copy (<= 0.01 mm), with encode and
// decode times.
//
//   formats_benchmark MESH.ply... [--repeat N] [--level 0..10] [--normals] [--json OUT.json]
//   formats_benchmark MESH.ply... --avatar N [--avatar N ...] [--json OUT.json]
//   formats_benchmark --scan-folder DIR [--json OUT.json]
//
// --level and --normals change the served GLB only. --avatar instead decimates
// each mesh to N triangles as the CAD avatars are (recon/geometry/simplify), beside
// meshoptimizer's collapses alone (the peer: what the repair of pinched edges
// costs, and what it mends), with the avatars' sizes. --scan-folder lists what one
// archived scan keeps, file by file (an archive's scans/ID folder). --json also
// writes the figures (bench/json_figures.hpp) for bench/tables.py.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <meshoptimizer.h>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "recon/geometry/mesh_distance.hpp"
#include "recon/geometry/simplify.hpp"
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
std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

// Every regular file under folder with its size, by path relative to it.
int scan_folder(const std::string& folder, nlohmann::json& records) {
  std::error_code ec;
  std::vector<std::pair<std::string, uintmax_t>> files;
  for (auto it = std::filesystem::recursive_directory_iterator(folder, ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file())
      files.emplace_back(std::filesystem::relative(it->path(), folder).string(), it->file_size());
  if (ec) return std::fprintf(stderr, "formats_benchmark: %s: %s\n", folder.c_str(), ec.message().c_str()), 1;
  std::sort(files.begin(), files.end());
  uintmax_t total = 0;
  for (const auto& [name, bytes] : files) {
    std::printf("%12ju  %s\n", bytes, name.c_str());
    records.push_back({{"file", name}, {"bytes", bytes}});
    total += bytes;
  }
  std::printf("%12ju  in all\n", total);
  return 0;
}

// Decimates each file to each budget, the product's way and meshoptimizer's alone.
int avatars(const std::vector<std::string>& files, const std::vector<size_t>& budgets, int repeat,
            nlohmann::json& records) {
  std::printf("%-40s %10s %8s | %7s %11s %8s %8s %8s %8s %7s %7s | %7s %11s\n", "mesh", "triangles", "budget", "time s",
              "non-manif.", "med mm", "p95 mm", "dev mm", "closed", "obj MB", "glb MB", "raw s", "non-manif.");
  for (const std::string& f : files) {
    auto mesh = read_ply_mesh(f);
    if (!mesh.ok()) return std::fprintf(stderr, "%s\n", mesh.status().message().c_str()), 1;
    for (size_t budget : budgets) {
      if (budget >= mesh->num_triangles()) continue;  // nothing to decimate
      SimplifyOptions o;
      o.max_triangles = budget;
      StatusOr<SimplifyResult> s = internal_error("not run");
      const double t = best_of(repeat, [&] { s = simplify(*mesh, o); });
      if (!s.ok()) return std::fprintf(stderr, "%s\n", s.status().message().c_str()), 1;
      const MeshTopology topo = analyze_topology(s->mesh);
      // The full surface's vertices against the avatar: the spread under the largest.
      const MeshDistance to_avatar(s->mesh);
      std::vector<float> d(mesh->num_vertices());
      for (size_t v = 0; v < d.size(); ++v) d[v] = to_avatar.closest_point(mesh->vertices[v]).distance;
      std::sort(d.begin(), d.end());
      auto glb = storage::encode_plain_glb(s->mesh);
      if (!glb.ok()) return std::fprintf(stderr, "%s\n", glb.status().message().c_str()), 1;
      std::vector<unsigned int> in, out(3 * mesh->num_triangles());
      for (const Triangle& tri : mesh->triangles) in.insert(in.end(), tri.begin(), tri.end());
      size_t kept = 0;
      const double raw = best_of(repeat, [&] {
        kept = meshopt_simplify(out.data(), in.data(), in.size(), mesh->vertices.front().data(), mesh->num_vertices(),
                                sizeof(Vec3f), 3 * budget, 1e30f, 0, nullptr);
      });
      TriangleMesh raw_mesh;
      raw_mesh.vertices = mesh->vertices;
      for (size_t i = 0; i + 2 < kept; i += 3) raw_mesh.triangles.push_back({out[i], out[i + 1], out[i + 2]});
      const size_t obj_bytes = storage::encode_obj(s->mesh).size();
      const size_t raw_non_manifold = analyze_topology(raw_mesh).non_manifold_edges;
      std::string name = f.size() > 40 ? "..." + f.substr(f.size() - 37) : f;
      std::printf("%-40s %10zu %8zu | %7.2f %11zu %8.3f %8.3f %8.2f %8s %7.2f %7.2f | %7.2f %11zu\n", name.c_str(),
                  mesh->num_triangles(), s->mesh.num_triangles(), t, topo.non_manifold_edges, d[d.size() / 2],
                  d[d.size() * 95 / 100], s->max_deviation_mm, topo.closed() ? "yes" : "no",
                  static_cast<double>(obj_bytes) / 1e6, static_cast<double>(glb->size()) / 1e6, raw, raw_non_manifold);
      records.push_back({{"mesh", file_name(f)},
                         {"triangles", mesh->num_triangles()},
                         {"budget", budget},
                         {"kept", s->mesh.num_triangles()},
                         {"seconds", t},
                         {"non_manifold_edges", topo.non_manifold_edges},
                         {"closed", topo.closed()},
                         {"median_mm", d[d.size() / 2]},
                         {"p95_mm", d[d.size() * 95 / 100]},
                         {"largest_mm", s->max_deviation_mm},
                         {"obj_bytes", obj_bytes},
                         {"glb_bytes", glb->size()},
                         {"meshoptimizer_seconds", raw},
                         {"meshoptimizer_non_manifold_edges", raw_non_manifold}});
    }
  }
  std::printf(
      "(time: the product's decimation with the repair and the deviation measured; med, p95: the full\n"
      " surface's vertices to the avatar; dev: the largest, both ways; raw: meshoptimizer's collapses\n"
      " alone, whose non-manifold edges the repair mends)\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  int repeat = 3;
  storage::DracoOptions served;
  std::vector<size_t> budgets;
  std::string folder, json_out;
  CommandLine cl("formats_benchmark",
                 "usage: formats_benchmark MESH.ply... [--repeat N] [--level L] [--normals] [--avatar TRIANGLES ...] "
                 "[--json OUT]\n       formats_benchmark --scan-folder DIR [--json OUT]\n");
  cl.rest("MESH.ply...", &files);
  cl.option("--repeat", integer_between(1, 1000000, [&repeat](long long n) { repeat = static_cast<int>(n); }));
  cl.option("--level", &served.compression_level);
  cl.flag("--normals", &served.normals);
  cl.option("--avatar",
            integer_between(4, 1LL << 32, [&budgets](long long n) { budgets.push_back(static_cast<size_t>(n)); }));
  cl.option("--scan-folder", &folder);
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);  // the tree as the run starts
  nlohmann::json records = nlohmann::json::array();
  const auto write = [&](int rc) {
    const bool failed = rc == 0 && !json_out.empty() && !bench::write_figures(json_out, run_info, records);
    return failed ? 1 : rc;
  };
  if (!folder.empty()) return write(scan_folder(folder, records));
  if (files.empty()) return cl.fail("give one or more meshes");
  if (!budgets.empty()) return write(avatars(files, budgets, repeat, records));
  std::printf("%-40s %10s %9s %8s %8s %8s | %8s %4s %7s %7s %7s | %8s %4s %7s %7s %7s\n", "mesh", "triangles", "ply MB",
              "obj MB", "stl MB", "", "glb MB", "bits", "err mm", "enc s", "dec s", "drc MB", "bits", "err mm", "enc s",
              "dec s");
  for (const std::string& f : files) {
    auto mesh = read_ply_mesh(f);
    if (!mesh.ok()) return std::fprintf(stderr, "%s\n", mesh.status().message().c_str()), 1;
    const size_t ply_bytes = encode_ply(*mesh, PlyFormat::kBinaryLittleEndian).size();
    const size_t obj_bytes = storage::encode_obj(*mesh).size();
    const size_t stl_bytes = storage::encode_stl(*mesh).size();
    const double ply = static_cast<double>(ply_bytes) / 1e6, obj = static_cast<double>(obj_bytes) / 1e6,
                 stl = static_cast<double>(stl_bytes) / 1e6;
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
    records.push_back({{"mesh", file_name(f)},
                       {"triangles", mesh->num_triangles()},
                       {"ply_bytes", ply_bytes},
                       {"obj_bytes", obj_bytes},
                       {"stl_bytes", stl_bytes},
                       {"glb_bytes", glb->bytes.size()},
                       {"glb_bits", glb->position_bits},
                       {"glb_error_mm", glb->max_error_mm},
                       {"glb_encode_seconds", glb_enc},
                       {"glb_decode_seconds", glb_dec},
                       {"drc_bytes", drc->bytes.size()},
                       {"drc_error_mm", drc->max_error_mm},
                       {"drc_encode_seconds", drc_enc},
                       {"drc_decode_seconds", drc_dec}});
  }
  std::printf("(encode times include the check: every encoding is decoded again and its vertices compared)\n");
  return write(0);
}
