#include "recon/measure/body_slicer.hpp"

#include <algorithm>
#include <cmath>

#include "recon/measure/plane_section.hpp"

namespace bodyscan {

bool Ring::crossing_z(double x, double* front, double* back) const {
  bool any = false;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& a = points[i];
    const Eigen::Vector3d& b = points[(i + 1) % points.size()];
    if ((a.x() < x) == (b.x() < x)) continue;
    const double t = (x - a.x()) / (b.x() - a.x());
    const double z = a.z() + t * (b.z() - a.z());
    if (!any) *front = *back = z;
    *front = std::max(*front, z);
    *back = std::min(*back, z);
    any = true;
  }
  return any;
}

bool Ring::crosses(const Ring& other) const {
  if (x_max < other.x_min || other.x_max < x_min || z_max < other.z_min || other.z_max < z_min) return false;
  const auto flat = [](const std::vector<Eigen::Vector3d>& loop) {
    std::vector<Eigen::Vector2d> out;
    out.reserve(loop.size());
    for (const Eigen::Vector3d& p : loop) out.emplace_back(p.x(), p.z());
    return out;
  };
  return loops_cross(flat(points), flat(other.points));
}

float Ring::crossing_confidence(double x) const {
  if (confidence.size() != points.size()) return 1;
  double front = -1e300, back = 1e300;
  float cf = 1, cb = 1;
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t j = (i + 1) % points.size();
    const Eigen::Vector3d& a = points[i];
    const Eigen::Vector3d& b = points[j];
    if ((a.x() < x) == (b.x() < x)) continue;
    const double t = (x - a.x()) / (b.x() - a.x());
    const double z = a.z() + t * (b.z() - a.z());
    const auto c = static_cast<float>((1 - t) * confidence[i] + t * confidence[j]);
    if (z > front) front = z, cf = c;
    if (z < back) back = z, cb = c;
  }
  return std::max(cf, cb);
}

BodySlicer::BodySlicer(const TriangleMesh& mesh, double y0, double y1, double step)
    : mesh_(mesh), y0_(y0), y1_(y1), step_(step) {
  const auto n = static_cast<size_t>(std::max(1.0, std::ceil((y1 - y0) / step)));
  bands_.resize(n);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tr = mesh.triangles[t];
    const double lo = std::min({mesh.vertices[tr[0]].y(), mesh.vertices[tr[1]].y(), mesh.vertices[tr[2]].y()});
    const double hi = std::max({mesh.vertices[tr[0]].y(), mesh.vertices[tr[1]].y(), mesh.vertices[tr[2]].y()});
    if (hi < y0 || lo > y1) continue;
    const auto b0 = static_cast<size_t>(std::clamp(std::floor((lo - y0) / step), 0.0, static_cast<double>(n - 1)));
    const auto b1 = static_cast<size_t>(std::clamp(std::floor((hi - y0) / step), 0.0, static_cast<double>(n - 1)));
    for (size_t b = b0; b <= b1; ++b) bands_[b].push_back(t);
  }
}

const std::vector<uint32_t>* BodySlicer::triangles_at(double y) const {
  const double b = std::floor((y - y0_) / step_);
  if (b < 0 || b >= static_cast<double>(bands_.size())) return nullptr;
  return &bands_[static_cast<size_t>(b)];
}

std::vector<Ring> BodySlicer::rings(double y) const {
  std::vector<Ring> out;
  const std::vector<uint32_t>* tris = triangles_at(y);
  if (!tris) return out;
  const Plane plane{Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitY()};
  std::vector<SectionLoop> loops = plane_section(mesh_, plane, tris);
  drop_nested_loops(&loops, plane);
  for (SectionLoop& loop : loops) {
    if (!loop.closed) continue;
    Ring r;
    std::vector<Eigen::Vector2d> flat;
    flat.reserve(loop.points.size());
    double area = 0, cx = 0, cz = 0;
    r.x_min = r.z_min = 1e300;
    r.x_max = r.z_max = -1e300;
    for (size_t i = 0; i < loop.points.size(); ++i) {
      const Eigen::Vector3d& a = loop.points[i];
      const Eigen::Vector3d& b = loop.points[(i + 1) % loop.points.size()];
      flat.emplace_back(a.x(), a.z());
      const double c = a.x() * b.z() - b.x() * a.z();
      area += c;
      cx += (a.x() + b.x()) * c;
      cz += (a.z() + b.z()) * c;
      r.x_min = std::min(r.x_min, a.x()), r.x_max = std::max(r.x_max, a.x());
      r.z_min = std::min(r.z_min, a.z()), r.z_max = std::max(r.z_max, a.z());
    }
    if (std::abs(area) > 1e-9)
      r.centroid = Eigen::Vector3d(cx / (3 * area), y, cz / (3 * area));
    else
      r.centroid = Eigen::Vector3d(0.5 * (r.x_min + r.x_max), y, 0.5 * (r.z_min + r.z_max));
    r.girth = closed_length(convex_hull(std::move(flat)));
    r.min_confidence =
        loop.confidence.empty() ? 1.f : *std::min_element(loop.confidence.begin(), loop.confidence.end());
    r.points = std::move(loop.points);
    r.confidence = std::move(loop.confidence);
    out.push_back(std::move(r));
  }
  return out;
}

StatusOr<Girth> BodySlicer::girth(double y, const Eigen::Vector3d& near) const {
  const std::vector<uint32_t>* tris = triangles_at(y);
  if (!tris) return not_found("girth: height " + std::to_string(y) + " mm is off the body");
  return mesh_girth(mesh_, Plane{Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitY()}, near, tris);
}

}  // namespace bodyscan
