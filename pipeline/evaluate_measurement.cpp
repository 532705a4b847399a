#include "pipeline/evaluate_measurement.hpp"

#include <cmath>
#include <string>

#include "core/json_text.hpp"
#include "pipeline/measurements_json.hpp"
#include "recon/measure/girth.hpp"
#include "recon/measure/surface_path.hpp"

namespace bodyscan::pipeline {

namespace {

// A body is inside a 3 m cube; anything past 10 m is a unit mistake or garbage.
constexpr double kMaxCoordinateMm = 10000;

StatusOr<Eigen::Vector3d> vec3(const nlohmann::json& j, const std::string& field) {
  if (!j.contains(field)) return invalid_argument("'" + field + "' is missing");
  const nlohmann::json& v = j.at(field);
  if (!v.is_array() || v.size() != 3) return invalid_argument("'" + field + "' must be [x, y, z] in mm");
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) return invalid_argument("'" + field + "' must be [x, y, z] in mm");
    p[i] = v[i].get<double>();
    if (!std::isfinite(p[i]) || std::abs(p[i]) > kMaxCoordinateMm)
      return invalid_argument("'" + field + "' is outside the scan volume (mm expected)");
  }
  return p;
}

}  // namespace

StatusOr<Plane> request_plane(const nlohmann::json& request) {
  if (request.contains("plane")) {
    const nlohmann::json& p = request.at("plane");
    if (!p.is_object()) return invalid_argument("'plane' must be {\"point\": [x,y,z], \"normal\": [x,y,z]}");
    ASSIGN_OR_RETURN(Eigen::Vector3d point, vec3(p, "point"));
    ASSIGN_OR_RETURN(Eigen::Vector3d normal, vec3(p, "normal"));
    if (!(normal.norm() > 1e-9)) return invalid_argument("the plane's normal must not be zero");
    return Plane{point, normal.normalized()};
  }
  if (request.contains("line")) {
    const nlohmann::json& l = request.at("line");
    if (!l.is_object()) return invalid_argument("'line' must be {\"from\": [x,y,z], \"to\": [x,y,z]}");
    ASSIGN_OR_RETURN(Eigen::Vector3d a, vec3(l, "from"));
    ASSIGN_OR_RETURN(Eigen::Vector3d b, vec3(l, "to"));
    ASSIGN_OR_RETURN(Eigen::Vector3d view, vec3(request, "view"));
    const Eigen::Vector3d normal = (b - a).cross(view);
    if (!((b - a).norm() > 1e-6) || !(view.norm() > 1e-9) || !(normal.norm() > 1e-9 * (b - a).norm() * view.norm()))
      return invalid_argument("the line must have length and not run along the view direction");
    return Plane{0.5 * (a + b), normal.normalized()};
  }
  return invalid_argument("give the cutting plane as 'plane' or as 'line' with 'view'");
}

StatusOr<nlohmann::json> evaluate_measurement(const TriangleMesh& mesh, const nlohmann::json& request) {
  if (!request.is_object()) return invalid_argument("the measurement request must be a JSON object");
  const std::optional<std::string> kind_field = string_field(request, "kind");
  if (!kind_field) return invalid_argument("'kind' is the kind of measurement, a string");
  const std::string& kind = *kind_field;
  if (kind == "distance") {
    ASSIGN_OR_RETURN(Eigen::Vector3d a, vec3(request, "from"));
    ASSIGN_OR_RETURN(Eigen::Vector3d b, vec3(request, "to"));
    return nlohmann::json{{"kind", "distance"},       {"value_mm", (b - a).norm()},    {"from", point_json(a)},
                          {"to", point_json(b)},      {"path", polyline_json({a, b})}, {"closed", false},
                          {"algorithm", "distance-1"}};
  }
  if (mesh.triangles.empty()) return failed_precondition("the scan has no surface to measure on");
  if (kind == "surface") {
    ASSIGN_OR_RETURN(Eigen::Vector3d a, vec3(request, "from"));
    ASSIGN_OR_RETURN(Eigen::Vector3d b, vec3(request, "to"));
    ASSIGN_OR_RETURN(SurfacePath p, mesh_surface_path(mesh, a, b));
    nlohmann::json j = to_json(p, "surface length");
    j.erase("name");
    return j;
  }
  if (kind == "girth") {
    ASSIGN_OR_RETURN(Plane plane, request_plane(request));
    std::optional<Eigen::Vector3d> near;
    if (request.contains("near")) {
      ASSIGN_OR_RETURN(near, vec3(request, "near"));
    } else if (request.contains("line")) {
      near = plane.point;  // the loop under the drawn line, not the longest one
    }
    ASSIGN_OR_RETURN(Girth g, mesh_girth(mesh, plane, near));
    nlohmann::json j = {{"kind", "girth"},
                        {"value_mm", g.value_mm},
                        {"plane", plane_json(g.plane)},
                        {"path", polyline_json(g.tape)},
                        {"closed", true},
                        {"tape", polyline_json(g.tape)},
                        {"loop", polyline_json(g.loop)},
                        {"loop_length_mm", g.loop_length_mm},
                        {"loops_cut", g.loops_cut},
                        {"algorithm", kGirthAlgorithm}};
    add_fill_fields(g.min_confidence, g.fill_bound_mm, &j);
    if (near) j["near"] = point_json(*near);
    return j;
  }
  if (kind == "arc") {
    ASSIGN_OR_RETURN(Plane plane, request_plane(request));
    ASSIGN_OR_RETURN(Eigen::Vector3d a, vec3(request, "from"));
    ASSIGN_OR_RETURN(Eigen::Vector3d b, vec3(request, "to"));
    ASSIGN_OR_RETURN(Arc arc, mesh_arc(mesh, plane, a, b));
    nlohmann::json j = {{"kind", "arc"},
                        {"value_mm", arc.value_mm},
                        {"other_way_mm", arc.other_way_mm},
                        {"from", point_json(a)},
                        {"to", point_json(b)},
                        {"path", polyline_json(arc.path)},
                        {"closed", false},
                        {"plane", plane_json(plane)},
                        {"girth_mm", arc.girth.value_mm},
                        {"algorithm", kGirthAlgorithm}};
    // The whole loop's: the arc covers part of it, so this is an upper bound.
    add_fill_fields(arc.girth.min_confidence, arc.girth.fill_bound_mm, &j);
    return j;
  }
  return invalid_argument("'kind' must be girth, arc, surface or distance");
}

}  // namespace bodyscan::pipeline
