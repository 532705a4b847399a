#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

namespace {

template <typename T>
bool absent_or_per_point(const std::vector<T>& attribute, size_t n) {
  return attribute.empty() || attribute.size() == n;
}

template <typename T>
void keep_unmarked(std::vector<T>& v, const std::vector<uint8_t>& drop) {
  if (v.empty()) return;
  size_t k = 0;
  for (size_t i = 0; i < v.size(); ++i)
    if (!drop[i]) v[k++] = v[i];
  v.resize(k);
}

}  // namespace

bool PointCloud::is_consistent() const {
  const size_t n = positions.size();
  if (!absent_or_per_point(normals, n) || !absent_or_per_point(intensity, n) || !absent_or_per_point(confidence, n) ||
      !absent_or_per_point(camera, n) || !absent_or_per_point(laser, n) || !absent_or_per_point(frame, n)) {
    return false;
  }
  // Camera ids may come without centres (has_cameras() is then false and nothing
  // indexes camera_centres), e.g. from a PLY with a per-vertex `camera` property but
  // no `camera` element; only ids that could be used to index must be in range.
  const auto num_centres = static_cast<int64_t>(camera_centres.size());
  for (int32_t id : camera) {
    if (id == kUnknownSource) continue;
    if (id < 0) return false;
    if (num_centres > 0 && id >= num_centres) return false;
  }
  return true;
}

size_t PointCloud::remove_points(const std::vector<uint8_t>& drop) {
  const size_t before = size();
  keep_unmarked(positions, drop);
  keep_unmarked(normals, drop);
  keep_unmarked(intensity, drop);
  keep_unmarked(confidence, drop);
  keep_unmarked(camera, drop);
  keep_unmarked(laser, drop);
  keep_unmarked(frame, drop);
  return before - size();
}

}  // namespace bodyscan
