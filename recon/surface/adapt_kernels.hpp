// Each point's kernel size from local density and curvature (thesis §3.2.2.3-4).
//
// Density (eq. 3.17-3.18): sigma_density = mean distance to the n nearest
// neighbours (n = 10), sigma_t = sigma_density * sigma_user, so the same sigma_user
// works in inches and millimetres and in sparse and dense regions alike.
//
// Curvature (eq. 3.24-3.25): sigma_t_a is lowered where the surface bends along
// t_a. The thesis writes sigma_t = sigma_density sigma_user - s c / sigma_density,
// which mixes units (c is 1/length): it is scale-invariant only in the form
//     sigma_t_a = sigma_density (sigma_user - s c_a sigma_density),
// where c_a sigma_density is the curvature relative to the point spacing (eq. 3.23
// without the division by distance is exactly such a dimensionless quantity). We
// use that form, so the thesis's promise of no re-tuning between units holds.
// sigma_t never drops below min_sigma_fraction of its density value.
//
// Normal direction: sigma_n = normal_scale * sigma_density (the thesis tunes sigma_n
// to the noise; reconstruct_surface() picks normal_scale from the estimated noise).
#pragma once

#include <vector>

#include "recon/geometry/point_cloud.hpp"
#include "recon/spatial/knn_index.hpp"
#include "recon/surface/estimate_curvature.hpp"
#include "recon/surface/estimate_normals.hpp"
#include "recon/surface/implicit_field.hpp"

namespace bodyscan {

struct AdaptKernelsOptions {
  float sigma_user = 1.f;     // tangential size in units of sigma_density
  float normal_scale = 0.5f;  // sigma_n in units of sigma_density
  float sharpening = 0.f;     // s; 0 = no curvature adaptation
  float min_sigma_fraction = 0.25f;
  // Bend kernels by the surface's normal curvatures along their axes
  // (implicit_field.hpp), each clamped so that |bend| sigma_t <= max_bend. A round
  // kernel (sigma_t1 = sigma_t2) first turns its axes to the principal directions.
  bool curvature_compensation = true;
  float max_bend = 0.7f;
  // Per-axis noise of the points (the cloud's unit). Noise along a curved surface
  // moves points to its convex side on average, by H sigma^2 (a point displaced by
  // t along the tangent plane of a sphere of radius R lies |t|^2 / 2R outside it);
  // with curvature compensation each kernel is moved back by that much.
  float noise_sigma = 0.f;
  // Normal reach of every kernel (Kernel::band), the points' unit; 0 = the full
  // support.
  float band = 0.f;
};

// Mean distance to the `k` nearest neighbours of each point (eq. 3.17).
std::vector<float> density_sigma(const NeighborGraph& graph, size_t k);

// Builds one kernel per point. frames: oriented (normals outward). curvature: may
// be null when options.sharpening == 0. shape: one per point (in the frames'
// tangents), or empty when options.curvature_compensation is off. confidence: empty (all 1) or one per point;
// points with confidence <= 0 are dropped.
std::vector<Kernel> adapt_kernels(const std::vector<Vec3f>& points, const LocalFrames& frames,
                                  const std::vector<float>& sigma_density, const CurvatureResult* curvature,
                                  const std::vector<ShapeOperator>& shape, const std::vector<float>& confidence,
                                  const AdaptKernelsOptions& options);

}  // namespace bodyscan
