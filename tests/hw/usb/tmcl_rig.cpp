#include "tests/hw/usb/tmcl_rig.hpp"

#include <gtest/gtest.h>

namespace bodyscan::hw::testing {

RigDescription tmcl_rig(const std::string& port, int watchdog_ms) {
  auto path = shipped_rig_path("thesis");
  EXPECT_TRUE(path.ok());
  auto rig = load_rig_description(*path);
  EXPECT_TRUE(rig.ok()) << rig.status().message();
  RigDescription r = *rig;
  ControllerDescription& c = r.controller;
  c.backend = "tmcl";
  c.port = port;
  c.lasers.assign(r.lasers.size(), {});
  for (size_t i = 0; i < r.lasers.size(); ++i) {
    c.lasers[i] = {static_cast<int>(i), static_cast<int>(i), 16, 1600 + 100 * static_cast<int>(i)};
  }
  c.room_lights_output = 4;
  c.front_lights_output = 5;
  c.back_lights_output = 6;
  c.reply_timeout_ms = 200;
  c.watchdog_ms = watchdog_ms;
  return r;
}

}  // namespace bodyscan::hw::testing
