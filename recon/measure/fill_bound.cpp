#include "recon/measure/fill_bound.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodyscan {

namespace {

using Points = std::vector<Eigen::Vector3d>;

// The length along `points` from index `from`, `steps` segments on (round the end
// of a closed line), beyond the straight chord between its two ends.
double stretch_excess(const Points& points, size_t from, size_t steps) {
  const size_t n = points.size();
  double along = 0;
  for (size_t k = 0; k < steps; ++k) along += (points[(from + k + 1) % n] - points[(from + k) % n]).norm();
  return along - (points[(from + steps) % n] - points[from]).norm();
}

// A closed line with a seen point at `first_seen`: each run of filled points,
// from the seen point before it to the seen point after it.
double closed_excess(const Points& points, const std::vector<bool>& seen, size_t first_seen) {
  const size_t n = points.size();
  double excess = 0;
  size_t last_k = 0;  // k counts steps from first_seen; k = n is that point again
  for (size_t k = 1; k <= n; ++k) {
    if (!seen[(first_seen + k) % n]) continue;
    if (k - last_k > 1) excess += stretch_excess(points, (first_seen + last_k) % n, k - last_k);
    last_k = k;
  }
  return excess;
}

// An open line: the same, a run that starts at the first point or ends at the
// last anchored there.
double open_excess(const Points& points, const std::vector<bool>& seen) {
  const size_t n = points.size();
  double excess = 0;
  size_t anchor = 0;
  for (size_t i = 1; i < n; ++i) {
    if (!seen[i] && i + 1 < n) continue;
    if (i - anchor > 1) excess += stretch_excess(points, anchor, i - anchor);
    anchor = i;
  }
  return excess;
}

}  // namespace

std::optional<double> filled_stretch_excess_mm(const Points& points, const std::vector<float>& confidence,
                                               bool closed) {
  const size_t n = points.size();
  if (confidence.size() != n) return std::nullopt;
  if (n < 2) return 0.0;
  std::vector<bool> seen(n);
  for (size_t i = 0; i < n; ++i) seen[i] = confidence[i] >= kMeasuredConfidence;
  const auto first_seen = static_cast<size_t>(std::find(seen.begin(), seen.end(), true) - seen.begin());
  if (first_seen == n) {  // nothing seen: the whole length
    double length = 0;
    for (size_t i = 0; i + 1 < n; ++i) length += (points[i + 1] - points[i]).norm();
    return closed ? length + (points[0] - points[n - 1]).norm() : length;
  }
  return closed ? closed_excess(points, seen, first_seen) : open_excess(points, seen);
}

double landmark_fill_offset_mm(const TriangleMesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& direction) {
  if (mesh.confidence.size() != mesh.vertices.size() || mesh.vertices.empty()) return 0;
  const Vec3f q = p.cast<float>();
  float nearest = std::numeric_limits<float>::infinity(), nearest_seen = nearest;
  size_t at = 0, at_seen = mesh.vertices.size();
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const float d = (mesh.vertices[i] - q).squaredNorm();
    if (d < nearest) nearest = d, at = i;
    if (mesh.confidence[i] >= kMeasuredConfidence && d < nearest_seen) nearest_seen = d, at_seen = i;
  }
  if (mesh.confidence[at] >= kMeasuredConfidence) return 0;
  if (at_seen == mesh.vertices.size()) return std::numeric_limits<double>::infinity();  // nothing seen at all
  const Eigen::Vector3d offset = mesh.vertices[at_seen].cast<double>() - p;
  return direction.squaredNorm() > 0 ? std::abs(offset.dot(direction)) : offset.norm();
}

}  // namespace bodyscan
