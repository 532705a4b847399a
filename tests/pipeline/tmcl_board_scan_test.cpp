// The thesis rig with its controller on a TMCL board - the simulated board behind
// a pseudo-terminal, so every switch and step crosses the real driver, protocol
// and serial path - and simulated cameras that see what that board switches.
// Calibration and the scan run unchanged: a real controller replaces a simulated
// one without anything above hw/ knowing.
#include <gtest/gtest.h>

#include <algorithm>

#include "hw/device_rig.hpp"
#include "hw/usb/sim_tmcl_board.hpp"
#include "pipeline/rig_backend.hpp"
#include "pipeline/scan_job.hpp"
#include "recon/geometry/mesh_distance.hpp"
#include "tests/half_resolution.hpp"
#include "tests/hw/usb/tmcl_rig.hpp"

namespace bodyscan::pipeline {
namespace {

TEST(TmclBoardRig, CalibratesAndScansThroughTheBoard) {
  hw::usb::SimTmclBoard board(1, {5000, -4000, 2500, -1200, 0, 0});
  board.set_speed(400000);  // microsteps per second: a 16-microstep laser step in 40 us
  auto pty = hw::usb::PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  hw::RigDescription desc = hw::testing::tmcl_rig((*pty)->path(), 500);
  testing::halve_resolution(desc);
  ASSERT_TRUE(desc.has_real_devices());
  auto devices = hw::DeviceRig::open(desc);
  ASSERT_TRUE(devices.ok()) << devices.status().message();
  ASSERT_NE((*devices)->simulation(), nullptr);

  ScanJobOptions options;
  options.every = 6;
  options.reconstruct = false;
  const uint64_t before = board.requests();
  auto result = run_scan_job(rig_handle(**devices), options);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_GT(board.requests() - before, 1000u) << "the scan did not go through the board";

  const MeshDistance truth((*devices)->simulation()->scene().subject());
  std::vector<float> d = truth.distances(result->cloud.positions);
  ASSERT_GT(d.size(), 5000u);
  std::sort(d.begin(), d.end());
  double mean = 0;
  for (float x : d) mean += x / static_cast<double>(d.size());
  EXPECT_LT(mean, 1.2) << "mm";
  std::printf("[ tmcl rig ] %zu points, mean %.3f mm from the true surface, %llu board requests\n", d.size(), mean,
              static_cast<unsigned long long>(board.requests() - before));
  // Every laser output is off after the job, on the board itself.
  for (const auto& w : desc.controller.lasers) EXPECT_FALSE(board.output(w.output));
  EXPECT_EQ(board.watchdog_trips(), 0);
}

}  // namespace
}  // namespace bodyscan::pipeline
