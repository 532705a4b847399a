// The TMCL stack without hardware: the frame format against hand-computed bytes,
// the client against the simulated board in process (errors, garbage, silence,
// unplugging), and the rig's controller over a pseudo-terminal - the same serial
// path a /dev/ttyACM0 board takes.
#include "hw/usb/tmcl.hpp"

#include <gtest/gtest.h>

#include <thread>

#include "hw/usb/serial_link.hpp"
#include "hw/usb/sim_tmcl_board.hpp"
#include "hw/usb/tmcl_controller.hpp"
#include "hw/usb/usb_link.hpp"
#include "tests/hw/usb/tmcl_rig.hpp"

namespace bodyscan::hw::usb {
namespace {

using namespace std::chrono_literals;

TEST(Tmcl, FramesMatchTheReference) {
  // MVP ABS, motor 0, 1000 microsteps to module 1: 01 04 00 00 000003E8 F0.
  const tmcl::Frame f = tmcl::encode(tmcl::Request{1, tmcl::kMVP, tmcl::kMvpAbsolute, 0, 1000});
  const tmcl::Frame want{0x01, 0x04, 0x00, 0x00, 0x00, 0x00, 0x03, 0xE8, 0xF0};
  EXPECT_EQ(f, want);
  // Negative values are two's complement, big-endian.
  const tmcl::Frame g = tmcl::encode(tmcl::Request{1, tmcl::kMVP, 0, 2, -2});
  EXPECT_EQ(g[4], 0xFF);
  EXPECT_EQ(g[7], 0xFE);
  EXPECT_EQ(tmcl::decode_request(g).value, -2);
  tmcl::Frame bad = f;
  bad[6] ^= 1;
  EXPECT_FALSE(tmcl::checksum_ok(bad));
  const tmcl::Reply r{2, 1, tmcl::kSuccess, tmcl::kGAP, -123456};
  EXPECT_EQ(tmcl::decode_reply(tmcl::encode(r)).value, -123456);
}

TEST(Tmcl, ClientTalksToTheBoard) {
  SimTmclBoard board;
  SimBoardLink link(board);
  tmcl::Client client(link, 1, 50ms);
  auto version = client.firmware_version();
  ASSERT_TRUE(version.ok()) << version.status().message();
  EXPECT_EQ(*version, "6110V130");
  ASSERT_TRUE(client.call(tmcl::kSIO, 3, tmcl::kBankOutputs, 1).ok());
  EXPECT_TRUE(board.output(3));
  auto out = client.call(tmcl::kGIO, 3, tmcl::kBankOutputs, 0);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(*out, 1);
  // The board's refusals come back in its words.
  auto refused = client.call(77, 0, 0, 0);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("invalid command"), std::string::npos) << refused.status().message();
  auto range = client.call(tmcl::kSIO, 42, tmcl::kBankOutputs, 1);
  ASSERT_FALSE(range.ok());
  EXPECT_NE(range.status().message().find("invalid value"), std::string::npos);
}

TEST(Tmcl, GarbledRepliesAreRetriedThenReported) {
  SimTmclBoard board;
  SimBoardLink link(board);
  tmcl::Client client(link, 1, 30ms, 3);
  board.garble_next_replies(2);  // two bad checksums, then a good reply
  auto ok = client.call(tmcl::kSIO, 0, tmcl::kBankOutputs, 1);
  EXPECT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_TRUE(board.output(0));
  board.garble_next_replies(3);
  auto bad = client.call(tmcl::kSIO, 0, tmcl::kBankOutputs, 0);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInternal);
  EXPECT_NE(bad.status().message().find("bad checksum"), std::string::npos) << bad.status().message();
  EXPECT_NE(bad.status().message().find("3 tries"), std::string::npos);
}

