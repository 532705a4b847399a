// The shipped thesis layout with its controller on a TMCL board at `port`, wired
// as docs/hardware.md's example: lasers on outputs 0-3 and axes 0-3, 16
// microsteps per laser step, lights on outputs 4-6.
#pragma once

#include <string>

#include "hw/rig_description.hpp"

namespace bodyscan::hw::testing {

RigDescription tmcl_rig(const std::string& port, int watchdog_ms);

}  // namespace bodyscan::hw::testing
