#include "hw/usb/sim_tmcl_board.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace bodyscan::hw::usb {

using namespace tmcl;  // NOLINT(google-build-using-namespace): the protocol's names

SimTmclBoard::SimTmclBoard(uint8_t address, std::array<int32_t, kAxes> reference_switch) : address_(address) {
  for (int i = 0; i < kAxes; ++i) axes_[static_cast<size_t>(i)].switch_at = reference_switch[static_cast<size_t>(i)];
  ticker_ = std::thread([this] { tick_loop(); });
}

SimTmclBoard::~SimTmclBoard() {
  stop_ = true;
  ticker_.join();
}

void SimTmclBoard::tick_loop() {
  auto last = std::chrono::steady_clock::now();
  while (!stop_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    std::lock_guard lock(mutex_);
    advance(dt);
    if (running_program_) {
      wait_left_s_ -= dt;
      for (int i = 0; i < 64 && running_program_ && wait_left_s_ <= 0; ++i) run_program_step();
    }
  }
}

void SimTmclBoard::advance(double dt) {
  for (Axis& a : axes_) {
    if (a.homing) {
      // Reference search: towards the switch; the switch's position becomes 0.
      const double to = a.switch_at - a.position;
      const double step = speed_ * dt;
      if (std::abs(to) <= step) {
        a.position = a.switch_at;
        a.origin = a.switch_at;
        a.homing = false;
        a.target = 0;
      } else {
        a.position += to > 0 ? step : -step;
      }
      continue;
    }
    if (!a.moving) continue;
    const double goal = a.origin + a.target;
    const double to = goal - a.position;
    const double step = speed_ * dt;
    if (std::abs(to) <= step) {
      a.position = goal;
      a.moving = false;
    } else {
      a.position += to > 0 ? step : -step;
    }
  }
}

void SimTmclBoard::run_program_step() {
  if (pc_ >= program_.size()) {
    running_program_ = false;
    return;
  }
  const Request r = program_[pc_++];
  switch (r.command) {
    case kWAIT:
      if (r.type == kWaitTicks) wait_left_s_ = r.value * 0.01;
      break;
    case kGGP:
      if (r.bank == kBankUserVariables) accumulator_ = user_vars_[r.type];
      break;
    case kAGP:
      if (r.bank == kBankUserVariables) user_vars_[r.type] = accumulator_;
      break;
    case kCALC:
      if (r.type == kCalcLoad) accumulator_ = r.value;
      break;
    case kCOMP: compare_equal_ = accumulator_ == r.value; break;
    case kJC:
      if (r.type == kJcNotEqual && !compare_equal_) pc_ = static_cast<size_t>(r.value);
      break;
    case kJA: pc_ = static_cast<size_t>(r.value); break;
    case kSIO:
      if (r.bank == kBankOutputs && r.type < kOutputs) {
        if (outputs_[r.type] && r.value == 0) ++watchdog_trips_;
        outputs_[r.type] = r.value != 0;
      }
      break;
    case kSTOP: running_program_ = false; break;
    default:  // what this board does not run stops the application, as a real one does
      running_program_ = false;
      break;
  }
}

