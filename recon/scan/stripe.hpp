// Laser stripe extraction (thesis §3.1.4): per image row, the brightest pixel of the
// frame minus the base frame (taken just before the laser came on), kept if it
// passes a threshold, refined to sub-pixel by the intensity-weighted centroid within
// a radius. This is the hot loop of a real-time scanner: the rows run in parallel
// and the per-row maximum is a vectorised pass over 16-bit pixels.
#pragma once

#include <cstdint>
#include <vector>

#include "core/status.hpp"

namespace bodyscan {

// A view of a 16-bit grayscale image (the Frame layout of hw/camera.hpp: values in
// the low bits, row-major).
struct ImageView {
  const uint16_t* pixels = nullptr;
  int width = 0, height = 0;
  const uint16_t* row(int y) const { return pixels + static_cast<size_t>(y) * width; }
};

struct StripeOptions {
  int threshold = 20;  // minimum peak of frame - base, in pixel values
  int radius = 4;      // half-width of the centroid window (the thesis's r)
};

struct StripeSample {
  int row = 0;
  float column = 0;        // sub-pixel, image x (pixel centres at integers)
  uint16_t peak = 0;       // frame - base at the brightest pixel
  bool saturated = false;  // the frame itself hit full scale inside the window
};

// Columns [begin, end) of one row; an empty range skips the row.
struct ColumnRange {
  int begin = 0, end = 0;
};

// The stripe samples of one frame, one per row at most, in row order. With
// `windows` (one range per row), each row is searched inside its range only: where
// the laser plane can meet the subject, so another laser's stripe or a reflection
// elsewhere in the row cannot win. Errors: the frame and base differ in size, the
// windows do not match the rows, or the options are out of range.
StatusOr<std::vector<StripeSample>> extract_stripe(const ImageView& frame, const ImageView& base,
                                                   const StripeOptions& options = {}, int full_scale = 255,
                                                   const std::vector<ColumnRange>* windows = nullptr);

// Smooths a frame's samples along the stripe: each column becomes the value at its
// row of the parabola fitted (least squares) to the samples within `half_window`
// rows that continue the stripe (each within `max_step` pixels per row of the one
// before); near an end of the stripe, with fewer than two such samples on a side,
// of a straight line. The stripe is a curve across rows while speckle and sensor
// noise are independent from row to row, so this averages the noise of
// 2 * half_window + 1 samples. A straight line's value at the middle row is the
// window's mean, which lies toward the inside of a curved stripe: on a body, whose
// stripes curve round it, that put every point 0.06-0.10 mm inside the skin
// (bench/stripe_fidelity --noisy), and a limb's girth 0.5 mm small. A parabola
// leaves only the curve's fourth-order part. Samples without two neighbours on the
// stripe keep their column.
void smooth_stripe(std::vector<StripeSample>& samples, int half_window = 5, double max_step = 1.5);

// Drops the samples of runs shorter than `min_rows` (a run: consecutive rows whose
// columns differ by at most `max_step` px; smooth_stripe's step per row, though
// smooth_stripe also reaches across missing rows and this does not) and returns
// how many. A sample with no neighbour on its stripe is where a stripe is
// glimpsed for one row, between a limb and the skin it hides or at a silhouette,
// and nothing along the stripe confirms it. Few samples are such, but they hold
// most of those that land far off the skin (bench/stripe_fidelity --noisy).
size_t drop_short_runs(std::vector<StripeSample>& samples, int min_rows = 2, double max_step = 1.5);

}  // namespace bodyscan
