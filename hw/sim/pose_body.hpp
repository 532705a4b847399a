// Poses a MakeHuman body by linear blend skinning with MakeHuman's CC0 default
// skeleton and weights (hw/sim/bodies/skeleton/README.md): the upper arms turned
// about the shoulder joints in the frontal plane, the legs about the hip joints
// with the feet turned back so that the soles stay flat. The simulated rig poses
// its subject so (a customer who stands otherwise than the rest A-pose), and tests
// pose bodies in many postures: vertex i stays the same anatomical point.
//
// A body it can pose is one of the MakeHuman bodies whose rest joints
// joints.json holds (the shipped demo bodies and the shared test bodies): 53,514
// vertices in the subdivided hm08 order, in its rest A-pose. It is recognised by
// its own vertices, wherever it stands, not by its file's name.
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/status.hpp"
#include "hw/rig_description.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::hw::sim {

// What the subject is asked to do (hw/rig_description.hpp). Unset: as in the rest pose.
using Posture = SubjectPosture;

// The joints a posture is read from and set by, mm, in the body's frame.
struct PostureJoints {
  Eigen::Vector3d shoulder[2], elbow[2], wrist[2], hip[2], ankle[2];  // [0] left, [1] right
  // The angle of elbow - shoulder from the downward vertical, degrees.
  double arm_abduction_deg(int side) const;
  double ankle_distance_mm() const { return (ankle[0] - ankle[1]).norm(); }
};

struct PosedBody {
  TriangleMesh mesh;                         // the rest mesh posed; faces unchanged, vertex i the same point
  std::string body;                          // which body of joints.json it was recognised as
  PostureJoints rest, posed;                 // the joints before and after, in the mesh's frame
  double shoulder_rotation_deg[2] = {0, 0};  // about +Z at each shoulder joint (left, right)
  double hip_adduction_deg = 0;              // each leg toward the midline (negative: apart)
};

class BodyPoser {
 public:
  // Reads default.mhskel, default_weights.mhw and joints.json from `dir`.
  static StatusOr<BodyPoser> load(const std::string& dir);
  // The shipped skeleton (hw/sim/bodies/skeleton), read once.
  static StatusOr<const BodyPoser*> shipped();

  // Poses `rest` (a MakeHuman body in its rest pose, anywhere: only a translation
  // from joints.json's frame is allowed) as `posture` asks. The rotations are
  // solved so that the posed joints reach the asked angles (to 0.01 degree) and
  // the ankle distance (to 0.1 mm); no bone turns by more than 60 degrees.
  // Errors: the mesh is not one of joints.json's bodies, or a posture is out of
  // reach (arms 0-80 degrees; ankles 100-700 mm).
  StatusOr<PosedBody> pose(const TriangleMesh& rest, const Posture& posture) const;

  // Linear blend skinning of `rest` (as `pose` takes it) with the given rotations:
  // bone name -> (unit axis in the body frame, degrees) about the bone's rest head
  // joint, carried down the hierarchy. For tests and studies of other postures.
  StatusOr<TriangleMesh> skin(const TriangleMesh& rest,
                              const std::map<std::string, std::pair<Eigen::Vector3d, double>>& rotations) const;

 private:
  struct Bone {
    std::string name, head;
    int parent = -1;
  };
  struct Match {
    std::string body;
    Eigen::Vector3d shift;  // mesh frame = joints.json frame + shift
  };
  StatusOr<Match> recognise(const TriangleMesh& rest) const;
  StatusOr<TriangleMesh> skin(const TriangleMesh& rest, const Match& m,
                              const std::map<std::string, std::pair<Eigen::Vector3d, double>>& rotations) const;
  Eigen::Vector3d joint(const Match& m, const std::string& name) const;
  // The skinning weights of every vertex of a 53,514-vertex body: (bone, weight).
  StatusOr<std::vector<std::vector<std::pair<int, float>>>> vertex_weights(const TriangleMesh& rest) const;

  std::vector<Bone> bones_;
  std::map<std::string, int> bone_index_;
  std::map<std::string, std::vector<int>> joint_vertices_;                     // hm08 indices
  std::vector<std::vector<std::pair<int, float>>> hm08_weights_;               // per hm08 body vertex, normalised
  std::map<std::string, std::map<std::string, Eigen::Vector3d>> rest_joints_;  // body -> joint -> mm
};

}  // namespace bodyscan::hw::sim