Reply SimTmclBoard::execute(const Request& r) {
  Reply rep{2, address_, kSuccess, r.command, 0};
  auto axis_ok = [&](int i) { return i >= 0 && i < kAxes; };
  if (downloading_ && r.command != kQuitDownload) {
    program_.push_back(r);
    rep.status = kLoaded;
    return rep;
  }
  switch (r.command) {
    case kMVP: {
      if (!axis_ok(r.bank)) return rep.status = kInvalidValue, rep;
      Axis& a = axes_[r.bank];
      if (r.type == kMvpAbsolute)
        a.target = r.value;
      else if (r.type == kMvpRelative)
        a.target += r.value;
      else
        return rep.status = kWrongType, rep;
      a.moving = true;
      rep.value = a.target;
      return rep;
    }
    case kMST:
      if (!axis_ok(r.bank)) return rep.status = kInvalidValue, rep;
      axes_[r.bank].moving = false;
      axes_[r.bank].homing = false;
      axes_[r.bank].target = static_cast<int32_t>(std::lround(axes_[r.bank].position - axes_[r.bank].origin));
      return rep;
    case kRFS:
      if (!axis_ok(r.bank)) return rep.status = kInvalidValue, rep;
      if (r.type == kRfsStart)
        axes_[r.bank].homing = true, axes_[r.bank].moving = false;
      else if (r.type == kRfsStop)
        axes_[r.bank].homing = false;
      else if (r.type == kRfsStatus)
        rep.value = axes_[r.bank].homing ? 1 : 0;
      else
        rep.status = kWrongType;
      return rep;
    case kGAP:
    case kSAP: {
      if (!axis_ok(r.bank)) return rep.status = kInvalidValue, rep;
      Axis& a = axes_[r.bank];
      const auto pos = static_cast<int32_t>(std::lround(a.position - a.origin));
      if (r.command == kSAP) {
        if (r.type == kApActualPosition)
          a.origin = static_cast<int32_t>(std::lround(a.position)) - r.value;
        else if (r.type == kApTargetPosition)
          a.target = r.value, a.moving = true;
        else if (r.type != kApMaxVelocity && r.type != kApMaxAcceleration && r.type < 130)
          rep.status = kWrongType;
        return rep;
      }
      switch (r.type) {
        case kApTargetPosition: rep.value = a.target; break;
        case kApActualPosition: rep.value = pos; break;
        case kApPositionReached: rep.value = (!a.moving && !a.homing) ? 1 : 0; break;
        case kApReferenceSwitch: rep.value = std::lround(a.position) == a.switch_at ? 1 : 0; break;
        case kApMaxVelocity:
        case kApMaxAcceleration: rep.value = static_cast<int32_t>(speed_); break;
        default: rep.status = kWrongType;
      }
      return rep;
    }
    case kSIO:
      if (r.bank != kBankOutputs) return rep.status = kWrongType, rep;
      if (r.type >= kOutputs) return rep.status = kInvalidValue, rep;
      outputs_[r.type] = r.value != 0;
      return rep;
    case kGIO:
      if (r.bank == kBankOutputs && r.type < kOutputs)
        rep.value = outputs_[r.type] ? 1 : 0;
      else if (r.bank == kBankInputs && r.type < 8)
        rep.value = 0;
      else
        rep.status = kInvalidValue;
      return rep;
    case kSGP:
    case kGGP:
      if (r.bank != kBankUserVariables) return rep.status = kWrongType, rep;
      if (r.command == kSGP)
        user_vars_[r.type] = r.value;
      else
        rep.value = user_vars_[r.type];
      return rep;
    case kStartDownload:
      program_.clear();
      running_program_ = false;
      downloading_ = true;
      return rep;
    case kQuitDownload: downloading_ = false; return rep;
    case kRunApplication:
      pc_ = static_cast<size_t>(r.type == 1 ? r.value : 0);
      running_program_ = !program_.empty();
      wait_left_s_ = 0;
      return rep;
    case kStopApplication: running_program_ = false; return rep;
    case kResetApplication:
      running_program_ = false;
      pc_ = 0;
      return rep;
    case kGetApplicationStatus: rep.value = running_program_ ? 1 : 0; return rep;
    default: rep.status = kInvalidCommand; return rep;
  }
}

std::optional<Frame> SimTmclBoard::handle(const Frame& request) {
  ++requests_;
  if (silent_) return std::nullopt;
  if (request[0] != address_) return std::nullopt;  // another module on the bus
  Frame out;
  if (!checksum_ok(request)) {
    ++checksum_errors_;
    out = encode(Reply{2, address_, kWrongChecksum, request[1], 0});
  } else if (request[1] == kGetFirmwareVersion && request[2] == 0) {
    out = Frame{2, '6', '1', '1', '0', 'V', '1', '3', '0'};
  } else if (const uint8_t refuse = refuse_.exchange(0); refuse != 0) {
    out = encode(Reply{2, address_, refuse, request[1], 0});
  } else {
    std::lock_guard lock(mutex_);
    const Request r = decode_request(request);
    executed_.push_back(r);
    if (executed_.size() > kExecutedKept) executed_.pop_front();
    ++executed_count_;
    out = encode(execute(r));
  }
  if (garble_ > 0) {
    --garble_;
    out[8] ^= 0x5a;
  }
  return out;
}

