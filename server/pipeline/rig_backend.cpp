#include "server/pipeline/rig_backend.hpp"

#include "recon/io/ply.hpp"

namespace bodyscan::pipeline {

namespace {
StatusOr<hw::RigDescription> load_rig(const std::string& rig) {
  std::string path = rig;
  if (rig.find('/') == std::string::npos && rig.find(".json") == std::string::npos) {
    ASSIGN_OR_RETURN(path, hw::shipped_rig_path(rig == "sim" ? "thesis" : rig));
  }
  return hw::load_rig_description(path);
}
}  // namespace

StatusOr<std::unique_ptr<hw::DeviceRig>> open_rig(const std::string& rig, const std::string& body) {
  ASSIGN_OR_RETURN(const hw::RigDescription desc, load_rig(rig));
  if (body.empty()) return hw::DeviceRig::open(desc);
  ASSIGN_OR_RETURN(const TriangleMesh mesh, read_ply_mesh(body));
  return hw::DeviceRig::open(desc, &mesh);
}

Rig rig_handle(hw::DeviceRig& devices) {
  Rig r;
  r.description = &devices.description();
  r.controller = &devices.controller();
  for (size_t i = 0; i < devices.num_cameras(); ++i) r.cameras.push_back(&devices.camera(i));
  r.hold_dot_grid = [&devices](size_t camera, bool held) { return devices.hold_dot_grid(camera, held); };
  return r;
}

StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> open_simulated_rig(const std::string& rig, const std::string& body) {
  ASSIGN_OR_RETURN(const hw::RigDescription desc, load_rig(rig));
  if (desc.has_real_devices()) {
    return invalid_argument(desc.source + " describes real devices; this command runs on the simulated rig only");
  }
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
