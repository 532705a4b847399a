// The thesis's implicit field (§3.2.2.2, §3.2.3) on a sparse grid of bricks.
//
// Each point contributes an anisotropic kernel in its own frame (t1, t2, n):
//     f_i(x) = w_i * G(t1 / s1) * G(t2 / s2) * G'(n / sn),   G(z) = exp(-z^2 / 2)
// (eq. 3.14-3.15). The derivative lobe is taken on the normalised coordinate,
// G'(z) = -z exp(-z^2/2), so each kernel's peak is the same whatever its size and a
// point in a sparse region is not drowned by its denser neighbours; the thesis's
// 1/sn^2 factor would weight sparse regions less. The field is positive inside
// (behind the normals) and negative outside; the surface is its zero level set.
// Beside the field the grid keeps the Gaussian weight W = sum w_i G G G, the local
// evidence: a node counts as defined only inside some kernel's support (W > 0), and
// marching cubes may demand more.
//
// Curvature compensation (beyond the thesis): a flat kernel's zero set is its
// point's tangent plane, and on a curved surface the neighbours' tangent planes all
// pass outside a convex point, pushing the summed zero set out by about
// H sigma_t^2 (H the mean curvature) - the bias that dominates the thesis's sparse
// sphere cells. A kernel may therefore carry the surface's normal curvatures along
// its two axes, `bend1` and `bend2`, and measure its normal coordinate from the
// osculating paraboloid instead of the plane, n' = n + (bend1 t1^2 + bend2 t2^2) / 2,
// which removes that bias to first order. With the axes along the principal
// directions the paraboloid is the surface's own. A single mean-curvature bend is
// enough only where the neighbours surround a point evenly: on a limb sampled by
// stripes across it, the kernels on either side along the stripe (bent by half the
// limb's curvature) outweigh those along the limb (bent where the limb is
// straight), and the limb comes out too thick.
// Past the paraboloid's second order, the sag grows as a circle's would,
// sag * 2 / (1 + sqrt(1 - x)) with x = bend1^2 t1^2 + bend2^2 t2^2: exact for a
// sphere and for a cylinder along either axis.
//
// Support: a kernel is cut where its Gaussian falls below the error tolerance
// epsilon, i.e. the ellipsoid |(t1/s1, t2/s2, n/sn)| < sqrt(-2 ln epsilon): eq.
// 3.26-3.27 (D = 2 sigma sqrt(-2 ln epsilon) is that ellipsoid's diameter).
//
// Storage follows the surface (thesis fig. 3.28, sub-fields): the grid is cut into
// cubic bricks of brick_size^3 nodes and only bricks that some kernel's visited
// nodes (its support, cut by its band) reach are allocated. Every node's value is the sum of its kernels in increasing
// point order, so the field is bit-identical whatever the brick size.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/progress.hpp"
#include "core/status.hpp"
#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

// One point's kernel. Axes are unit and orthogonal; sigmas in the points' unit.
struct Kernel {
  Vec3f center;
  Vec3f t1, t2, n;  // n points out of the surface
  float sigma_t1 = 1.f, sigma_t2 = 1.f, sigma_n = 1.f;
  float weight = 1.f;  // confidence, > 0
  // Normal curvatures (1 / length) along t1 and t2, positive where the surface
  // bends away from n. 0 = the thesis's flat kernel. Callers keep |bend_a| sigma_t_a
  // well below 1.
  float bend1 = 0.f, bend2 = 0.f;
  // If > 0, the kernel reaches at most this far along its normal (before the
  // bend), the points' unit. Marching cubes only needs the field within a few
  // voxels of the surface, and every kernel that matters there has its plane that
  // close (within the noise), so a band of a few voxels plus the noise keeps the
  // field near the surface while skipping most of each kernel's normal extent.
  float band = 0.f;
};

struct ImplicitFieldOptions {
  float voxel_size = 1.f;  // grid spacing, the points' unit (> 0)
  float epsilon = 1e-3f;   // error tolerance of eq. 3.26, in (0, 1)
  int brick_size = 16;     // nodes per brick side, a power of two in [2, 1024]
  // Refuse to allocate more than this many bricks (each brick_size^3 * 8 bytes):
  // protects against a voxel size far too small for the cloud.
  size_t max_bricks = 4'000'000;
  ProgressFn progress;
};

class ImplicitField {
 public:
  float voxel_size() const { return voxel_size_; }
  int brick_size() const { return brick_size_; }
  // World position of grid node (0,0,0).
  const Vec3d& origin() const { return origin_; }
  size_t num_bricks() const { return keys_.size(); }
  size_t nodes_per_brick() const { return static_cast<size_t>(brick_size_) * brick_size_ * brick_size_; }
  size_t memory_bytes() const;

  // Brick b's integer coordinates (node coordinates / brick_size).
  Eigen::Vector3i brick_coord(size_t b) const;
  // Index of the brick at brick coordinates c, or -1 when it is not allocated.
  long find_brick(const Eigen::Vector3i& c) const;

  // Node values of brick b, x fastest: index = x + B (y + B z).
  const float* values(size_t b) const { return blocks_[b].get(); }
  const float* weights(size_t b) const { return blocks_[b].get() + nodes_per_brick(); }

  // Field and weight at global node (i, j, k); weight 0 when not allocated.
  float value_at(const Eigen::Vector3i& node) const;
  float weight_at(const Eigen::Vector3i& node) const;
  Vec3d node_position(const Eigen::Vector3i& node) const {
    return origin_ + static_cast<double>(voxel_size_) * node.cast<double>();
  }

  // Evaluates the field directly from the kernels at any position (for tests).
  static void evaluate(const std::vector<Kernel>& kernels, float epsilon, const Vec3d& x, double* value,
                       double* weight);

 private:
  friend StatusOr<ImplicitField> build_implicit_field(const std::vector<Kernel>&, const ImplicitFieldOptions&);
  static uint64_t pack(const Eigen::Vector3i& c);
  float voxel_size_ = 1.f;
  int brick_size_ = 8;
  int brick_shift_ = 3;
  Vec3d origin_ = Vec3d::Zero();
  std::vector<uint64_t> keys_;  // sorted packed brick coordinates
  // Brick b's values, then its weights: allocated one by one, as kernels first
  // reach them, so that only bricks some kernel's band touches take memory.
  std::vector<std::unique_ptr<float[]>> blocks_;
};

// The median Gaussian weight W at the grid nodes nearest to the given surface
// points (at most `max_samples`, evenly strided): the weight the surface itself
// carries. Kernels scale with the local spacing, so about the same number of
// points overlaps anywhere on the surface and this median is a scale for the whole
// field: a zero crossing where W is far below it lies in the tails of a few
// kernels, where the sum's sign is noise, not surface. 0 when no point has weight.
float median_surface_weight(const ImplicitField& field, const std::vector<Vec3f>& points, size_t max_samples = 20000);

// Sums every kernel into a sparse grid. Runs in parallel over bricks.
StatusOr<ImplicitField> build_implicit_field(const std::vector<Kernel>& kernels, const ImplicitFieldOptions& options);

}  // namespace bodyscan
