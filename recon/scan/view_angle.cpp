#include "recon/scan/view_angle.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "recon/spatial/knn_index.hpp"
#include "recon/surface/estimate_normals.hpp"

namespace bodyscan {

ViewAngleResult weigh_by_view_angle(PointCloud& cloud, const ViewAngleOptions& options) {
  ViewAngleResult result;
  if (!cloud.has_cameras() || cloud.camera.size() != cloud.size() || cloud.size() <= options.k) return result;
  const KnnIndex index(cloud.positions);
  EstimateNormalsOptions normal_options;
  normal_options.k = options.k;
  LocalFrames frames = estimate_normals(cloud.positions, index, NeighborGraph{}, normal_options);
  const double cos_max = std::cos(options.max_view_deg * M_PI / 180);
  const double cos_full = std::cos(options.full_view_deg * M_PI / 180);
  const bool weigh = cloud.confidence.size() == cloud.size();
  std::vector<uint8_t> drop(cloud.size(), 0);
  tbb::parallel_for(size_t{0}, cloud.size(), [&](size_t i) {
    const int c = cloud.camera[i];
    if (c < 0 || static_cast<size_t>(c) >= cloud.camera_centres.size()) return;
    Vec3f& n = frames.normals[i];
    const Vec3f to_camera = (cloud.camera_centres[static_cast<size_t>(c)] - cloud.positions[i]).normalized();
    float cos_view = n.dot(to_camera);
    if (cos_view < 0) n = -n, cos_view = -cos_view;
    if (cos_view < cos_max) {
      drop[i] = 1;
      return;
    }
    if (weigh) cloud.confidence[i] *= static_cast<float>(std::min(1.0, cos_view / cos_full));
  });
  cloud.normals = std::move(frames.normals);
  result.dropped = cloud.remove_points(drop);
  return result;
}

}  // namespace bodyscan
