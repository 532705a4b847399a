// PCA normals. The thesis writes the covariance entries with absolute values
// (eq. 3.13, |x - x̄||y - ȳ|); that is a typo: absolute values would make every
// off-diagonal entry non-negative and tilt every normal. We use the covariance.
#include "recon/surface/estimate_normals.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>

#include <algorithm>

namespace bodyscan {

LocalFrames estimate_normals(const std::vector<Vec3f>& points, const KnnIndex& index, const NeighborGraph& graph,
                             const EstimateNormalsOptions& options) {
  const size_t n = points.size();
  const bool from_graph = options.k <= graph.k;
  const size_t k = from_graph ? options.k : std::min(options.k, n > 0 ? n - 1 : 0);
  LocalFrames f;
  f.normals.resize(n);
  f.tangent1.resize(n);
  f.tangent2.resize(n);
  f.eigenvalues.resize(n);
  f.offset.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 2048), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> queried(from_graph ? 0 : k + 1);
    std::vector<float> d2(queried.size());
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const uint32_t* nb = graph.row(i);
      size_t count = k;
      if (!from_graph) {
        const size_t got = index.knn(points[i], k + 1, queried.data(), d2.data());
        count = 0;
        for (size_t j = 0; j < got && count < k; ++j)
          if (queried[j] != i) queried[count++] = queried[j];
        nb = queried.data();
      }
      // Centre on the point itself first so the sums stay well conditioned in float
      // input far from the origin.
      const Vec3d p = points[i].cast<double>();
      Vec3d sum = Vec3d::Zero();
      Eigen::Matrix3d sq = Eigen::Matrix3d::Zero();
      for (size_t j = 0; j < count; ++j) {
        const Vec3d d = points[nb[j]].cast<double>() - p;
        sum += d;
        sq += d * d.transpose();
      }
      const double m = static_cast<double>(count + 1);
      const Vec3d mean = sum / m;
      const Eigen::Matrix3d cov = sq / m - mean * mean.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
      es.computeDirect(cov);
      Vec3d nrm = es.eigenvectors().col(0);
      Vec3d t1 = es.eigenvectors().col(2);
      // computeDirect can lose orthogonality for nearly equal eigenvalues; re-orthogonalise.
      nrm.normalize();
      t1 = (t1 - t1.dot(nrm) * nrm);
      if (t1.squaredNorm() < 1e-20) t1 = nrm.unitOrthogonal();
      t1.normalize();
      const Vec3d t2 = nrm.cross(t1);
      f.normals[i] = nrm.cast<float>();
      f.tangent1[i] = t1.cast<float>();
      f.tangent2[i] = t2.cast<float>();
      f.eigenvalues[i] = es.eigenvalues().cwiseMax(0.0).cast<float>();
      f.offset[i] = (-mean).cast<float>();
    }
  });
  return f;
}

void flip_frame(LocalFrames& frames, size_t i) {
  frames.normals[i] = -frames.normals[i];
  frames.tangent2[i] = -frames.tangent2[i];
}

}  // namespace bodyscan
