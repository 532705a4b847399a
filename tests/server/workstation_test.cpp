// The workstation on its own (no HTTP): what it finds in a data folder at start.
#include <gtest/gtest.h>
#include <sodium.h>

#include <cstdlib>

#include "server/workstation/workstation.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::testing {
namespace {

// A scan stored by `bodyscan scan --archive` carries its calibration in its raw
// record: a workstation opened on that archive starts calibrated with it (for
// the same rig only), so the demo's server needs no calibration before its first
// scan.
TEST(Workstation, StartsWithTheCalibrationOfTheNewestArchivedScanOnThisRig) {
  const std::string data = temp_dir();
  const std::string cmd = std::string(BODYSCAN_BIN) + " scan --rig sim --every 12 --no-surface -q --archive '" + data +
                          "' --new-customer Demo > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  server::WorkstationOptions o;
  o.data_dir = data;
  o.auth.opslimit = crypto_pwhash_OPSLIMIT_MIN;
  o.auth.memlimit = crypto_pwhash_MEMLIMIT_MIN;
  std::string scan_calibration;
  {
    auto ws = server::Workstation::open(o);
    ASSERT_TRUE(ws.ok()) << ws.status().message();
    auto scans = (*ws)->archive().scans();
    ASSERT_TRUE(scans.ok());
    ASSERT_EQ(scans->size(), 1u);
    scan_calibration = (*scans)[0].calibration_id;
    ASSERT_FALSE(scan_calibration.empty());
    const nlohmann::json rig = (*ws)->rig_status();
    ASSERT_TRUE(rig["calibration"].is_object()) << rig.dump();
    EXPECT_EQ(rig["calibration"]["id"], scan_calibration);
    EXPECT_EQ(rig["calibration"]["cameras"].size(), 3u);
    EXPECT_LT(rig["calibration"]["age_s"].get<int64_t>(), 600);
  }
  // Another rig does not inherit it.
  o.rig = "square";
  auto other = server::Workstation::open(o);
  ASSERT_TRUE(other.ok()) << other.status().message();
  EXPECT_TRUE((*other)->rig_status()["calibration"].is_null());
}

}  // namespace
}  // namespace bodyscan::testing
