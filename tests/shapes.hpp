// Simple closed shapes with known measurements, for the measurement tests.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::testing {

// A closed prism: the polygon (x, z), star-shaped about `centre`, from y0 to y1,
// side walls in `rings` layers, caps fanned from the centre.
inline TriangleMesh prism(const std::vector<Eigen::Vector2d>& poly, Eigen::Vector2d centre, double y0, double y1,
                          int rings = 8) {
  TriangleMesh m;
  const auto n = static_cast<uint32_t>(poly.size());
  for (int r = 0; r <= rings; ++r) {
    const double y = y0 + (y1 - y0) * r / rings;
    for (const Eigen::Vector2d& p : poly)
      m.vertices.emplace_back(static_cast<float>(p.x()), static_cast<float>(y), static_cast<float>(p.y()));
  }
  for (uint32_t r = 0; r < static_cast<uint32_t>(rings); ++r)
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t a = r * n + i, b = r * n + (i + 1) % n, c = a + n, d = b + n;
      m.triangles.push_back({a, c, b});
      m.triangles.push_back({b, c, d});
    }
  const auto bottom = static_cast<uint32_t>(m.vertices.size());
  m.vertices.emplace_back(static_cast<float>(centre.x()), static_cast<float>(y0), static_cast<float>(centre.y()));
  m.vertices.emplace_back(static_cast<float>(centre.x()), static_cast<float>(y1), static_cast<float>(centre.y()));
  const uint32_t top_ring = static_cast<uint32_t>(rings) * n;
  for (uint32_t i = 0; i < n; ++i) {
    m.triangles.push_back({bottom, i, (i + 1) % n});
    m.triangles.push_back({bottom + 1, top_ring + (i + 1) % n, top_ring + i});
  }
  return m;
}

inline std::vector<Eigen::Vector2d> circle(double r, Eigen::Vector2d c = {0, 0}, int n = 720) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i)
    p.push_back(c + r * Eigen::Vector2d(std::cos(2 * M_PI * i / n), -std::sin(2 * M_PI * i / n)));
  return p;
}

inline TriangleMesh merged(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh m = a;
  const auto off = static_cast<uint32_t>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (Triangle t : b.triangles) m.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  return m;
}

}  // namespace bodyscan::testing
