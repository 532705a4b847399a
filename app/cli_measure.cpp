// bodyscan measure: one measurement on a mesh or a point cloud, as JSON on stdout.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

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

void usage(FILE* out) {
  std::fputs(
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
      "Exit status: 0 measured, 1 the file or the measurement failed, 2 bad arguments.\n",
      out);
}

std::optional<std::vector<double>> numbers(const std::string& text, size_t count) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x)) return std::nullopt;
    v.push_back(x);
  }
  if (v.size() != count) return std::nullopt;
  return v;
}

}  // namespace

int run_measure(int argc, char** argv) {
  std::string file;
  std::optional<double> girth_y;
  std::optional<Plane> plane;
  std::optional<Eigen::Vector3d> near, from, to, arc_from, surface_from;
  std::optional<double> floor_y;
  bool automatic = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    }
    if (a == "--auto") {
      automatic = true;
      continue;
    }
    const bool takes_value = a == "--girth-y" || a == "--plane" || a == "--near" || a == "--distance" || a == "--to" ||
                             a == "--arc" || a == "--surface" || a == "--floor";
    if (!takes_value) {
      if (!a.empty() && a[0] == '-') {
        std::fprintf(stderr, "bodyscan measure: unknown option '%s'\n", a.c_str());
        usage(stderr);
        return 2;
      }
      if (!file.empty()) {
        std::fprintf(stderr, "bodyscan measure: one file only ('%s' and '%s')\n", file.c_str(), a.c_str());
        return 2;
      }
      file = a;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "bodyscan measure: %s needs a value\n", a.c_str());
      return 2;
    }
    const std::string v = argv[++i];
    const size_t count = a == "--girth-y" || a == "--floor" ? 1 : a == "--plane" ? 6 : 3;
    const auto n = numbers(v, count);
    if (!n) {
      std::fprintf(stderr, "bodyscan measure: %s expects %zu comma-separated numbers (mm), got '%s'\n", a.c_str(),
                   count, v.c_str());
      return 2;
    }
    const std::vector<double>& x = *n;
    if (a == "--girth-y") girth_y = x[0];
    if (a == "--plane") {
      const Eigen::Vector3d normal(x[3], x[4], x[5]);
      if (!(normal.norm() > 0)) {
        std::fprintf(stderr, "bodyscan measure: --plane's normal (the last three numbers) must not be zero\n");
        return 2;
      }
      plane = Plane{Eigen::Vector3d(x[0], x[1], x[2]), normal.normalized()};
    }
    if (a == "--near") near = Eigen::Vector3d(x[0], x[1], x[2]);
    if (a == "--distance") from = Eigen::Vector3d(x[0], x[1], x[2]);
    if (a == "--to") to = Eigen::Vector3d(x[0], x[1], x[2]);
    if (a == "--arc") arc_from = Eigen::Vector3d(x[0], x[1], x[2]);
    if (a == "--surface") surface_from = Eigen::Vector3d(x[0], x[1], x[2]);
    if (a == "--floor") floor_y = x[0];
  }
  const int whats = (girth_y ? 1 : 0) + (plane ? 1 : 0) + (from ? 1 : 0) + (surface_from ? 1 : 0) + (automatic ? 1 : 0);
  const int starts = (from ? 1 : 0) + (arc_from ? 1 : 0) + (surface_from ? 1 : 0);
  const bool ends_ok = (starts == 1) == to.has_value() && starts <= 1;
  if (file.empty() || whats != 1 || !ends_ok || (arc_from && near) || (floor_y && !automatic) ||
      (near && (from || surface_from || automatic))) {
    std::fprintf(stderr,
                 "bodyscan measure: give a FILE and one of --girth-y or --plane (optionally --near, or --arc with "
                 "--to), --distance or --surface with --to, or --auto (optionally --floor)\n");
    usage(stderr);
    return 2;
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
