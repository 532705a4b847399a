// Where on a body a surface point lies, for the coverage reports of rig_coverage and
// scan_benchmark (which must name the same places): a height band and the way the
// skin faces.
#pragma once

#include <cmath>
#include <string>

#include <Eigen/Core>

namespace bodyscan::bench {

inline std::string body_region(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  const char* band = p.y() < 80 ? "feet" : p.y() < 800 ? "legs" : p.y() < 1450 ? "trunk" : "head/neck";
  const char* facing = n.y() > 0.7                         ? "up"
                       : n.y() < -0.7                      ? "down"
                       : std::abs(n.x()) > std::abs(n.z()) ? "side"
                       : n.z() > 0                         ? "front"
                                                           : "back";
  return std::string(band) + " facing " + facing;
}

}  // namespace bodyscan::bench
