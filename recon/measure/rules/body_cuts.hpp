// The body as the landmark rules read it: the mesh in the body's own frame
// (body_frame.hpp: standing on Y = 0, facing +Z, its left side at +X), its
// horizontal cuts remembered per level, and the questions the rules ask of a cut
// (the loop on the midline, an arm's or a leg's loop on one side).
//
// The rules themselves live by body region beside this file: trunk.*,
// neck_shoulders.*, legs.*, arms.*. Every position they handle is in the body's
// frame; measure_body (body_measurements.cpp) gives them back in the mesh's.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/body_frame.hpp"
#include "recon/measure/body_slicer.hpp"

namespace bodyscan::rules {

// A side of the body. In the body's frame the left side is at +X.
enum class Side { kLeft, kRight };
inline constexpr Side kBothSides[] = {Side::kLeft, Side::kRight};
// +1 for the left (toward +X), -1 for the right.
inline double sign(Side side) { return side == Side::kLeft ? 1.0 : -1.0; }
inline Side opposite(Side side) { return side == Side::kLeft ? Side::kRight : Side::kLeft; }
// "left" or "right", as the landmarks' and measurements' names spell it.
inline std::string side_name(Side side) { return side == Side::kLeft ? "left" : "right"; }

// One value per side.
template <class T>
struct PerSide {
  T left{}, right{};
  T& operator[](Side side) { return side == Side::kLeft ? left : right; }
  const T& operator[](Side side) const { return side == Side::kLeft ? left : right; }
};

class BodyCuts {
 public:
  // `body`: the mesh moved into `frame` (transformed(mesh, frame.body_from_world())),
  // which must outlive this; its triangles are bucketed in `step_mm` bands
  // (BodySlicer). The floor is Y = 0 there; the stature is the highest point's Y.
  BodyCuts(const TriangleMesh& body, const BodyFrame& frame, double step_mm);

  const TriangleMesh& mesh() const { return body_; }
  const BodyFrame& frame() const { return frame_; }
  double stature() const { return stature_; }
  const Eigen::Vector3d& crown() const { return crown_; }  // the highest vertex
  // The level `fraction` of the stature above the floor, mm.
  double level(double fraction) const { return fraction * stature_; }

  // The midline: the centroid of the longest loop at 55 % of the stature (the
  // trunk). The rules tell the sides apart by X = midline_x(). Errors when nothing
  // is there (not a standing body).
  Status find_midline();
  double midline_x() const { return midline_x_; }
  double midline_z() const { return midline_z_; }
  // A point on the midline at height y.
  Eigen::Vector3d on_midline(double y) const { return {midline_x_, y, midline_z_}; }

  // The closed loops of the cut at height y, remembered: the searches revisit the
  // same levels (both legs, several windows). Levels are keyed to 1/64 mm.
  const std::vector<Ring>& at(double y) const;
  // The cuts a walk from y0 toward y1 in steps of `step` (either sign) will ask for,
  // made ahead on every core: the searches walk hundreds of levels and each cut
  // stands alone. (The same levels as the walk's own loop, to the bit.)
  void prefetch(double y0, double y1, double step) const;

  // The loop at y spanning the midline (trunk, neck, head), the longest if several.
  const Ring* midline_loop(double y) const;
  // The midline loop's front (largest Z) where it crosses the plane X = midline_x
  // at height y; midline_z() where it does not.
  double front_z(double y) const;
  // An arm's loop on `side` in a cut: the outermost loop wholly on that side, at
  // least 5 % of the stature round (a scrap a coarse scan leaves beside the hip is
  // no arm).
  const Ring* arm_loop(const std::vector<Ring>& cut, Side side) const;
  // Whether at height y the arm on `side` is a loop of its own that does not cross
  // the trunk's: a horizontal tape round the trunk leaves it out.
  bool arm_clear(double y, Side side) const;
  // The horizontal tape at height y round the loop nearest `near`.
  StatusOr<Girth> level_girth(double y, const Eigen::Vector3d& near) const;
  // Triangles with a corner within r of c, for the tilted cuts (among `among`
  // when given: a subset known to hold them all).
  std::vector<uint32_t> triangles_near(const Eigen::Vector3d& c, double r,
                                       const std::vector<uint32_t>& among = {}) const;

