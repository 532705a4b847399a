#include "recon/calib/frame_markers.hpp"

#include <algorithm>
#include <numeric>

#include "recon/calib/components.hpp"

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
  int count = 0;
  const std::vector<int> label = label_components(
      w, h, [&](int x, int y) { return diff(x, y) >= o.threshold; }, &count);
  std::vector<Marker> blobs(static_cast<size_t>(count));
  std::vector<Eigen::Vector2d> moment(static_cast<size_t>(count), Eigen::Vector2d::Zero());
  std::vector<Eigen::Vector4i> box(static_cast<size_t>(count), Eigen::Vector4i(w, h, -1, -1));  // x0, y0, x1, y1
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int l = label[static_cast<size_t>(y) * w + x];
      if (l < 0) continue;
      const double d = diff(x, y);
      Eigen::Vector4i& b = box[static_cast<size_t>(l)];
      b = Eigen::Vector4i(std::min(b(0), x), std::min(b(1), y), std::max(b(2), x), std::max(b(3), y));
      blobs[static_cast<size_t>(l)].area += 1;
      blobs[static_cast<size_t>(l)].mass += d;
      moment[static_cast<size_t>(l)] += d * Eigen::Vector2d(x, y);
    }
  // The centre: the light's whole spot, not only its pixels above the threshold.
  // The lens spreads a light's edge over a pixel or two, and the threshold (40 of
  // 255) cut that tail off unevenly where the spot is seen obliquely; the centroids
  // were 0.04-0.06 px off the true centres on every camera. Over the blob's box
  // widened by kTail pixels, every pixel not another blob's counts with its signed
  // difference (the background's noise averages out rather than adding up).
  constexpr int kTail = 3;
  std::vector<Marker> out;
  for (size_t i = 0; i < blobs.size(); ++i) {
    if (blobs[i].area < o.min_area || blobs[i].area > o.max_area) continue;
    const Eigen::Vector4i& b = box[i];
    double mass = 0;
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    for (int y = std::max(0, b(1) - kTail); y <= std::min(h - 1, b(3) + kTail); ++y)
      for (int x = std::max(0, b(0) - kTail); x <= std::min(w - 1, b(2) + kTail); ++x) {
        const int l = label[static_cast<size_t>(y) * w + x];
        if (l >= 0 && static_cast<size_t>(l) != i) continue;
        const double d = static_cast<int>(on.row(y)[x]) - static_cast<int>(off.row(y)[x]);
        mass += d;
        m += d * Eigen::Vector2d(x, y);
      }
    blobs[i].centre =
        mass > 0.5 * blobs[i].mass ? Eigen::Vector2d(m / mass) : Eigen::Vector2d(moment[i] / blobs[i].mass);
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
