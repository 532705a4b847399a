// `--rig sim|thesis|square|FILE` and an optional body resolved to the rig's
// devices - simulated, real (Aravis cameras, a TMCL board) or a mix, as the
// description says - and the Rig handle the sequences drive.
#pragma once

#include <memory>
#include <string>

#include "hw/device_rig.hpp"
#include "hw/sim/sim_rig.hpp"
#include "server/pipeline/acquire.hpp"

namespace bodyscan::pipeline {

// "sim" is the thesis rig with the shipped demo body; other names are shipped
// layouts; anything with a '/' or ending in .json is a description file. `body`
// (a PLY mesh, mm, Y up) replaces the description's subject when not empty.
StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> open_simulated_rig(const std::string& rig, const std::string& body);

// The description's devices, whatever they are. `body` replaces the simulated
// subject when not empty.
StatusOr<std::unique_ptr<hw::DeviceRig>> open_rig(const std::string& rig, const std::string& body);

// The handle the sequences drive; valid while `sim` (or `devices`) lives.
Rig rig_handle(hw::sim::SimulatedRig& sim);
Rig rig_handle(hw::DeviceRig& devices);

}  // namespace bodyscan::pipeline
