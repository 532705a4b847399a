#include "tests/support/skin_noise.hpp"

#include <cmath>

namespace bodyscan {

namespace {

// A standard normal deviate for one lattice node.
double node_value(uint64_t seed, int64_t i, int64_t j, int64_t k) {
  uint64_t h = seed * 0x9E3779B97F4A7C15ull ^ (static_cast<uint64_t>(i) * 0xBF58476D1CE4E5B9ull) ^
               (static_cast<uint64_t>(j) * 0x94D049BB133111EBull) ^ (static_cast<uint64_t>(k) * 0x2545F4914F6CDD1Dull);
  h ^= h >> 31, h *= 0xD6E8FEB86659FD93ull, h ^= h >> 32;
  // Two uniforms from the hash's bits, one normal deviate (Box-Muller).
  const double u1 = (static_cast<double>(h >> 11) + 0.5) / 9007199254740992.0;
  const double u2 = static_cast<double>(h & 0x7FF) / 2048.0;
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
}

}  // namespace

double smooth_noise(const Vec3f& p, double spacing, uint64_t seed) {
  int64_t base[3];
  double w[3];
  for (int a = 0; a < 3; ++a) {
    const double c = p[a] / spacing;
    base[a] = static_cast<int64_t>(std::floor(c));
    const double t = c - static_cast<double>(base[a]);
    w[a] = t * t * (3 - 2 * t);
  }
  double v = 0;
  for (int dx = 0; dx < 2; ++dx)
    for (int dy = 0; dy < 2; ++dy)
      for (int dz = 0; dz < 2; ++dz)
        v += (dx ? w[0] : 1 - w[0]) * (dy ? w[1] : 1 - w[1]) * (dz ? w[2] : 1 - w[2]) *
             node_value(seed, base[0] + dx, base[1] + dy, base[2] + dz);
  return v;
}

TriangleMesh with_smooth_skin_noise(const TriangleMesh& mesh, double rms_mm, uint64_t seed,
                                    const std::vector<double>& spacings_mm) {
  const std::vector<Vec3f> normals = compute_vertex_normals(mesh);
  TriangleMesh noisy = mesh;
  std::vector<double> field(mesh.vertices.size());
  for (size_t o = 0; o < spacings_mm.size(); ++o) {
    double ss = 0;
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      field[i] = smooth_noise(mesh.vertices[i], spacings_mm[o], seed * spacings_mm.size() + o);
      ss += field[i] * field[i];
    }
    if (ss <= 0) continue;
    const double scale = rms_mm / std::sqrt(ss / static_cast<double>(field.size()));
    for (size_t i = 0; i < noisy.vertices.size(); ++i)
      noisy.vertices[i] += static_cast<float>(scale * field[i]) * normals[i];
  }
  return noisy;
}

}  // namespace bodyscan
