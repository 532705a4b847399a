// Laser safety on the paths that bypass destructors: a crash (SIGSEGV, SIGBUS,
// SIGILL, SIGFPE, SIGABRT), std::terminate, and - in processes that do not take
// them themselves - SIGINT, SIGTERM, SIGHUP and SIGQUIT.
//
// Each controller registers an emergency stop: a function that switches its lasers
// off using only async-signal-safe calls (a prepared byte string written with
// write(2) or one usbfs ioctl). The handlers run every registered stop, then let
// the signal do what it would have done. Orderly paths (errors, exceptions, the
// server stopping) go through Controller::all_lasers_off and LasersOff instead.
// SIGKILL and power loss cannot be caught: the board-side watchdog covers them
// (hw/usb/tmcl_controller.hpp).
//
// A handler needs stack to run on, and a thread whose stack overflowed has none
// left: the kernel then ends the process without running any handler. So the
// handlers run on an alternate signal stack (sigaltstack), which is per thread:
// the thread that installs the handlers gets one for the life of the process, and
// every other thread that may crash with the lasers on must get its own with
// ensure_alternate_signal_stack. TmclController does that on each thread that
// switches a laser on, so the thread driving the rig always has one.
#pragma once

namespace bodyscan::hw {

using EmergencyStopFn = void (*)(void* context) noexcept;

// Returns a slot for unregister_emergency_stop, or -1 when all 16 are taken.
int register_emergency_stop(EmergencyStopFn fn, void* context);
void unregister_emergency_stop(int slot);

// Runs every registered stop. Async-signal-safe.
void run_emergency_stops() noexcept;

// Installs the handlers (idempotent). With `termination_signals`, SIGINT, SIGTERM,
// SIGHUP and SIGQUIT also switch the lasers off before ending the process; leave it
// false in a process that handles them itself (`bodyscan serve` takes them with
// sigwait and stops in order).
void install_laser_safety_handlers(bool termination_signals);

// Gives the calling thread an alternate signal stack, unless it has one, kept until
// the thread ends. Cheap after the first call on a thread. False when the thread
// has none (out of memory).
bool ensure_alternate_signal_stack();

}  // namespace bodyscan::hw
