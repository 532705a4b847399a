// Horizontal cuts through a standing body, many of them, fast: the triangles are
// bucketed by height once, so each cut costs only the triangles it crosses. The
// landmark finder reads the body's shape from these cuts (how many parts a level
// has, where each is, how wide, how long its tape).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/girth.hpp"

namespace bodyscan {

// One closed loop of a horizontal cut, with what the landmark rules ask of it.
struct Ring {
  std::vector<Eigen::Vector3d> points;
  double girth = 0;  // tape (convex hull) length, mm
  double x_min = 0, x_max = 0, z_min = 0, z_max = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // of the enclosed area
  float min_confidence = 1;
  std::vector<float> confidence;  // per point (empty: all measured)
  bool spans_x(double x) const { return x_min < x && x < x_max; }
  // Where the loop crosses the vertical plane X = x: the largest and smallest Z
  // (front and back, the body facing +Z). False when it does not cross.
  bool crossing_z(double x, double* front, double* back) const;
  // The mesh's confidence where the loop crosses X = x at its front and at its back,
  // the higher of the two (1 where the mesh has none, or the loop does not cross).
  float crossing_confidence(double x) const;
  // Whether the two loops' outlines cross in the horizontal plane: one part's
  // surface passes through the other's (a posed arm through the flank).
  bool crosses(const Ring& other) const;
};

class BodySlicer {
 public:
  // Buckets the triangles spanning [y0, y1] into `step`-high bands.
  BodySlicer(const TriangleMesh& mesh, double y0, double y1, double step = 2.0);

  // The closed loops of the cut at height y (open pieces of an open mesh are left out).
  std::vector<Ring> rings(double y) const;
  // The triangles that may cross height y (for mesh_girth and plane_section).
  const std::vector<uint32_t>* triangles_at(double y) const;
  // The tape at height y around the loop nearest `near`.
  StatusOr<Girth> girth(double y, const Eigen::Vector3d& near) const;

  const TriangleMesh& mesh() const { return mesh_; }
  double y0() const { return y0_; }
  double y1() const { return y1_; }

 private:
  const TriangleMesh& mesh_;
  double y0_, y1_, step_;
  std::vector<std::vector<uint32_t>> bands_;
};

}  // namespace bodyscan
