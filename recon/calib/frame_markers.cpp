#include "recon/calib/frame_markers.hpp"

#include <algorithm>
#include <numeric>

namespace bodyscan {

StatusOr<std::vector<Marker>> find_markers(const ImageView& on, const ImageView& off, const MarkerOptions& o) {
  if (on.width != off.width || on.height != off.height || on.width <= 0 || on.height <= 0 || !on.pixels ||
      !off.pixels) {
    return invalid_argument("frame markers: the lights-on and lights-off images differ in size or are empty");
  }
  const int w = on.width, h = on.height;
  auto diff = [&](int x, int y) {
    const int d = static_cast<int>(on.row(y)[x]) - static_cast<int>(off.row(y)[x]);
    return d > 0 ? d : 0;
  };
  // Two-pass connected components (4-connected) with union-find on run labels.
  std::vector<int> label(static_cast<size_t>(w) * h, -1);
  std::vector<int> parent;
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (diff(x, y) < o.threshold) continue;
      const int left = x > 0 ? label[static_cast<size_t>(y) * w + x - 1] : -1;
      const int up = y > 0 ? label[static_cast<size_t>(y - 1) * w + x] : -1;
      int l;
      if (left < 0 && up < 0) {
        l = static_cast<int>(parent.size());
        parent.push_back(l);
      } else if (left >= 0 && up >= 0) {
        l = find(left);
        const int u = find(up);
        if (u != l) parent[std::max(u, l)] = std::min(u, l), l = std::min(u, l);
      } else {
        l = left >= 0 ? left : up;
      }
      label[static_cast<size_t>(y) * w + x] = l;
    }
  std::vector<Marker> blobs(parent.size());
  std::vector<Eigen::Vector2d> moment(parent.size(), Eigen::Vector2d::Zero());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int l = label[static_cast<size_t>(y) * w + x];
      if (l < 0) continue;
      const int r = find(l);
      const double d = diff(x, y);
      blobs[r].area += 1;
      blobs[r].mass += d;
      moment[r] += d * Eigen::Vector2d(x, y);
    }
  std::vector<Marker> out;
  for (size_t i = 0; i < blobs.size(); ++i) {
    if (blobs[i].area < o.min_area || blobs[i].area > o.max_area) continue;
    blobs[i].centre = moment[i] / blobs[i].mass;
    out.push_back(blobs[i]);
  }
  std::sort(out.begin(), out.end(), [](const Marker& a, const Marker& b) { return a.mass > b.mass; });
  return out;
}

StatusOr<FrameMarkers> order_frame_markers(const std::vector<Marker>& markers) {
  if (markers.size() != 8) {
    return failed_precondition("found " + std::to_string(markers.size()) +
                               " frame lights where 8 should be (4 per frame on the camera's side): " +
                               (markers.size() < 8 ? "a light is off, covered or outside the view"
                                                   : "something else lit up (a reflection, a lamp)"));
  }
  std::vector<Marker> m = markers;
  std::sort(m.begin(), m.end(), [](const Marker& a, const Marker& b) { return a.centre.y() < b.centre.y(); });
  // The two frames must be told apart: the gap between the 4th and 5th marker in y
  // must be the largest by far.
  double widest_inner = 0;
  for (int i = 0; i < 7; ++i)
    if (i != 3) widest_inner = std::max(widest_inner, m[i + 1].centre.y() - m[i].centre.y());
  if (m[4].centre.y() - m[3].centre.y() < 2 * widest_inner) {
    return failed_precondition("the 8 frame lights do not form a top and a bottom row of four (is the camera level?)");
  }
  FrameMarkers f;
  auto by_x = [](const Marker& a, const Marker& b) { return a.centre.x() < b.centre.x(); };
  std::sort(m.begin(), m.begin() + 4, by_x);
  std::sort(m.begin() + 4, m.end(), by_x);
  for (int i = 0; i < 4; ++i) {
    f.top[i] = m[i].centre;
    f.bottom[i] = m[4 + i].centre;
  }
  return f;
}

}  // namespace bodyscan
