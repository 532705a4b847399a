// How far skin the cameras did not see could move a measurement. Hole filling
// invents the surface where no camera looked (the crown, the flanks under the
// arms, the insides of the legs); a value read over it is an estimate, and staff
// need to know by how much, not merely that it is one.
//
// The bound is geometric, from the measurement's own line and the seen skin
// around it, with nothing fitted to bodies:
// - along a line over the skin (a girth's section loop, a surface path), each
//   stretch over filled skin counts its length beyond the straight chord between
//   the seen points either side of it. A tape over the real skin there is no
//   shorter than that chord (it passes both seen points), and the real skin is
//   taken to lie as far from the fill the other way;
// - a landmark on filled skin counts how far it lies, along the direction the
//   value is read in, from the nearest seen skin.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

// A mesh vertex at or above this confidence is measured skin; below, hole filling
// invented it.
inline constexpr float kMeasuredConfidence = 0.5f;

// A value whose bound exceeds this is marked as an estimate ("≈" on the screen,
// starred on the sheets): under half of every ISO 20685-1 allowance (4 to 9 mm),
// so a value left unmarked cannot be moved past its allowance by the fill alone.
inline constexpr double kEstimateThresholdMm = 2.0;

// The filled stretches' excess along `points` (closed: a loop) with `confidence`
// per point, mm. A line with no seen point at all counts its whole length; an
// open line's stretch that runs off one of its ends is measured from that end.
// Nullopt when the confidences do not match the points.
std::optional<double> filled_stretch_excess_mm(const std::vector<Eigen::Vector3d>& points,
                                               const std::vector<float>& confidence, bool closed);

// How far `p` lies from the nearest measured vertex of `mesh` along the unit
// `direction` (a zero direction: the straight distance), mm; 0 when the vertex
// nearest `p` is measured or the mesh has no confidences. The whole mesh is
// searched: call it for the few landmarks on filled skin.
double landmark_fill_offset_mm(const TriangleMesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& direction);

}  // namespace bodyscan