bool SimTmclBoard::output(int i) const {
  std::lock_guard lock(mutex_);
  return outputs_.at(static_cast<size_t>(i));
}
int32_t SimTmclBoard::position(int axis) const {
  std::lock_guard lock(mutex_);
  const Axis& a = axes_.at(static_cast<size_t>(axis));
  return static_cast<int32_t>(std::lround(a.position - a.origin));
}
bool SimTmclBoard::application_running() const {
  std::lock_guard lock(mutex_);
  return running_program_;
}
uint64_t SimTmclBoard::executed_count() const {
  std::lock_guard lock(mutex_);
  return executed_count_;
}
std::vector<Request> SimTmclBoard::last_executed(size_t n) const {
  std::lock_guard lock(mutex_);
  n = std::min(n, executed_.size());
  return std::vector<Request>(executed_.end() - static_cast<std::ptrdiff_t>(n), executed_.end());
}
int32_t SimTmclBoard::user_variable(int i) const {
  std::lock_guard lock(mutex_);
  return user_vars_.at(static_cast<size_t>(i));
}

// ---- in process ----

Status SimBoardLink::write(const uint8_t* data, size_t size, std::chrono::milliseconds) {
  if (unplugged_) return unavailable("the simulated board is unplugged");
  WireLedger::Send send(ledger_);
  if (!send.open()) return unavailable("the simulated board is taken by the emergency stop");
  send.sent(data, size);
  deliver(data, size);
  return Status::Ok();
}

void SimBoardLink::deliver(const uint8_t* data, size_t size) {
  std::lock_guard lock(mutex_);
  pending_.insert(pending_.end(), data, data + size);
  while (pending_.size() >= 9) {
    Frame f;
    std::copy(pending_.begin(), pending_.begin() + 9, f.begin());
    pending_.erase(pending_.begin(), pending_.begin() + 9);
    if (auto rep = board_.handle(f)) replies_.insert(replies_.end(), rep->begin(), rep->end());
  }
}

Status SimBoardLink::read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) {
  if (unplugged_) return unavailable("the simulated board is unplugged");
  std::unique_lock lock(mutex_);
  if (replies_.size() < size) {
    lock.unlock();
    std::this_thread::sleep_for(timeout);  // nothing else will come: the board answers at once
    return deadline_exceeded("the simulated board did not answer within " + std::to_string(timeout.count()) + " ms");
  }
  for (size_t i = 0; i < size; ++i) {
    data[i] = replies_.front();
    replies_.pop_front();
  }
  return Status::Ok();
}

void SimBoardLink::discard_input() {
  std::lock_guard lock(mutex_);
  replies_.clear();
}

bool SimBoardLink::emergency_write(const uint8_t* data, size_t size) noexcept {
  // Tests only: a real link's emergency path is a plain system call.
  if (unplugged_) return false;
  try {
    deliver(data, size);
  } catch (...) {
    return false;
  }
  ledger_.record(data, size);
  return true;
}

// ---- behind a pseudo-terminal ----

StatusOr<std::unique_ptr<PtyBoard>> PtyBoard::start(SimTmclBoard& board) {
  const int master = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
    const int err = errno;
    if (master >= 0) ::close(master);
    return io_error(std::string("cannot make a pseudo-terminal: ") + std::strerror(err));
  }
  char name[128];
  if (ptsname_r(master, name, sizeof name) != 0) {
    ::close(master);
    return io_error("cannot name the pseudo-terminal");
  }
  termios tio{};
  if (tcgetattr(master, &tio) == 0) {
    cfmakeraw(&tio);
    tcsetattr(master, TCSANOW, &tio);
  }
  return std::unique_ptr<PtyBoard>(new PtyBoard(board, master, name));
}

PtyBoard::PtyBoard(SimTmclBoard& board, int master, std::string path)
    : board_(board), master_(master), path_(std::move(path)) {
  thread_ = std::thread([this] { serve(); });
}

PtyBoard::~PtyBoard() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (master_ >= 0) ::close(master_);
}

void PtyBoard::unplug() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  ::close(master_);
  master_ = -1;
}

void PtyBoard::serve() {
  std::vector<uint8_t> pending;
  while (!stop_) {
    pollfd p{master_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0 || !(p.revents & POLLIN)) continue;
    uint8_t buf[256];
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) continue;  // EIO while no one has the slave open
    pending.insert(pending.end(), buf, buf + n);
    while (pending.size() >= 9) {
      Frame f;
      std::copy(pending.begin(), pending.begin() + 9, f.begin());
      pending.erase(pending.begin(), pending.begin() + 9);
      if (auto rep = board_.handle(f)) (void)!::write(master_, rep->data(), rep->size());
    }
  }
}

}  // namespace bodyscan::hw::usb
