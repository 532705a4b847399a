// Connected components of a binary image (4-connected), for the blob finders of
// calibration: frame markers (bright) and dot-grid spots (dark).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace bodyscan {

// Each pixel's component, row-major: -1 where `in(x, y)` is false, else a label in
// [0, *count), numbered in raster order of the components' first pixels. Two passes
// with union-find on the labels of the first.
template <typename In>
std::vector<int> label_components(int width, int height, In in, int* count) {
  std::vector<int> label(static_cast<size_t>(width) * height, -1);
  std::vector<int> parent;
  auto find = [&](int a) {
    while (parent[static_cast<size_t>(a)] != a) {
      a = parent[static_cast<size_t>(a)] = parent[static_cast<size_t>(parent[static_cast<size_t>(a)])];
    }
    return a;
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (!in(x, y)) continue;
      const int left = x > 0 ? label[i - 1] : -1, up = y > 0 ? label[i - static_cast<size_t>(width)] : -1;
      int l;
      if (left < 0 && up < 0) {
        l = static_cast<int>(parent.size());
        parent.push_back(l);
      } else if (left >= 0 && up >= 0) {
        l = find(left);
        const int u = find(up);
        if (u != l) parent[static_cast<size_t>(std::max(u, l))] = std::min(u, l), l = std::min(u, l);
      } else {
        l = left >= 0 ? left : up;
      }
      label[i] = l;
    }
  // Labels only ever join a smaller one, so one pass in order points every label at
  // its root; roots are then numbered densely.
  std::vector<int> dense(parent.size(), -1);
  int n = 0;
  for (size_t l = 0; l < parent.size(); ++l) {
    parent[l] = parent[static_cast<size_t>(parent[l])];
    if (parent[l] == static_cast<int>(l)) dense[l] = n++;
  }
  for (int& l : label)
    if (l >= 0) l = dense[static_cast<size_t>(parent[static_cast<size_t>(l)])];
  *count = n;
  return label;
}

}  // namespace bodyscan
