// bodyscan measure: one measurement on a mesh or a point cloud, as JSON on stdout.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/command_line.hpp"
#include "pipeline/evaluate_measurement.hpp"
#include "pipeline/measurements_json.hpp"
#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "recon/measure/girth.hpp"

namespace bodyscan::cli {

namespace {

using pipeline::kGirthAlgorithm;
using pipeline::plane_json;
using pipeline::point_json;
using pipeline::polyline_json;

constexpr const char* kUsage =
    "usage: bodyscan measure FILE.ply WHAT [--near X,Y,Z]\n"
    "\n"
    "Measures a body (mm, Y up; a mesh, or a point cloud as the thesis does) and\n"
    "prints one JSON document: each measurement with its name, value_mm and the\n"
    "geometry to draw.\n"
    "\n"
    "  --girth-y Y            horizontal girth at height Y: the tape around the\n"
    "                         section loop (convex hull, as a tape bridges hollows)\n"
    "  --plane PX,PY,PZ,NX,NY,NZ\n"
    "                         girth in the plane through P with normal N\n"
    "  --near X,Y,Z           measure around the loop nearest this point (default:\n"
    "                         the loop with the longest tape, the torso at the waist)\n"
    "  --distance X,Y,Z --to X,Y,Z\n"
    "                         straight distance between two points\n"
    "  --arc X,Y,Z --to X,Y,Z (with --girth-y or --plane)\n"
    "                         length along the girth's tape between two points, the\n"
    "                         shorter way round (thesis fig. 3.43; meshes)\n"
    "  --surface X,Y,Z --to X,Y,Z\n"
    "                         length over the skin between two points: the\n"
    "                         shortest path on the mesh (meshes)\n"
    "  --auto                 the automatic set: landmarks and the ISO 8559-1\n"
    "                         measurements (a standing body, Y up, facing any way,\n"
    "                         anywhere on the floor; meshes)\n"
    "  --floor Y              with --auto: the floor's height (default: the mesh's\n"
    "                         lowest point)\n"
    "\n"
    "Exit status: 0 measured, 1 the file or the measurement failed, 2 bad arguments.\n";

}  // namespace

int run_measure(int argc, char** argv) {
  std::string file;
  std::optional<double> girth_y;
  std::optional<Plane> plane;
  std::optional<Eigen::Vector3d> near, from, to, arc_from, surface_from;
  std::optional<double> floor_y;
  bool automatic = false;
  CommandLine cl("bodyscan measure", kUsage);
  // Each point or plane option is comma-separated numbers (mm).
  auto point = [](std::optional<Eigen::Vector3d>* out) {
    return [out](const std::string& v) -> std::string {
      const auto x = parse_number_list(v, 3);
      if (!x) return "expects 3 comma-separated numbers (mm), got '" + v + "'";
      *out = Eigen::Vector3d((*x)[0], (*x)[1], (*x)[2]);
      return "";
    };
  };
  cl.positional("FILE", &file, /*required=*/false);
  cl.flag("--auto", &automatic);
  cl.option("--girth-y", &girth_y);
  cl.option("--floor", &floor_y);
  cl.option("--plane", [&plane](const std::string& v) -> std::string {
    const auto x = parse_number_list(v, 6);
    if (!x) return "expects 6 comma-separated numbers (mm), got '" + v + "'";
    const Eigen::Vector3d normal((*x)[3], (*x)[4], (*x)[5]);
    if (!(normal.norm() > 0)) return "needs a normal (the last three numbers) that is not zero";
    plane = Plane{Eigen::Vector3d((*x)[0], (*x)[1], (*x)[2]), normal.normalized()};
    return "";
  });
  cl.option("--near", point(&near));
  cl.option("--distance", point(&from));
  cl.option("--to", point(&to));
  cl.option("--arc", point(&arc_from));
  cl.option("--surface", point(&surface_from));
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const int whats = (girth_y ? 1 : 0) + (plane ? 1 : 0) + (from ? 1 : 0) + (surface_from ? 1 : 0) + (automatic ? 1 : 0);
  const int starts = (from ? 1 : 0) + (arc_from ? 1 : 0) + (surface_from ? 1 : 0);
  const bool ends_ok = (starts == 1) == to.has_value() && starts <= 1;
  if (file.empty() || whats != 1 || !ends_ok || (arc_from && near) || (floor_y && !automatic) ||
      (near && (from || surface_from || automatic))) {
    return cl.fail(
        "give a FILE and one of --girth-y or --plane (optionally --near, or --arc with --to), --distance or "
        "--surface with --to, or --auto (optionally --floor)");
  }
  nlohmann::json out = pipeline::measurements_document(file, "mesh");
  // The evaluation names the request's fields ('near' ...): say the options instead.
  const std::string start_option = from ? "--distance" : surface_from ? "--surface" : "--arc";
  auto fail = [&](const Status& st) {
    std::string m = st.message();
    for (const auto& [field, option] :
         {std::pair<std::string, std::string>{"'near'", "--near"}, {"'from'", start_option}, {"'to'", "--to"}}) {
      for (size_t at = m.find(field); at != std::string::npos; at = m.find(field, at + option.size()))
        m.replace(at, field.size(), option);
    }
    std::fprintf(stderr, "bodyscan measure: %s: %s\n", file.c_str(), m.c_str());
    return 1;
  };
  auto print = [&](nlohmann::json m, const std::string& name) {
    m["name"] = name;
    out["measurements"].push_back(std::move(m));
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  };
  // Everything but a point cloud's girth is the very evaluation the server runs
  // for the browser (pipeline/evaluate_measurement.hpp), so the two agree.
  const Plane cut = plane ? *plane : Plane{Eigen::Vector3d(0, girth_y.value_or(0), 0), Eigen::Vector3d::UnitY()};
  nlohmann::json request;
  std::string name;
  if (from) {
    request = {{"kind", "distance"}, {"from", point_json(*from)}, {"to", point_json(*to)}};
    name = "distance";
  } else if (surface_from) {
    request = {{"kind", "surface"}, {"from", point_json(*surface_from)}, {"to", point_json(*to)}};
    name = "surface length";
  } else if (arc_from) {
    request = {{"kind", "arc"}, {"plane", plane_json(cut)}, {"from", point_json(*arc_from)}, {"to", point_json(*to)}};
    name = "arc";
  } else if (!automatic) {
    request = {{"kind", "girth"}, {"plane", plane_json(cut)}};
    if (near) request["near"] = point_json(*near);
    name = girth_y ? "girth at y " + std::to_string(static_cast<long>(std::lround(*girth_y))) : "girth";
  }
  if (from) {
    out.erase("kind");  // the file is not read
    auto m = pipeline::evaluate_measurement(TriangleMesh{}, request);
    if (!m.ok()) return fail(m.status());
    return print(*m, name);
  }
  auto ply = read_ply(file);
  if (!ply.ok()) {
    std::fprintf(stderr, "bodyscan measure: %s\n", ply.status().message().c_str());
    return 1;
  }
  const bool is_mesh = !ply->triangles.empty();
  if (!is_mesh) {
    if (surface_from || automatic || arc_from) {
      std::fprintf(stderr, "bodyscan measure: %s needs a mesh (%s is a point cloud)\n",
                   automatic      ? "--auto"
                   : surface_from ? "--surface"
                                  : "--arc",
                   file.c_str());
      return 1;
    }
    // The thesis's girth on a cloud: the points within a slab of the plane.
    const StatusOr<Girth> g = cloud_girth(ply->cloud, cut, near);
    if (!g.ok()) return fail(g.status());
    out["kind"] = "points";
    nlohmann::json m = {{"kind", "girth"},
                        {"value_mm", g->value_mm},
                        {"plane", plane_json(g->plane)},
                        {"path", polyline_json(g->tape)},
                        {"closed", true},
                        {"tape", polyline_json(g->tape)},
                        {"loops_cut", g->loops_cut},
                        {"algorithm", kGirthAlgorithm}};
    if (near) m["near"] = point_json(*near);
    return print(m, name);
  }
  TriangleMesh mesh;
  mesh.vertices = ply->cloud.positions;
  mesh.triangles = ply->triangles;
  if (ply->cloud.confidence.size() == mesh.vertices.size()) mesh.confidence = ply->cloud.confidence;
  if (automatic) {
    BodyMeasureOptions options;
    options.floor_y = floor_y;
    const StatusOr<BodyMeasurements> body = measure_body(mesh, options);
    if (!body.ok()) return fail(body.status());
    pipeline::add_body_measurements(*body, &out);
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  auto m = pipeline::evaluate_measurement(mesh, request);
  if (!m.ok()) return fail(m.status());
  return print(*m, name);
}

}  // namespace bodyscan::cli
