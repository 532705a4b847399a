#include "recon/scan/redundancy.hpp"

#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "recon/spatial/knn_index.hpp"

namespace bodyscan {

size_t drop_redundant_points(PointCloud& cloud, float radius, float ratio, float weak) {
  if (cloud.confidence.size() != cloud.size() || cloud.empty()) return 0;
  const KnnIndex index(cloud.positions);
  std::vector<uint8_t> drop(cloud.size(), 0);
  const bool frames = cloud.frame.size() == cloud.size(), cameras = cloud.camera.size() == cloud.size();
  tbb::parallel_for(size_t{0}, cloud.size(), [&](size_t i) {
    const float c = cloud.confidence[i];
    const float need = c < weak ? std::nextafter(c, 2.f) : ratio * c;
    if (need > 1.f) return;  // nothing can be that much better
    for (const auto& [j, d2] : index.within_radius(cloud.positions[i], radius, false)) {  // any one will do
      if (j == i || cloud.confidence[j] < need) continue;
      const bool other =
          (frames && cloud.frame[j] != cloud.frame[i]) || (cameras && cloud.camera[j] != cloud.camera[i]);
      if (other) {
        drop[i] = 1;
        return;
      }
    }
  });
  return cloud.remove_points(drop);
}

}  // namespace bodyscan