TEST(Tmcl, SilenceAndUnpluggingAreReported) {
  SimTmclBoard board;
  SimBoardLink link(board);
  tmcl::Client client(link, 1, 20ms, 2);
  board.set_silent(true);
  auto silent = client.call(tmcl::kGAP, tmcl::kApActualPosition, 0, 0);
  ASSERT_FALSE(silent.ok());
  EXPECT_EQ(silent.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(silent.status().message().find("did not answer"), std::string::npos) << silent.status().message();
  board.set_silent(false);
  link.unplug();
  auto gone = client.call(tmcl::kGAP, tmcl::kApActualPosition, 0, 0);
  ASSERT_FALSE(gone.ok());
  EXPECT_EQ(gone.status().code(), StatusCode::kUnavailable);
}

TEST(Tmcl, SerialLinkOverAPseudoTerminal) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok()) << pty.status().message();
  auto link = SerialLink::open((*pty)->path());
  ASSERT_TRUE(link.ok()) << link.status().message();
  tmcl::Client client(**link, 1, 200ms);
  auto version = client.firmware_version();
  ASSERT_TRUE(version.ok()) << version.status().message();
  EXPECT_EQ(*version, "6110V130");
  ASSERT_TRUE(client.call(tmcl::kSIO, 5, tmcl::kBankOutputs, 1).ok());
  EXPECT_TRUE(board.output(5));
  // A request for another module on the bus gets no answer.
  tmcl::Client other(**link, 7, 50ms, 1);
  EXPECT_EQ(other.call(tmcl::kGIO, 0, 2, 0).status().code(), StatusCode::kDeadlineExceeded);
  // The cable pulled: the port reports it, not a timeout.
  (*pty)->unplug();
  auto gone = client.call(tmcl::kGIO, 5, tmcl::kBankOutputs, 0);
  ASSERT_FALSE(gone.ok());
  EXPECT_EQ(gone.status().code(), StatusCode::kUnavailable) << gone.status().message();
}

TEST(Tmcl, MissingPortSaysWhatToCheck) {
  auto link = SerialLink::open("/dev/does-not-exist-ttyACM9");
  ASSERT_FALSE(link.ok());
  EXPECT_NE(link.status().message().find("plugged in"), std::string::npos) << link.status().message();
}

// No board on the USB bus (there is none on a test machine; a shop's unplugged
// cable): unavailable, naming the ids and what to check - whether or not the
// machine has USB at all.
TEST(Tmcl, MissingUsbBoardSaysWhatToCheck) {
  auto link = UsbLink::open(0x2a3c, 0x0100, "NO-SUCH-SERIAL");
  ASSERT_FALSE(link.ok());
  EXPECT_EQ(link.status().code(), StatusCode::kUnavailable) << link.status().message();
  const std::string& m = link.status().message();
  EXPECT_TRUE(m.find("2a3c:0100") != std::string::npos || m.find("libusb") != std::string::npos) << m;
  auto listed = list_usb_devices();
  if (listed.ok()) {
    for (const UsbDeviceInfo& d : *listed) EXPECT_FALSE(d.serial == "NO-SUCH-SERIAL");
  } else {
    EXPECT_EQ(listed.status().code(), StatusCode::kUnavailable) << listed.status().message();
  }
}

TEST(TmclController, DrivesTheRigOverAPseudoTerminal) {
  // The home switches sit off the motors' power-on positions; home() finds them.
  SimTmclBoard board(1, {3000, -2500, 800, 0, 0, 0});
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  const RigDescription rig = testing::tmcl_rig((*pty)->path(), 0);
  auto opened = TmclController::open(rig);
  ASSERT_TRUE(opened.ok()) << opened.status().message();
  TmclController& c = **opened;
  EXPECT_EQ(c.firmware(), "6110V130");
  ASSERT_EQ(c.num_lasers(), 4);
  const auto& w = rig.controller.lasers;

  EXPECT_EQ(c.move_to(0, 10).code(), StatusCode::kFailedPrecondition);  // not homed
  for (int m = 0; m < 4; ++m) ASSERT_TRUE(c.home(m).ok());
  ASSERT_TRUE(c.move_to(1, -120).ok());
  EXPECT_EQ(board.position(w[1].axis), w[1].home_offset - 120 * w[1].microsteps_per_step);
  auto step = c.current_step(1);
  ASSERT_TRUE(step.ok());
  EXPECT_EQ(*step, -120);
  EXPECT_EQ(c.move_to(1, 10000).code(), StatusCode::kOutOfRange);

  ASSERT_TRUE(c.set_laser(2, true).ok());
  EXPECT_TRUE(board.output(w[2].output));
  EXPECT_TRUE(c.laser_on(2));
  ASSERT_TRUE(c.set_room_lights(true).ok());
  EXPECT_TRUE(board.output(rig.controller.room_lights_output));
  ASSERT_TRUE(c.set_frame_light_circuits(true, false).ok());
  EXPECT_TRUE(board.output(rig.controller.front_lights_output));
  EXPECT_FALSE(board.output(rig.controller.back_lights_output));

  // The board refuses a move: the error says which laser, and the lasers go off.
  board.refuse_next(tmcl::kInvalidValue);
  const Status refused = c.move_to(0, 5);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("front-left"), std::string::npos) << refused.message();
  EXPECT_FALSE(board.output(w[2].output));
  EXPECT_FALSE(c.laser_on(2));

  ASSERT_TRUE(c.set_laser(3, true).ok());
  opened->reset();  // closing switches every laser off
  EXPECT_FALSE(board.output(w[3].output));
}

