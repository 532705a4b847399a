// A simulated TMCL module (a TMCM-6110: 6 axes, 8 digital outputs) that answers
// like the real one: the 9-byte frames and their checksums, status codes for what
// it does not understand, motion that takes time, reference switches found by RFS,
// outputs, user variables, and stored TMCL programs run by the board itself (what
// the controller's board-side laser watchdog is made of). Faults for tests: silence,
// garbled replies, refusals, being unplugged.
//
// It serves in process (SimBoardLink) or behind a pseudo-terminal (PtyBoard), so
// the serial path of the real driver is exercised byte for byte.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "hw/usb/byte_link.hpp"
#include "hw/usb/tmcl.hpp"

namespace bodyscan::hw::usb {

class SimTmclBoard {
 public:
  static constexpr int kAxes = 6;
  static constexpr int kOutputs = 8;

  // `reference_switch[i]`: where axis i's home switch sits, in microsteps of the
  // motor's power-on position (the board does not know it until RFS finds it).
  explicit SimTmclBoard(uint8_t address = 1, std::array<int32_t, kAxes> reference_switch = {});
  ~SimTmclBoard();
  SimTmclBoard(const SimTmclBoard&) = delete;
  SimTmclBoard& operator=(const SimTmclBoard&) = delete;

  // One request frame in; the reply frame out, or nothing (silent, or a request for
  // another module).
  std::optional<tmcl::Frame> handle(const tmcl::Frame& request);

  // State, for tests.
  bool output(int i) const;
  int32_t position(int axis) const;
  bool application_running() const;
  int32_t user_variable(int i) const;
  uint64_t requests() const { return requests_; }
  // Times any of the outputs in `mask` was switched on, and how many of those the
  // board's own program switched off.
  int watchdog_trips() const { return watchdog_trips_; }
  // Frames refused for their checksum: answered "wrong checksum" and not run, as the
  // TMCL reference says a module does.
  uint64_t checksum_errors() const { return checksum_errors_; }
  // Requests from the host the board has acted on (run, or stored in download
  // mode), in order: how many, and the last `n` of them (at most kExecutedKept).
  static constexpr size_t kExecutedKept = 256;
  uint64_t executed_count() const;
  std::vector<tmcl::Request> last_executed(size_t n) const;

  // Faults.
  void set_silent(bool silent) { silent_ = silent; }
  void garble_next_replies(int n) { garble_ = n; }
  void refuse_next(uint8_t status) { refuse_ = status; }
  // Microsteps per second the axes move at, whatever the velocity parameter says.
  void set_speed(double microsteps_per_s) { speed_ = microsteps_per_s; }

 private:
  struct Axis {
    double position = 0;  // microsteps from the power-on position
    int32_t target = 0;
    bool moving = false;
    bool homing = false;
    int32_t switch_at = 0;  // in power-on coordinates
    int32_t origin = 0;     // power-on coordinate of the board's 0
  };
  void tick_loop();
  void advance(double dt);                      // under mutex
  void run_program_step();                      // under mutex
  tmcl::Reply execute(const tmcl::Request& r);  // under mutex

  const uint8_t address_;
  mutable std::mutex mutex_;
  std::array<Axis, kAxes> axes_;
  std::array<bool, kOutputs> outputs_{};
  std::array<int32_t, 256> user_vars_{};
  std::vector<tmcl::Request> program_;
  bool downloading_ = false;
  bool running_program_ = false;
  size_t pc_ = 0;
  int32_t accumulator_ = 0;
  bool compare_equal_ = true;
  double wait_left_s_ = 0;
  int watchdog_trips_ = 0;
  std::deque<tmcl::Request> executed_;  // the last kExecutedKept
  uint64_t executed_count_ = 0;
  std::atomic<uint64_t> checksum_errors_{0};
  double speed_ = 20000;
  std::atomic<bool> silent_{false};
  std::atomic<int> garble_{0};
  std::atomic<uint8_t> refuse_{0};
  std::atomic<uint64_t> requests_{0};
  std::atomic<bool> stop_{false};
  std::thread ticker_;
};

// The board in process, as a link (no serial port involved).
class SimBoardLink : public ByteLink {
 public:
  explicit SimBoardLink(SimTmclBoard& board) : board_(board) {}
  Status write(const uint8_t* data, size_t size, std::chrono::milliseconds timeout) override;
  Status read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) override;
  void discard_input() override;
  bool emergency_write(const uint8_t* data, size_t size) noexcept override;
  const std::string& name() const override { return name_; }
  void unplug() { unplugged_ = true; }

 private:
  void deliver(const uint8_t* data, size_t size);  // to the board, frame by frame
  SimTmclBoard& board_;
  std::string name_ = "the simulated board";
  std::mutex mutex_;
  std::vector<uint8_t> pending_;  // request bytes not yet a whole frame
  std::deque<uint8_t> replies_;
  std::atomic<bool> unplugged_{false};
};

// The board behind a pseudo-terminal: open path() with SerialLink as if it were
// /dev/ttyACM0. unplug() closes the master side, as pulling the cable does.
class PtyBoard {
 public:
  static StatusOr<std::unique_ptr<PtyBoard>> start(SimTmclBoard& board);
  ~PtyBoard();
  const std::string& path() const { return path_; }
  void unplug();

 private:
  PtyBoard(SimTmclBoard& board, int master, std::string path);
  void serve();
  SimTmclBoard& board_;
  int master_;
  std::string path_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace bodyscan::hw::usb
