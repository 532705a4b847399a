// The median of a sample, for robust scale estimates.
#pragma once

#include <algorithm>
#include <vector>

namespace bodyscan {

// The upper median of v (v[n/2] in sorted order); reorders v. 0 when v is empty.
inline float median_in_place(std::vector<float>& v) {
  if (v.empty()) return 0.f;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace bodyscan
