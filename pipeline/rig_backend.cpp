#include "pipeline/rig_backend.hpp"

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

hw::RigDescription SimulatedSubject::applied_to(hw::RigDescription rig) const {
  for (int s = 0; s < 2; ++s)
    if (posture.arm_abduction_deg[s]) rig.simulation.posture.arm_abduction_deg[s] = posture.arm_abduction_deg[s];
  if (posture.ankle_distance_mm) rig.simulation.posture.ankle_distance_mm = posture.ankle_distance_mm;
  if (turn_deg) rig.simulation.subject_yaw_deg = *turn_deg;
  if (position_mm) rig.simulation.subject_offset = {position_mm->x(), 0, position_mm->y()};
  return rig;
}

StatusOr<std::unique_ptr<hw::DeviceRig>> open_rig(const std::string& rig, const SimulatedSubject& subject) {
  ASSIGN_OR_RETURN(const hw::RigDescription loaded, load_rig(rig));
  const hw::RigDescription desc = subject.applied_to(loaded);
  if (subject.body.empty()) return hw::DeviceRig::open(desc);
  ASSIGN_OR_RETURN(const TriangleMesh mesh, read_ply_mesh(subject.body));
  return hw::DeviceRig::open(desc, &mesh);
}

const char* to_string(OperatorRequest::Kind k) {
  switch (k) {
    case OperatorRequest::Kind::kHoldDotGrid: return "hold_dot_grid";
    case OperatorRequest::Kind::kRemoveDotGrid: return "remove_dot_grid";
  }
  return "?";
}

std::string OperatorRequest::text() const {
  if (kind == Kind::kRemoveDotGrid) {
    return "Take the dot-grid board out of the rig and leave the rig empty, then confirm: the frame lights and the "
           "lasers are next.";
  }
  return "Hold the dot-grid board before camera '" + camera_id +
         "': square to the camera and close enough that its dots fill the whole picture, still, with the room "
         "lights on. Confirm while you hold it.";
}

Rig rig_handle(hw::DeviceRig& devices, AskOperator ask, bool ask_for_simulated) {
  Rig r;
  r.description = &devices.description();
  r.controller = &devices.controller();
  for (size_t i = 0; i < devices.num_cameras(); ++i) r.cameras.push_back(&devices.camera(i));
  auto person = [&devices, has_ask = static_cast<bool>(ask), ask_for_simulated](size_t c) {
    return !devices.camera_simulated(c) || (has_ask && ask_for_simulated);
  };
  r.person_holds_dot_grid = person;
  r.hold_dot_grid = [&devices, ask, person](size_t c, bool held, const std::string& why) -> Status {
    if (!person(c) || !ask) return devices.hold_dot_grid(c, held);
    OperatorRequest req;
    req.camera = c;
    req.camera_id = devices.description().cameras.at(c).id;
    req.why = why;
    if (held) {
      RETURN_IF_ERROR(ask(req));
    } else {
      // Moving the board to the next camera takes it away from this one; after
      // the last camera a person holds it before, it must leave the rig.
      bool last = true;
      for (size_t next = c + 1; next < devices.num_cameras(); ++next) last = last && !person(next);
      if (last) {
        req.kind = OperatorRequest::Kind::kRemoveDotGrid;
        RETURN_IF_ERROR(ask(req));
      }
    }
    // In training, the simulation does what the person said they did.
    return devices.camera_simulated(c) ? devices.hold_dot_grid(c, held) : Status::Ok();
  };
  return r;
}

StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> open_simulated_rig(const std::string& rig,
                                                                    const SimulatedSubject& subject) {
  ASSIGN_OR_RETURN(const hw::RigDescription loaded, load_rig(rig));
  const hw::RigDescription desc = subject.applied_to(loaded);
  if (desc.has_real_devices()) {
    return invalid_argument(desc.source + " describes real devices; this command runs on the simulated rig only");
  }
  if (subject.body.empty()) return hw::sim::SimulatedRig::create(desc);
  ASSIGN_OR_RETURN(const TriangleMesh mesh, read_ply_mesh(subject.body));
  return hw::sim::SimulatedRig::create(desc, mesh);
}

Rig rig_handle(hw::sim::SimulatedRig& sim) {
  Rig r;
  r.description = &sim.description();
  r.controller = &sim.controller();
  for (size_t i = 0; i < sim.num_cameras(); ++i) r.cameras.push_back(&sim.camera(i));
  r.hold_dot_grid = [&sim](size_t camera, bool held, const std::string&) {
    sim.hold_dot_grid(camera, held);
    return Status();
  };
  return r;
}

}  // namespace bodyscan::pipeline
