#include "recon/measure/rules/sheet.hpp"

#include <algorithm>
#include <limits>

namespace bodyscan::rules {

MeasurementSheet::MeasurementSheet(const TriangleMesh& body, BodyMeasurements* out) : body_(body), out_(out) {
  paths_ready_ = std::async(std::launch::async, [this] { paths_.emplace(body_); });
}

void MeasurementSheet::landmark(const std::string& name, const Eigen::Vector3d& p) {
  float confidence = 1;
  if (body_.confidence.size() == body_.vertices.size()) {
    const Vec3f q = p.cast<float>();
    float best = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < body_.vertices.size(); ++i)
      if (const float d = (body_.vertices[i] - q).squaredNorm(); d < best) best = d, confidence = body_.confidence[i];
  }
  out_->landmarks.push_back({name, p, confidence});
}

Eigen::Vector3d MeasurementSheet::position(const std::string& landmark) const {
  return out_->landmark(landmark)->position;
}

BodyMeasurement* MeasurementSheet::last(const std::string& name) {
  return !out_->measurements.empty() && out_->measurements.back().name == name ? &out_->measurements.back() : nullptr;
}

void MeasurementSheet::add(BodyMeasurement m) {
  // A height is read vertically at its landmark, a straight distance along its
  // line: a landmark on filled skin moves it by its offset from the seen skin in
  // that direction. Girths and surface lengths bring their own line's bound.
  const bool from_landmarks = m.kind == "height" || (m.kind == "distance" && m.path.size() == 2);
  const Eigen::Vector3d direction = m.kind == "height" ? Eigen::Vector3d::UnitY()
                                    : from_landmarks   ? (m.path[1] - m.path[0]).normalized()
                                                       : Eigen::Vector3d::Zero();
  for (const std::string& l : m.landmarks)
    if (const BodyLandmark* b = out_->landmark(l)) {
      m.min_confidence = std::min(m.min_confidence, b->confidence);
      if (from_landmarks && b->confidence < kMeasuredConfidence && m.fill_bound_mm)
        *m.fill_bound_mm += landmark_fill_offset_mm(body_, b->position, direction);
    }
  out_->measurements.push_back(std::move(m));
}

void MeasurementSheet::skip(const std::string& name, const std::string& why) {
  out_->skipped.push_back(name + ": " + why);
}

void MeasurementSheet::height(const std::string& name, const std::string& label, const std::string& clause,
                              std::vector<std::string> landmarks, const Eigen::Vector3d& p,
                              const std::string& definition) {
  BodyMeasurement m;
  m.name = name, m.label = label, m.iso_clause = clause, m.kind = "height";
  m.value_mm = p.y();
  m.path = {Eigen::Vector3d(p.x(), 0, p.z()), p};
  m.landmarks = std::move(landmarks);
  m.definition = definition;
  add(std::move(m));
}

void MeasurementSheet::girth(const std::string& name, const std::string& label, const std::string& clause,
                             const StatusOr<Girth>& g, std::vector<std::string> landmarks,
                             const std::string& definition) {
  if (!g.ok()) {
    skip(name, g.status().message());
    return;
  }
  BodyMeasurement m;
  m.name = name, m.label = label, m.iso_clause = clause, m.kind = "girth";
  m.value_mm = g->value_mm;
  m.path = g->tape;
  m.closed = true;
  m.loop = g->loop;
  m.plane = g->plane;
  m.landmarks = std::move(landmarks);
  m.definition = definition;
  m.min_confidence = g->min_confidence;
  m.fill_bound_mm = g->fill_bound_mm;
  add(std::move(m));
}

void MeasurementSheet::surface(const std::string& name, const std::string& label, const std::string& clause,
                               const std::vector<Eigen::Vector3d>& via, std::vector<std::string> landmarks,
                               const std::string& definition) {
  BodyMeasurement m;
  m.name = name, m.label = label, m.iso_clause = clause, m.kind = "surface_length";
  for (size_t i = 0; i + 1 < via.size(); ++i) {
    if (paths_ready_.valid()) paths_ready_.get();
    StatusOr<SurfacePath> p = paths_->shortest(via[i], via[i + 1]);
    if (!p.ok()) {
      skip(name, p.status().message());
      return;
    }
    m.value_mm += p->value_mm;
    m.min_confidence = std::min(m.min_confidence, p->min_confidence);
    *m.fill_bound_mm += p->fill_bound_mm;
    m.path.insert(m.path.end(), p->path.begin() + (m.path.empty() ? 0 : 1), p->path.end());
  }
  m.landmarks = std::move(landmarks);
  m.definition = definition;
  add(std::move(m));
}

}  // namespace bodyscan::rules
