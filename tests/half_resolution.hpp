// A rig for tests that calibrate or scan: the same lenses on pixels twice the
// size (half the width and height), so that a calibration renders in a few
// seconds instead of a minute.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "hw/rig_description.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::testing {

inline void halve_resolution(hw::RigDescription& desc) {
  for (hw::CameraDescription& c : desc.cameras) {
    c.width /= 2;
    c.height /= 2;
    c.pixel_size_um *= 2;
    c.blur_px /= 2;
  }
}

// A shipped layout ("thesis", "square") at half resolution.
inline hw::RigDescription half_resolution_rig(const std::string& name = "thesis") {
  auto desc = hw::load_rig_description(*hw::shipped_rig_path(name));
  EXPECT_TRUE(desc.ok()) << desc.status().message();
  if (!desc.ok()) return {};
  halve_resolution(*desc);
  return *desc;
}

// The thesis rig at half resolution as a rig file (in a new temporary folder), for
// what takes a rig by path: `bodyscan scan --rig`, a workstation's options.
inline std::string half_resolution_rig_file() {
  const std::string path = temp_dir() + "/half-thesis.json";
  std::ofstream(path) << hw::to_json(half_resolution_rig());
  return path;
}

}  // namespace bodyscan::testing
