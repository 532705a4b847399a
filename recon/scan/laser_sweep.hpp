// A line laser on a stepper motor, calibrated from the whole scan: every plane it
// sweeps contains one axis, and each motor step turns the plane by the same angle.
// Six numbers (the axis, the angle at step 0, the angle per step) fitted to every
// pole point of the sweep - a thousand or more, from every camera that sees the
// laser - give each step's plane far more precisely than the three or four points
// of its own frame (thesis §3.1.3), and outvote a pole point the subject spoiled.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "core/status.hpp"

namespace bodyscan {

struct SweepPoint {
  int step = 0;
  Eigen::Vector3d world = Eigen::Vector3d::Zero();  // a measured point of that step's plane, mm
};

struct SweepPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  // unit
  double offset = 0;                                  // normal . x = offset
};

class LaserSweep {
 public:
  // Fits the sweep to points of at least three distinct steps; `initial` are per-step
  // planes (any sense) to start from, at least two distinct steps. Points farther
  // than `reject_mm` (or 4 robust sigmas, if more) from the first fit are left out.
  static StatusOr<LaserSweep> fit(const std::vector<SweepPoint>& points,
                                  const std::vector<std::pair<int, SweepPlane>>& initial, double reject_mm = 1.5);

  SweepPlane plane(int step) const;
  const Eigen::Vector3d& axis_point() const { return a_; }
  const Eigen::Vector3d& axis_direction() const { return u_; }
  double degrees_per_step() const;
  double rms_mm() const { return rms_; }  // of the points kept
  size_t points_used() const { return used_; }
  size_t points_rejected() const { return rejected_; }

 private:
  Eigen::Vector3d a_ = Eigen::Vector3d::Zero(), u_ = Eigen::Vector3d::UnitY();
  Eigen::Vector3d e1_ = Eigen::Vector3d::UnitX(), e2_ = Eigen::Vector3d::UnitZ();
  double theta0_ = 0, dtheta_ = 0;
  double rms_ = 0;
  size_t used_ = 0, rejected_ = 0;
};

}  // namespace bodyscan
