#include "pipeline/measurements_json.hpp"

#include <cmath>

namespace bodyscan::pipeline {

namespace {
// Positions to the micrometre: far below what a scan resolves, and a third of the
// text of full double precision (the served measurements are mostly polylines).
double to_um(double mm) { return std::round(mm * 1000.0) / 1000.0; }
}  // namespace

nlohmann::json point_json(const Eigen::Vector3d& p) {
  return nlohmann::json::array({to_um(p.x()), to_um(p.y()), to_um(p.z())});
}

nlohmann::json polyline_json(const std::vector<Eigen::Vector3d>& points) {
  nlohmann::json a = nlohmann::json::array();
  for (const Eigen::Vector3d& p : points) a.push_back(point_json(p));
  return a;
}

nlohmann::json plane_json(const Plane& plane) {
  return {{"point", point_json(plane.point)},
          {"normal", nlohmann::json::array({plane.normal.x(), plane.normal.y(), plane.normal.z()})}};
}

void add_fill_fields(float min_confidence, const std::optional<double>& fill_bound_mm, nlohmann::json* j) {
  const bool crosses = min_confidence < kMeasuredConfidence;
  (*j)["min_confidence"] = min_confidence;
  (*j)["crosses_filled_hole"] = crosses;
  (*j)["fill_bound_mm"] = fill_bound_mm ? nlohmann::json(crosses ? *fill_bound_mm : 0.0) : nlohmann::json();
  (*j)["estimated"] = crosses && (!fill_bound_mm || *fill_bound_mm > kEstimateThresholdMm);
}

nlohmann::json measurements_document(const std::string& file, const std::string& kind) {
  return {{"schema", kMeasurementsSchema}, {"file", file}, {"kind", kind}, {"measurements", nlohmann::json::array()}};
}

nlohmann::json to_json(const BodyMeasurement& m) {
  nlohmann::json j = {{"name", m.name},
                      {"label", m.label},
                      {"iso_clause", m.iso_clause.empty() ? nlohmann::json(nullptr) : nlohmann::json(m.iso_clause)},
                      {"kind", m.kind},
                      {"value_mm", m.value_mm},
                      {"path", polyline_json(m.path)},
                      {"closed", m.closed},
                      {"landmarks", m.landmarks},
                      {"definition", m.definition},
                      {"algorithm", std::string(kBodyMeasurementsAlgorithm) + "/" +
                                        (m.kind == "girth" && m.plane                 ? kGirthAlgorithm
                                         : m.kind == "height" || m.kind == "distance" ? "straight-1"
                                                                                      : kSurfaceAlgorithm)}};
  add_fill_fields(m.min_confidence, m.fill_bound_mm, &j);
  if (m.plane) j["plane"] = plane_json(*m.plane);
  if (!m.loop.empty()) j["loop"] = polyline_json(m.loop);
  if (!m.posture_assumed.empty()) {
    j["posture_assumed"] = m.posture_assumed;
    j["outside_posture"] = m.outside_posture;
  }
  return j;
}

nlohmann::json to_json(const BodyPosture& p, const std::vector<PostureCheck>& checks) {
  const auto optional = [](const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); };
  nlohmann::json j = {{"turn_deg", p.turn_deg},
                      {"position_mm", {p.position_x_mm, p.position_z_mm}},
                      {"arm_abduction_deg", {optional(p.arm_abduction_deg[0]), optional(p.arm_abduction_deg[1])}},
                      {"elbow_bend_deg", {optional(p.elbow_bend_deg[0]), optional(p.elbow_bend_deg[1])}},
                      {"ankle_distance_mm", optional(p.ankle_distance_mm)},
                      {"head_tilt_deg", optional(p.head_tilt_deg)},
                      {"head_side_tilt_deg", optional(p.head_side_tilt_deg)},
                      {"checks", nlohmann::json::array()}};
  bool ok = true;
  for (const PostureCheck& c : checks) {
    j["checks"].push_back({{"part", c.part}, {"ok", c.ok}, {"message", c.message}});
    ok = ok && c.ok;
  }
  j["ok"] = ok;
  return j;
}

void add_body_measurements(const BodyMeasurements& body, nlohmann::json* document) {
  nlohmann::json& d = *document;
  d["algorithm"] = kBodyMeasurementsAlgorithm;
  d["floor_y_mm"] = body.floor_y;
  d["posture"] = to_json(body.posture, body.posture_checks);
  d["landmarks"] = nlohmann::json::array();
  for (const BodyLandmark& l : body.landmarks)
    d["landmarks"].push_back({{"name", l.name}, {"position", point_json(l.position)}, {"confidence", l.confidence}});
  for (const BodyMeasurement& m : body.measurements) d["measurements"].push_back(to_json(m));
  d["skipped"] = body.skipped;
}

nlohmann::json to_json(const SurfacePath& p, const std::string& name) {
  nlohmann::json j = {{"name", name},
                      {"kind", "surface_length"},
                      {"value_mm", p.value_mm},
                      {"straight_mm", p.straight_mm},
                      {"from", point_json(p.from)},
                      {"to", point_json(p.to)},
                      {"path", polyline_json(p.path)},
                      {"closed", false},
                      {"algorithm", kSurfaceAlgorithm}};
  add_fill_fields(p.min_confidence, p.fill_bound_mm, &j);
  return j;
}

}  // namespace bodyscan::pipeline
