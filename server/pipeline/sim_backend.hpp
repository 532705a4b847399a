// The simulated rig as a pipeline backend: `--rig sim|thesis|square|FILE` and an
// optional body resolved to a running simulated rig, and its Rig handle.
#pragma once

#include <memory>
#include <string>

#include "hw/sim/sim_rig.hpp"
#include "server/pipeline/acquire.hpp"

namespace bodyscan::pipeline {

// "sim" is the thesis rig with the shipped demo body; other names are shipped
// layouts; anything with a '/' or ending in .json is a description file. `body`
// (a PLY mesh, mm, Y up) replaces the description's subject when not empty.
StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> open_simulated_rig(const std::string& rig, const std::string& body);

// The handle the sequences drive; valid while `sim` lives.
Rig rig_handle(hw::sim::SimulatedRig& sim);

}  // namespace bodyscan::pipeline
