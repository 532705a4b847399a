// Grayscale PNG files (libpng): 8- or 16-bit, written atomically like every file we
// write (temporary file, fsync, rename).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/status.hpp"

namespace bodyscan {

struct GrayImage {
  int width = 0, height = 0;
  int bit_depth = 8;             // 8 or 16
  std::vector<uint16_t> pixels;  // row-major; values < 2^bit_depth
};

// zlib level 1-9 (speed against size); 1 suits the mostly dark frames of a scan.
Status write_png(const std::string& path, const GrayImage& image, int compression = 1);
// The PNG file's bytes, in memory (camera previews sent to browsers).
StatusOr<std::string> encode_png(const GrayImage& image, int compression = 1);
StatusOr<GrayImage> read_png(const std::string& path);

}  // namespace bodyscan
