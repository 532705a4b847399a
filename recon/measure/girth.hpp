// Girths the way a tailor's tape takes them (thesis §3.3): cut the body with a plane,
// take the loop around the part meant, and measure the convex hull of that loop in
// the plane, because a tape bridges the body's hollows. The thesis does it on the
// point cloud (points within a threshold of the plane); on a mesh the cut is exact.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/point_cloud.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/plane_section.hpp"

namespace bodyscan {

// The convex hull of points in a plane, counter-clockwise, without collinear points
// (Andrew's monotone chain, O(n log n)). Fewer than 3 distinct points: those points.
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> points);
// Whether two closed polygons' edges cross (a surface that passes through itself
// cuts as crossing loops).
bool loops_cross(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);
// Length of the closed polygon through `polygon` (mm).
double closed_length(const std::vector<Eigen::Vector2d>& polygon);
double closed_length(const std::vector<Eigen::Vector3d>& polygon);

struct Girth {
  double value_mm = 0;  // the tape: the hull's perimeter
  Plane plane;
  std::vector<Eigen::Vector3d> loop;  // the section loop measured around, in order
  std::vector<Eigen::Vector3d> tape;  // the hull's corners in order: the tape's path
  double loop_length_mm = 0;          // along the skin, hollows followed
  float min_confidence = 1;           // lowest mesh confidence along the loop (1: all measured)
  // How far filled skin under the loop could move the tape (fill_bound.hpp);
  // nullopt where that is not known (the tape goes round crossing loops too).
  std::optional<double> fill_bound_mm = 0.0;
  size_t loops_cut = 0;  // how many loops the plane cut (arms, legs, torso...)
};

// The girth in `plane` around the closed section loop that encircles `near` (a
// limb's centre), else the loop nearest it (a point picked on the skin), or without
// `near` the loop with the longest tape (at the waist, the torso rather than an
// arm). Loops that cross it are the same part cut twice (a surface through itself):
// the tape goes round them too, and `loop` is the one meant. Errors: the plane
// misses the mesh, or cuts no closed loop (an open mesh's border).
StatusOr<Girth> mesh_girth(const TriangleMesh& mesh, const Plane& plane,
                           const std::optional<Eigen::Vector3d>& near = std::nullopt);
// The same, cutting only `triangles` (those the plane can reach; plane_section.hpp).
StatusOr<Girth> mesh_girth(const TriangleMesh& mesh, const Plane& plane, const std::optional<Eigen::Vector3d>& near,
                           const std::vector<uint32_t>* triangles);

// The same on a point cloud, as the thesis does it: the points within `slab_mm` of
// the plane, projected into it, grouped into parts (points closer than `gap_mm`
// belong together), the part nearest `near` (or the one with the longest tape)
// measured around its hull. `loop` holds the part's projected points (unordered).
StatusOr<Girth> cloud_girth(const PointCloud& cloud, const Plane& plane, const std::optional<Eigen::Vector3d>& near,
                            double slab_mm = 2.0, double gap_mm = 25.0);

// An arc (thesis fig. 3.43): the length along a girth's tape between two points
// (each taken at the tape's point nearest it), the shorter way round; the other way's
// length comes with it.
struct Arc {
  double value_mm = 0;
  double other_way_mm = 0;
  std::vector<Eigen::Vector3d> path;  // from the first point's place on the tape to the second's
  Girth girth;                        // the girth whose tape it follows
};

// The arc on the section loop nearest the two points' midpoint.
StatusOr<Arc> mesh_arc(const TriangleMesh& mesh, const Plane& plane, const Eigen::Vector3d& from,
                       const Eigen::Vector3d& to);

// A unit vector pair spanning the plane: (u, v, normal) right-handed.
void plane_basis(const Eigen::Vector3d& normal, Eigen::Vector3d* u, Eigen::Vector3d* v);

// Drops the closed loops that lie inside another closed loop of the same cut. A
// tape goes round the outside: a nested loop is a cavity's wall (a bubble the
// reconstruction left inside the body) or the gap in a part that joins itself (an
// arm resting on the hip, cut edge-on), never a part of the body of its own.
void drop_nested_loops(std::vector<SectionLoop>* loops, const Plane& plane);

}  // namespace bodyscan
