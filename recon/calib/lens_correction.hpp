// Lens-distortion correction from one image of a dot grid (thesis §3.1.1): a flat
// white board with a square grid of black dots, held facing the camera. The dots'
// centroids are found (local thresholding), each is given its place (col, row) in
// the grid, and the undistorted image of the grid is taken to be the homography of
// the places that best fits the dots near the image centre, where a lens distorts
// least. Thin-plate splines (thesis fig. 3.1) carry captured pixels to these ideal
// ones and back. No lens model is assumed, so any smooth distortion is corrected;
// the ideal image is the true pinhole image only up to a homography, which the
// plane transforms of the next step (§3.1.2) absorb.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/status.hpp"
#include "recon/scan/stripe.hpp"  // ImageView

namespace bodyscan {

struct Dot {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // darkness-weighted centroid, pixels
  int area = 0;                                      // pixels below the threshold
  double mass = 0;                                   // summed darkness (local background - value)
};

struct DotOptions {
  // Side of the box the local mean is taken over, pixels (odd, 3..255): about 2-3
  // dot diameters, so a dot is dark against its surroundings whatever the lighting.
  int window = 41;
  // A dot pixel is darker than the local mean by this fraction of it (and, in dim
  // parts such as the room beside the board, by this fraction of a quarter of the
  // image's white).
  double contrast = 0.25;
  int min_area = 12;          // smaller blobs are noise
  int max_area = 0;           // larger ones are not dots; 0: half the window's area
  double max_elongation = 3;  // ratio of a blob's principal axes; longer ones are edges
};

// The dots of a dot-grid image, in raster order of their first pixel. Blobs within
// six pixels of the image border are left out: part of their dot may be cut off,
// and their background cannot be measured all round. Errors: an empty image or
// options out of range.
StatusOr<std::vector<Dot>> find_dots(const ImageView& image, const DotOptions& options = {});

struct GridDot {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  int col = 0, row = 0;
};

struct GridOptions {
  // A neighbour is accepted within this fraction of a grid step of where the
  // neighbouring steps predict it.
  double tolerance = 0.3;
};

// The dots that form the square grid, each with its place: grown from a dot near the
// middle, predicting each neighbour from the local grid steps (so the distortion is
// followed). The grid may be turned in-plane by any angle; col grows roughly with
// image x and row with image y, and (0, 0) is the seed. Dots the growth never
// reaches (stray blobs) are left out, as are both sides of a conflict (one dot
// claimed by two places or one place by two dots). Empty when no grid is found.
std::vector<GridDot> index_grid(const std::vector<Dot>& dots, const GridOptions& options = {});

struct LensOptions {
  DotOptions dots;
  GridOptions grid;
  // The ideal homography is fitted to the dots within this fraction of the image's
  // half-diagonal from its centre (or the `min_centre_dots` nearest, if more).
  double centre_fraction = 0.3;
  int min_centre_dots = 12;
  // Fewer indexed dots cannot pin the splines down across the image; at least twice
  // the polynomial part's (degree + 1)(degree + 2)/2 terms.
  int min_dots = 42;
  // Thin-plate spline smoothing: added to the kernel matrix's diagonal, with the dots'
  // coordinates scaled to unit RMS radius. 0 interpolates the centroids, noise and
  // all; the default, tuned on the simulated thesis rig (held-out error 0.017 px),
  // trims the error between dots by a sixth.
  double smoothing = 0.01;
  // Degree of the splines' polynomial part, 1..5. 1 is the thesis's (affine); 5 takes
  // in a lens's radial distortion up to r^5 (Brown-Conrady k1, k2), so the kernels
  // only interpolate what is left: on the thesis rig the error between dots halves,
  // the worst one falls fivefold and the extrapolation beyond the outermost dots
  // sixfold.
  int degree = 5;
  int table_step = 8;  // pixels between the nodes of the tables correct() and distort() interpolate
};

// Immutable once fitted (copies share the tables), so it may be used from many
// threads at once.
class LensCorrection {
 public:
  LensCorrection() = default;  // no correction: correct() and distort() return their argument

  // From indexed dots of a `width` x `height` image. Also computes the held-out
  // residual (5 folds, each every fifth dot along the diagonals, so a held-out dot
  // keeps its four neighbours). Errors: fewer than options.min_dots dots, non-finite
  // centres, a grid whose places are degenerate (all on one line).
  static StatusOr<LensCorrection> fit(const std::vector<GridDot>& dots, int width, int height,
                                      const LensOptions& options = {});

  // Captured pixel -> ideal pixel: O(1), a bicubic (Catmull-Rom) interpolation of the
  // spline tabulated every table_step pixels over the image and a margin; the exact
  // spline beyond.
  Eigen::Vector2d correct(const Eigen::Vector2d& captured) const;
  // Ideal pixel -> captured pixel: the inverse splines, tabulated the same way, then
  // a Newton step on correct(), so that the two agree to ~1e-5 pixel.
  Eigen::Vector2d distort(const Eigen::Vector2d& ideal) const;
  // The same from the splines themselves, O(dots) per call.
  Eigen::Vector2d correct_exact(const Eigen::Vector2d& captured) const;
  Eigen::Vector2d distort_exact(const Eigen::Vector2d& ideal) const;

  // The lens-corrected image (same size, ideal pixel coordinates; black where the
  // lens saw nothing), bilinear samples through a per-pixel table built at fit time.
  // Error: the image is not the size the correction was fitted for.
  StatusOr<std::vector<uint16_t>> remap(const ImageView& image) const;

  int width() const { return width_; }
  int height() const { return height_; }
  int dots_found() const { return dots_found_; }  // blobs find_dots returned (calibrate_lens)
  int dots_used() const { return dots_used_; }    // indexed dots the splines were fitted to
  // RMS distance (pixels) between the splines' images of the dots and their ideal
  // positions: the smoothing's share of the residual.
  double fit_rms_px() const { return fit_rms_; }
  // RMS distance (pixels) between held-out dots' corrected and ideal positions: the
  // correction's accuracy between dots, centroid noise included.
  double held_out_rms_px() const { return held_out_rms_; }
  // What fit() was given (empty for the identity): fitting them again with the
  // same options and image size gives this correction again, exactly.
  const std::vector<GridDot>& grid_dots() const;
  const LensOptions& options() const;
  void set_dots_found(int n) { dots_found_ = n; }  // for a correction rebuilt from its dots

 private:
  struct State;
  friend StatusOr<LensCorrection> calibrate_lens(const ImageView& dot_grid_image, const LensOptions& options);
  Eigen::Vector2d inverse_estimate(const Eigen::Vector2d& ideal) const;  // the inverse splines' table

  std::shared_ptr<const State> state_;  // null: the identity; shared, as it never changes
  int width_ = 0, height_ = 0;
  int dots_found_ = 0, dots_used_ = 0;
  double fit_rms_ = 0, held_out_rms_ = 0;
};

// The whole of §3.1.1 on one image of the dot grid: find_dots, index_grid, fit.
// Errors say what is missing: no dots at all, or how many were indexed and how many
// are needed.
StatusOr<LensCorrection> calibrate_lens(const ImageView& dot_grid_image, const LensOptions& options = {});

}  // namespace bodyscan
