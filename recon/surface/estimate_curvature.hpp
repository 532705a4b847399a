// Normal-section curvature along each principal tangent direction (thesis §3.2.2.4).
//
// For a point p with frame (t1, t2, n) and direction t_a (a = 1, 2), the neighbours
// lying near the plane spanned by t_a and n are projected into it and a circle is
// fitted to them by Levenberg-Marquardt on the geometric distance (thesis ref. [15]).
// The fit is checked against the stable normal-angle estimate (eq. 3.22-3.23),
// c = mean over neighbours of 2 sin(theta/2) / dist: where the circle is unstable
// (no convergence, too few points, or a curvature far above the angle estimate) the
// angle estimate is used, as the thesis does.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "recon/geometry/point_cloud.hpp"
#include "recon/spatial/knn_index.hpp"
#include "recon/surface/estimate_normals.hpp"

namespace bodyscan {

struct EstimateCurvatureOptions {
  size_t k = 20;  // neighbours considered (the graph must have at least this many)
  // A neighbour belongs to the (t_a, n) plane when its direction is within this
  // angle of the plane, radians.
  float plane_angle = 0.5236f;  // 30 degrees
  // The circle is unstable when its curvature exceeds `instability_ratio` times the
  // angle estimate plus one over (instability_ratio x neighbourhood radius).
  float instability_ratio = 2.5f;
  int max_iterations = 4;
};

struct CurvatureResult {
  // |curvature| (1 / length unit) of the normal section along tangent1 and tangent2.
  std::vector<Eigen::Vector2f> curvature;
  size_t circle_fits_used = 0;  // sections where the circle fit was kept
  size_t angle_fallbacks = 0;   // sections where the angle estimate replaced it
};

// Circle fit for one section. u: positions along the tangent, h: heights along the
// normal, both relative to the point, which is included by the caller if wanted.
// Returns the signed curvature (positive when the circle's centre is on -n, i.e. the
// surface bends away from the normal, as on a sphere with outward normals), or NaN
// when the fit is not determined.
float fit_circle_curvature(const float* u, const float* h, size_t count, int max_iterations);

// The normal-angle curvature estimate (eq. 3.23 divided by the distances, i.e. the
// mean of eq. 3.22 over the neighbours given), unsigned.
float angle_curvature(const Vec3f& p, const Vec3f& n, const std::vector<Vec3f>& points,
                      const std::vector<Vec3f>& normals, const uint32_t* neighbours, size_t count);

// A quadric height field h = a u^2 + b uv + c v^2 + d u + e v + f fitted by least
// squares to a point (at the origin) and its neighbours in its frame (u along
// tangent1, v along tangent2, h along the normal).
struct LocalQuadric {
  Eigen::Matrix<double, 6, 1> coef = Eigen::Matrix<double, 6, 1>::Zero();  // a b c d e f
  double residual_rms = 0.0;                                               // corrected for the six fitted parameters
  bool ok = false;
  // Mean curvature, positive where the surface bends away from the normal (convex
  // with outward normals): -(a + c) for a near-level fit.
  double mean_curvature() const { return -(coef[0] + coef[2]); }
};
LocalQuadric fit_local_quadric(const std::vector<Vec3f>& points, size_t i, const uint32_t* neighbours, size_t count,
                               const LocalFrames& frames);

// A point's shape operator in its own frame: the normal turns by dn = S d for a
// small step d in the tangent plane, S = [[s11, s12], [s12, s22]] in (tangent1,
// tangent2) coordinates. s11 and s22 are the normal curvatures along tangent1 and
// tangent2, positive where the surface bends away from the normal; the mean
// curvature is (s11 + s22) / 2 and the principal curvatures are S's eigenvalues.
struct ShapeOperator {
  float s11 = 0.f, s12 = 0.f, s22 = 0.f;
  float mean() const { return 0.5f * (s11 + s22); }
};

struct MeanCurvatureOptions {
  // Neighbours per quadric fit. Up to graph.k they come from the graph; more are
  // queried from the index (a noisy cloud needs fits as wide as its kernels).
  size_t k = 20;
  int smoothing_passes = 2;  // neighbour averages of the result
  size_t smoothing_k = 10;
};

// Each point's shape operator (1 / length unit) from the turning of the normals
// over its neighbourhood (least squares), smoothed over the neighbour graph: each
// neighbour's operator is carried into the point's frame (the smallest rotation
// taking its normal onto the point's) before the average. frames must be oriented
// (the signs follow the normals).
std::vector<ShapeOperator> estimate_shape_operators(const std::vector<Vec3f>& points, const KnnIndex& index,
                                                    const NeighborGraph& graph, const LocalFrames& frames,
                                                    const MeanCurvatureOptions& options = {});

// Carries each PCA normal from its neighbourhood's mean to the point itself along
// the surface's shape operator: n = normalise(n_pca + S d), d the point's tangential
// offset from the mean (pca.offset), S in pca's tangent frame. Inside a
// well-sampled patch d is a fraction of the spacing and nothing moves; at the edge
// of what the cameras saw every neighbour lies on one side, the PCA normal is the
// one a few millimetres back, and a kernel extrapolating across the unseen strip
// from that tilted plane stands proud of the skin (the crown of a head, seen only
// up its sides, came out 4 mm high). The tangents are re-orthogonalised to the new
// normal, tangent1 kept as close to pca's as possible. Only points whose shape
// operator is convex on average (mean curvature > 0) are carried: in the hollows,
// where the legs' inner faces meet at the crotch, carrying moved a scan's crotch
// 0.9-1.2 mm down on three of six bodies (the thigh girths with it) and helped
// nothing. pca without offsets, or a shape of the wrong size, returns pca
// unchanged.
LocalFrames correct_normal_tilt(const LocalFrames& pca, const std::vector<ShapeOperator>& shape);

// Signed mean curvature per point: the trace of estimate_shape_operators() / 2.
std::vector<float> estimate_mean_curvature(const std::vector<Vec3f>& points, const KnnIndex& index,
                                           const NeighborGraph& graph, const LocalFrames& frames,
                                           const MeanCurvatureOptions& options = {});

CurvatureResult estimate_curvature(const std::vector<Vec3f>& points, const NeighborGraph& graph,
                                   const LocalFrames& frames, const EstimateCurvatureOptions& options = {});

}  // namespace bodyscan