TEST(TmclController, BoardFallingSilentMidMoveIsAnErrorNotAHang) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  RigDescription rig = testing::tmcl_rig((*pty)->path(), 0);
  rig.controller.reply_timeout_ms = 30;
  auto c = TmclController::open(rig);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE((*c)->home(0).ok());
  board.set_silent(true);
  const auto t0 = std::chrono::steady_clock::now();
  const Status st = (*c)->move_to(0, 100);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(st.message().find("front-left"), std::string::npos) << st.message();
}

// A stalled motor or a switch that never closes: the wait ends at the
// description's timeout with what to check, the axis stopped and every laser off.
TEST(TmclController, StalledMotorAndMissingSwitchTimeOut) {
  SimTmclBoard board(1, {400000, 0, 0, 0, 0, 0});  // axis 0's switch far away
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  RigDescription rig = testing::tmcl_rig((*pty)->path(), 0);
  rig.controller.home_timeout_ms = 300;
  rig.controller.move_timeout_ms = 300;
  auto c = TmclController::open(rig);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE((*c)->set_laser(1, true).ok());
  Status st = (*c)->home(0);
  EXPECT_EQ(st.code(), StatusCode::kDeadlineExceeded) << st.message();
  EXPECT_NE(st.message().find("reference switch within 300 ms"), std::string::npos) << st.message();
  EXPECT_FALSE(board.output(rig.controller.lasers[1].output));
  EXPECT_FALSE((*c)->laser_on(1));
  const int32_t stopped_at = board.position(0);
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(board.position(0), stopped_at) << "the search was stopped";

  ASSERT_TRUE((*c)->home(1).ok());  // axis 1's switch is at its power-on position
  board.set_speed(10);              // microsteps per second: a stall
  ASSERT_TRUE((*c)->set_laser(1, true).ok());
  st = (*c)->move_to(1, rig.lasers[1].max_step);
  EXPECT_EQ(st.code(), StatusCode::kDeadlineExceeded) << st.message();
  EXPECT_NE(st.message().find("did not reach step"), std::string::npos) << st.message();
  EXPECT_FALSE(board.output(rig.controller.lasers[1].output));
}

TEST(TmclController, StoresAndRunsTheWatchdog) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  // A period well above any scheduling delay on a loaded test machine.
  const RigDescription rig = testing::tmcl_rig((*pty)->path(), 1000);
  {
    auto c = TmclController::open(rig);
    ASSERT_TRUE(c.ok()) << c.status().message();
    EXPECT_TRUE(board.application_running());
    ASSERT_TRUE((*c)->set_laser(0, true).ok());
    // Fed by the controller, the watchdog leaves the laser on.
    std::this_thread::sleep_for(2500ms);
    EXPECT_TRUE(board.output(rig.controller.lasers[0].output));
    EXPECT_EQ(board.watchdog_trips(), 0);
  }
  EXPECT_TRUE(board.application_running());  // it keeps the lasers off after the host is gone
}

}  // namespace
}  // namespace bodyscan::hw::usb