 private:
  BodyFrame frame_;
  const TriangleMesh& body_;
  double stature_ = 0;
  Eigen::Vector3d crown_ = Eigen::Vector3d::Zero();
  std::optional<BodySlicer> slicer_;
  double midline_x_ = 0, midline_z_ = 0;
  mutable std::unordered_map<int64_t, std::vector<Ring>> cache_;
};

// --- the shapes of loops and outlines -------------------------------------------

// The loop spanning the midline X = x (trunk, neck, head), the longest if several.
const Ring* midline_ring(const std::vector<Ring>& rings, double x);

// A loop of a cut whose tape is shorter than this (mm) is no part of the body.
constexpr double kMinPartGirthMm = 30;

// The loop wholly on `side` of the midline X = x, at least min_girth round:
// `farthest` picks the outermost (an arm), otherwise the innermost (a leg).
const Ring* side_ring(const std::vector<Ring>& rings, double x, Side side, bool farthest,
                      double min_girth = kMinPartGirthMm);
// The loop wholly on `side` of the midline X = x, at least kMinPartGirthMm round,
// whose centre lies nearest `last` in the cut's plane (a part followed cut by cut).
const Ring* nearest_side_ring(const std::vector<Ring>& rings, double x, Side side, const Eigen::Vector3d& last);

// How many other loops of the cut (of a tape at least min_girth) lie within
// `reach` of the part's centre: fingers parting from a hand. A stray fold of the
// reconstruction against the flank, far from the arm, is not counted.
size_t parts_near(const std::vector<Ring>& rings, const Ring& part, double reach, double min_girth = kMinPartGirthMm);

// The middle of a flat extreme: of the points whose height along `dir` lies within
// `band` of the highest, the one nearest (along `across`) to the vertex of the
// parabola least-squares fitted to their heights, or to the middle of their span
// where the fit does not open downwards or its vertex falls outside. The highest
// point alone slides from end to end of a flat side (a neck's, the top of a
// shoulder) with the scan's noise; so, less, does the span's middle. With
// `between`, the point at that middle itself, interpolated between the nearest
// points either side of it along `across` (for points on one arch, such as a
// section's top), since a mesh's section has a point only every few mm.
Eigen::Vector3d middle_of_extreme(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& dir,
                                  const Eigen::Vector3d& across, double band, bool between = false);

// Where the ray from `origin` along `dir` last leaves a closed loop lying in a plane
// through `origin` that holds `dir` and `across`: the loop's outermost crossing of
// that line. On a limb's round side the middle of the flattest stretch slides round
// with the skin's noise; the crossing moves only as far as the skin does. Empty
// when the ray never crosses the loop.
std::optional<Eigen::Vector3d> ray_exit(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& dir, const Eigen::Vector3d& across);

// The centre of a closed loop's outline: its edges' midpoints weighted by their
// lengths (unlike the vertices' mean, indifferent to where the cut samples densely).
Eigen::Vector3d loop_centre(const std::vector<Eigen::Vector3d>& loop);

// A least-squares line through points [b, e): (centre, unit direction with y >= 0);
// `residual`, when given, receives the spread off the line (the two smaller
// eigenvalues' sum). `weights`, when given, weigh each point (indexed as p; their
// sum over [b, e) must be positive).
std::pair<Eigen::Vector3d, Eigen::Vector3d> fit_line(const std::vector<Eigen::Vector3d>& p, size_t b, size_t e,
                                                     double* residual = nullptr,
                                                     const std::vector<double>* weights = nullptr);

// Whether a loop in the plane with normal n winds round p (the loop is the limb's
// own, not a neighbour's that the nearest-loop rule fell back to).
bool winds_round(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& p, const Eigen::Vector3d& n);

}  // namespace bodyscan::rules
