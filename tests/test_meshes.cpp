#include "tests/test_meshes.hpp"

#include <cmath>
#include <map>
#include <utility>

namespace bodyscan::testing {

TriangleMesh box_mesh(const Vec3f& lo, const Vec3f& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), ((i >> 1) & 1) ? hi.y() : lo.y(),
                            ((i >> 2) & 1) ? hi.z() : lo.z());
  }
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TriangleMesh unit_cube() { return box_mesh(Vec3f::Zero(), Vec3f::Ones()); }

TriangleMesh icosphere(int levels, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3d& p : v) p.normalize();
  std::vector<Triangle> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const auto index = static_cast<uint32_t>(v.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<Triangle> finer;
    for (const Triangle& tri : f) {
      const uint32_t ab = midpoint(tri[0], tri[1]);
      const uint32_t bc = midpoint(tri[1], tri[2]);
      const uint32_t ca = midpoint(tri[2], tri[0]);
      finer.push_back({tri[0], ab, ca});
      finer.push_back({tri[1], bc, ab});
      finer.push_back({tri[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    f = std::move(finer);
  }
  TriangleMesh m;
  for (const Vec3d& p : v) m.vertices.push_back((radius * p).cast<float>());
  m.triangles = std::move(f);
  return m;
}

}  // namespace bodyscan::testing
