// The ways the laser-safety tests' child dies (tests/hw/usb/laser_safety_test.cpp,
// tests/hw/usb/laser_death_child.cpp), and the name the child takes each by.
#pragma once

#include <algorithm>
#include <iterator>
#include <optional>
#include <string_view>

namespace bodyscan::hw::testing {

enum class Death {
  kSegfault,
  kAbort,
  kTerminate,
  kSigterm,
  kSigint,
  kSigkill,
  kSighup,
  kStackOverflow,               // on the main thread, which installed the handlers
  kStackOverflowOnRigThread,    // on a thread that switched the laser on
  kStackOverflowOnOtherThread,  // on a thread that asked for an alternate stack
};

inline constexpr const char* kDeathNames[] = {"segfault",
                                              "abort",
                                              "terminate",
                                              "sigterm",
                                              "sigint",
                                              "sigkill",
                                              "sighup",
                                              "stack-overflow",
                                              "stack-overflow-on-rig-thread",
                                              "stack-overflow-on-other-thread"};

inline const char* death_name(Death death) { return kDeathNames[static_cast<int>(death)]; }

inline std::optional<Death> parse_death(std::string_view name) {
  const auto* at = std::find(std::begin(kDeathNames), std::end(kDeathNames), name);
  if (at == std::end(kDeathNames)) return std::nullopt;
  return static_cast<Death>(at - std::begin(kDeathNames));
}

}  // namespace bodyscan::hw::testing
