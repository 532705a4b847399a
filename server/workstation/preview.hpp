// What the station shows of a camera while it scans: the frame shrunk to a
// thumbnail an operator can read. A scan frame is mostly dark (room lights off)
// with a laser line a few pixels wide; a plain average would lose the line and
// leave the body black. The levels are stretched from the block means' own 1st to
// 99.5th percentile with a gamma of 0.6 (the body and the frames show), and a
// block whose brightest pixel is more than twice that top level is white: the
// line survives, sensor noise does not.
#pragma once

#include <string>

#include "core/status.hpp"
#include "hw/camera.hpp"
#include "recon/io/png_image.hpp"

namespace bodyscan::server {

// 8 bits, at most `width` pixels across (the frame's aspect kept).
StatusOr<GrayImage> preview_image(const hw::Frame& frame, int width);

// The same as an 8-bit PNG.
StatusOr<std::string> preview_png(const hw::Frame& frame, int width);

}  // namespace bodyscan::server
