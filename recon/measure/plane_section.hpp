// Where a plane cuts a triangle mesh: closed loops (and, on an open mesh, open
// polylines) of points on the mesh's edges, the exact plane–mesh intersection the
// girth tools of thesis §3.3 measure around.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

// The plane through `point` with unit `normal` (mm, world frame).
struct Plane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  double signed_distance(const Eigen::Vector3d& p) const { return normal.dot(p - point); }
};

struct SectionLoop {
  std::vector<Eigen::Vector3d> points;  // in order along the cut; not repeated at the end
  bool closed = true;                   // false where the cut runs off an open mesh's border
  // Per point, the mesh's confidence interpolated along the edge (1 when the mesh
  // has none): where a loop crosses filled holes.
  std::vector<float> confidence;
};

// Every loop the plane cuts from the mesh. A vertex exactly on the plane is taken
// to lie a hair on its positive side, so every cut crosses edges, never vertices,
// and the loops come out simple. Loops of fewer than 3 points are left out.
std::vector<SectionLoop> plane_section(const TriangleMesh& mesh, const Plane& plane);
// The same over a subset of the triangles (e.g. those spanning the plane's height),
// so that many parallel cuts through a big mesh cost what they cross.
std::vector<SectionLoop> plane_section(const TriangleMesh& mesh, const Plane& plane,
                                       const std::vector<uint32_t>* triangles);

// For a sweep of parallel cuts, the planes through origin + offsets[k] * normal
// (normal unit, offsets ascending): per plane, the triangles of `candidates` whose
// corners lie on both sides of it or on it, in candidates' order. One pass over the
// candidates, where cutting each plane through all of them would take one per plane;
// plane_section over a plane's list finds the same loops as over the candidates.
std::vector<std::vector<uint32_t>> triangles_by_plane(const TriangleMesh& mesh, const std::vector<uint32_t>& candidates,
                                                      const Eigen::Vector3d& origin, const Eigen::Vector3d& normal,
                                                      const std::vector<double>& offsets);

}  // namespace bodyscan
