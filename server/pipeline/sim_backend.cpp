#include "server/pipeline/sim_backend.hpp"

#include "recon/io/ply.hpp"

namespace bodyscan::pipeline {

StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> open_simulated_rig(const std::string& rig, const std::string& body) {
  std::string path = rig;
  if (rig.find('/') == std::string::npos && rig.find(".json") == std::string::npos) {
    ASSIGN_OR_RETURN(path, hw::shipped_rig_path(rig == "sim" ? "thesis" : rig));
  }
  ASSIGN_OR_RETURN(const hw::RigDescription desc, hw::load_rig_description(path));
  if (body.empty()) return hw::sim::SimulatedRig::create(desc);
  ASSIGN_OR_RETURN(const TriangleMesh mesh, read_ply_mesh(body));
  return hw::sim::SimulatedRig::create(desc, mesh);
}

Rig rig_handle(hw::sim::SimulatedRig& sim) {
  Rig r;
  r.description = &sim.description();
  r.controller = &sim.controller();
  for (size_t i = 0; i < sim.num_cameras(); ++i) r.cameras.push_back(&sim.camera(i));
  r.hold_dot_grid = [&sim](size_t camera, bool held) {
    sim.hold_dot_grid(camera, held);
    return Status();
  };
  return r;
}

}  // namespace bodyscan::pipeline
