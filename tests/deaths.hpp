// Ways for a test's child process to die that the optimiser cannot remove: the
// laser-safety tests kill a process with a laser on and check the board saw it
// switched off.
#pragma once

namespace bodyscan::testing {

// Whether to go deeper is a volatile read, and each frame's volatile buffer is
// read after the call returns, so the recursion can neither be dropped nor turned
// into a loop: it overflows the stack.
inline volatile bool g_deeper = true;
[[gnu::noinline]] inline int overflow_stack(int depth) {
  volatile char frame[1024];
  frame[0] = static_cast<char>(depth);
  const int below = g_deeper ? overflow_stack(depth + 1) : depth;
  return below + frame[0];
}

}  // namespace bodyscan::testing
