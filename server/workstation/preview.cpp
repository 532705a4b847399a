#include "server/workstation/preview.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace bodyscan::server {

StatusOr<GrayImage> preview_image(const hw::Frame& f, int width) {
  if (f.width <= 0 || f.height <= 0 || f.pixels.size() < static_cast<size_t>(f.width) * f.height)
    return invalid_argument("preview: empty frame");
  if (width <= 0) return invalid_argument("preview: width must be positive");
  const int step = std::max(1, (f.width + width - 1) / width);
  const int w = std::max(1, f.width / step), h = std::max(1, f.height / step);
  const int full = f.max_value();
  // Each block's mean (the scene) and peak (a laser line a few pixels wide).
  std::vector<int> mean(static_cast<size_t>(w) * h), peak(mean.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint64_t sum = 0;
      int top = 0, n = 0;
      for (int dy = 0; dy < step && y * step + dy < f.height; ++dy)
        for (int dx = 0; dx < step && x * step + dx < f.width; ++dx, ++n) {
          const int p = f.at(x * step + dx, y * step + dy);
          sum += static_cast<uint64_t>(p);
          top = std::max(top, p);
        }
      mean[static_cast<size_t>(y) * w + x] = static_cast<int>(sum / std::max(1, n));
      peak[static_cast<size_t>(y) * w + x] = top;
    }
  // Levels from the scene (the means), so a bright line does not push the body
  // into black: the line saturates instead.
  std::vector<uint32_t> hist(static_cast<size_t>(full) + 1);
  for (int p : mean) ++hist[static_cast<size_t>(std::clamp(p, 0, full))];
  auto percentile = [&](double q) {
    const auto target = static_cast<uint64_t>(q * static_cast<double>(mean.size()));
    uint64_t seen = 0;
    for (size_t i = 0; i < hist.size(); ++i)
      if ((seen += hist[i]) > target) return static_cast<int>(i);
    return full;
  };
  const int lo = percentile(0.01);
  const int hi = std::max(lo + std::max(1, full / 64), percentile(0.995));  // a flat frame stays dark, not noise
  std::array<uint8_t, 1024> curve{};
  for (size_t i = 0; i < curve.size(); ++i)
    curve[i] = static_cast<uint8_t>(std::lround(255.0 * std::pow(static_cast<double>(i) / (curve.size() - 1), 0.6)));
  auto level = [&](double value) {
    const double t = std::clamp((value - lo) / (hi - lo), 0.0, 1.0);
    return curve[static_cast<size_t>(std::lround(t * (curve.size() - 1)))];
  };
  GrayImage img;
  img.width = w;
  img.height = h;
  img.bit_depth = 8;
  img.pixels.resize(mean.size());
  // A block's brightest pixel counts when it stands far above the scene (a laser
  // line), not for sensor noise.
  for (size_t i = 0; i < mean.size(); ++i) img.pixels[i] = peak[i] > 2 * hi ? uint8_t{255} : level(mean[i]);
  return img;
}

StatusOr<std::string> preview_png(const hw::Frame& frame, int width) {
  ASSIGN_OR_RETURN(GrayImage img, preview_image(frame, width));
  return encode_png(img, 6);
}

}  // namespace bodyscan::server
