// Progress reporting for long algorithms: a stage name and the fraction done.
// Called from the thread that runs the algorithm; must be cheap and thread-safe
// with respect to the caller's own state. Returning false asks the algorithm to
// stop early (it then returns a Cancelled status).
#pragma once

#include <functional>
#include <string_view>

namespace bodyscan {

using ProgressFn = std::function<bool(std::string_view stage, double fraction)>;

inline bool report(const ProgressFn& fn, std::string_view stage, double fraction) {
  return fn ? fn(stage, fraction) : true;
}

}  // namespace bodyscan
