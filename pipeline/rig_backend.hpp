// `--rig sim|thesis|square|FILE` and an optional body resolved to the rig's
// devices - simulated, real (Aravis cameras, a TMCL board) or a mix, as the
// description says - and the Rig handle the sequences drive.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "hw/device_rig.hpp"
#include "hw/sim/sim_rig.hpp"
#include "pipeline/acquire.hpp"

namespace bodyscan::pipeline {

// Who the simulated rig scans and how they stand, where it differs from the rig
// description's simulation: each field set replaces the description's.
struct SimulatedSubject {
  std::string body;  // a PLY mesh, mm, Y up; "" the description's
  // Arms and feet, by skinning (hw/sim/pose_body.hpp): a MakeHuman body only.
  hw::SubjectPosture posture;
  std::optional<double> turn_deg;              // about the vertical: + turns the face from +Z toward +X
  std::optional<Eigen::Vector2d> position_mm;  // (X, Z) on the floor where the body's centre stands
  // The description with these applied.
  hw::RigDescription applied_to(hw::RigDescription rig) const;
};

// "sim" is the thesis rig with the shipped demo body; other names are shipped
// layouts; anything with a '/' or ending in .json is a description file.
StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> open_simulated_rig(const std::string& rig,
                                                                    const SimulatedSubject& subject = {});

// The description's devices, whatever they are; `subject` changes the simulated one.
StatusOr<std::unique_ptr<hw::DeviceRig>> open_rig(const std::string& rig, const SimulatedSubject& subject = {});

// What a person is asked to do during a calibration: hold the lens dot-grid
// board before a camera (again, when `why` says the last picture could not be
// used), or, after the last camera, take it out of the rig.
struct OperatorRequest {
  enum class Kind { kHoldDotGrid, kRemoveDotGrid };
  Kind kind = Kind::kHoldDotGrid;
  size_t camera = 0;
  std::string camera_id;
  std::string why;
  std::string text() const;  // the instruction, in words for the shop's staff (`why` apart)
};
const char* to_string(OperatorRequest::Kind k);
// Returns when the person has done it; an error (kCancelled: nobody will) stops
// the calibration.
using AskOperator = std::function<Status(const OperatorRequest&)>;

// The handle the sequences drive; valid while `sim` (or `devices`) lives.
Rig rig_handle(hw::sim::SimulatedRig& sim);
// A person holds the dot grid before every real camera, asked through `ask`;
// with `ask_for_simulated` before the simulated ones too (staff training: the
// simulation places the board when the person says it is in place). Without
// `ask`, a real camera's dot grid is a failed_precondition saying what to do.
Rig rig_handle(hw::DeviceRig& devices, AskOperator ask = {}, bool ask_for_simulated = false);

}  // namespace bodyscan::pipeline
