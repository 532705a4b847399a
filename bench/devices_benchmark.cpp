// What the real-device paths cost (issue 9), without the hardware: the TMCL
// protocol to the simulated board in process and over a pseudo-terminal (the
// serial driver byte for byte), the rig controller's laser switching and one
// laser step on it, the board-side watchdog's trip time, Aravis' in-process fake
// camera grabbing at the thesis rig's frame size, and unpacking the packed pixel
// formats a GigE camera sends.
//
//   ./build/bench/devices_benchmark [--json OUT.json] [Google Benchmark's flags]
//
// The figures are in docs/benchmarks.md §11 (rendered by bench/tables.py from --json).
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

#include "bench/benchmark_main.hpp"
#include "hw/aravis/aravis_camera.hpp"
#include "hw/aravis/pixel_unpack.hpp"
#include "hw/rig_description.hpp"
#include "hw/usb/serial_link.hpp"
#include "hw/usb/sim_tmcl_board.hpp"
#include "hw/usb/tmcl.hpp"
#include "hw/usb/tmcl_controller.hpp"

namespace bodyscan {
namespace {

using namespace hw::usb;

// The shop example's TMCL wiring (hw/rigs/examples/shop-example.json) on `port`,
// with the watchdog period given.
hw::RigDescription shop_rig(const std::string& port, int watchdog_ms) {
  const std::filesystem::path rigs = std::filesystem::path(*hw::shipped_rig_path("thesis")).parent_path();
  auto rig = hw::load_rig_description((rigs / "examples" / "shop-example.json").string());
  if (!rig.ok()) throw std::runtime_error(rig.status().message());
  rig->controller.port = port;
  rig->controller.watchdog_ms = watchdog_ms;
  return *rig;
}

// Requests and their replies (GIO: read an output) over `link`.
void time_requests(benchmark::State& state, ByteLink& link) {
  tmcl::Client client(link);
  for (auto _ : state) {
    auto v = client.call(tmcl::kGIO, 0, tmcl::kBankOutputs, 0);
    if (!v.ok()) state.SkipWithError(v.status().message().c_str());
    benchmark::DoNotOptimize(v);
  }
  state.SetItemsProcessed(state.iterations());
}

// To the board in process.
void BM_TmclRequestInProcess(benchmark::State& state) {
  SimTmclBoard board;
  SimBoardLink link(board);
  time_requests(state, link);
}
BENCHMARK(BM_TmclRequestInProcess)->UseRealTime();

// The same through SerialLink over a pseudo-terminal: the path a board on
// /dev/ttyACM0 takes.
void BM_TmclRequestPty(benchmark::State& state) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  if (!pty.ok()) return state.SkipWithError(pty.status().message().c_str());
  auto link = SerialLink::open((*pty)->path());
  if (!link.ok()) return state.SkipWithError(link.status().message().c_str());
  time_requests(state, **link);
}
BENCHMARK(BM_TmclRequestPty)->UseRealTime();

// A laser on and off through the rig's controller over the pty (each switch is
// a request the board confirms).
void BM_ControllerLaserOnOffPty(benchmark::State& state) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  if (!pty.ok()) return state.SkipWithError(pty.status().message().c_str());
  auto c = TmclController::open(shop_rig((*pty)->path(), 500));
  if (!c.ok()) return state.SkipWithError(c.status().message().c_str());
  for (auto _ : state) {
    if (!(*c)->set_laser(0, true).ok() || !(*c)->set_laser(0, false).ok()) state.SkipWithError("set_laser failed");
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ControllerLaserOnOffPty)->UseRealTime();

// One laser step (16 microsteps) there and back, waiting for the board to report
// the position reached, over the pty. The simulated motor runs 20,000 microsteps
// a second, so 0.8 ms of each move is the motor's; the rest is the protocol and
// the polling.
void BM_ControllerLaserStepPty(benchmark::State& state) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  if (!pty.ok()) return state.SkipWithError(pty.status().message().c_str());
  auto c = TmclController::open(shop_rig((*pty)->path(), 500));
  if (!c.ok()) return state.SkipWithError(c.status().message().c_str());
  if (!(*c)->home(0).ok()) return state.SkipWithError("home failed");
  int step = 0;
  for (auto _ : state) {
    step = step == 0 ? 1 : 0;
    if (!(*c)->move_to(0, step).ok()) state.SkipWithError("move failed");
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ControllerLaserStepPty)->UseRealTime();

// The cable pulled while a laser shines: from then until the board's own program
// (the watchdog open() stores, 500 ms period) switches the laser off, with no
// host to tell it. Reported as the manual time.
void BM_WatchdogTrip(benchmark::State& state) {
  for (auto _ : state) {
    SimTmclBoard board;
    auto pty = PtyBoard::start(board);
    if (!pty.ok()) return state.SkipWithError(pty.status().message().c_str());
    const hw::RigDescription rig = shop_rig((*pty)->path(), 500);
    const int output = rig.controller.lasers.at(0).output;
    auto c = TmclController::open(rig);
    if (!c.ok()) return state.SkipWithError(c.status().message().c_str());
    if (!(*c)->set_laser(0, true).ok()) return state.SkipWithError("set_laser failed");
    std::this_thread::sleep_for(std::chrono::milliseconds(700));  // fed a while
    (*pty)->unplug();
    const auto t0 = std::chrono::steady_clock::now();
    while (board.output(output) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5))
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    if (board.output(output)) return state.SkipWithError("the watchdog never tripped");
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
}
BENCHMARK(BM_WatchdogTrip)->UseManualTime()->Iterations(10)->Unit(benchmark::kMillisecond);

// Software-triggered frames from Aravis' in-process fake camera at the thesis
// rig's 1280 x 1024 (Mono8 and Mono16): the buffer pool, the trigger, the copy
// into a Frame.
void BM_AravisFakeGrab(benchmark::State& state) {
  hw::CameraDescription d;
  d.id = "bench";
  d.width = 1280;
  d.height = 1024;
  d.exposure_us = 1000;
  d.device.backend = "aravis";
  d.device.id = "Fake_1";
  d.device.timeout_ms = 2000;
  auto cam = hw::aravis::AravisCamera::open(d);
  if (!cam.ok()) return state.SkipWithError(cam.status().message().c_str());
  if (state.range(0) == 16 && !(*cam)->set_pixel_format(hw::PixelFormat::kMono16).ok())
    return state.SkipWithError("no Mono16");
  for (auto _ : state) {
    auto f = (*cam)->grab(std::chrono::milliseconds(2000));
    if (!f.ok()) state.SkipWithError(f.status().message().c_str());
    benchmark::DoNotOptimize(f);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * 1280 * 1024 * (state.range(0) / 8));
}
BENCHMARK(BM_AravisFakeGrab)->Arg(8)->Arg(16)->UseRealTime()->Unit(benchmark::kMillisecond);

// Unpacking one 1280 x 1024 frame of each packed format into 16-bit pixels.
void BM_Unpack(benchmark::State& state) {
  const uint32_t code = static_cast<uint32_t>(state.range(0));
  const int w = 1280, h = 1024;
  const size_t bytes = static_cast<size_t>(w) * h * static_cast<size_t>(hw::aravis::pfnc_bits(code) > 8 ? 2 : 1);
  std::vector<uint8_t> data(bytes);
  std::mt19937 rng(7);
  for (uint8_t& b : data) b = static_cast<uint8_t>(rng());
  std::vector<uint16_t> out;
  state.SetLabel(hw::aravis::pfnc_name(code));
  for (auto _ : state) {
    const Status s = hw::aravis::unpack_mono(code, data.data(), data.size(), w, h, out);
    if (!s.ok()) state.SkipWithError(s.message().c_str());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * w * h);
}
BENCHMARK(BM_Unpack)
    ->Arg(hw::aravis::kPfncMono8)
    ->Arg(hw::aravis::kPfncMono12Packed)
    ->Arg(hw::aravis::kPfncMono12p)
    ->Arg(hw::aravis::kPfncMono10p)
    ->Arg(hw::aravis::kPfncMono16)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bodyscan

int main(int argc, char** argv) { return bodyscan::bench::run_benchmarks(argc, argv); }
