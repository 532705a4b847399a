// Test fixture shared by the field and marching-cubes tests: kernels on a Fibonacci
// sphere with exact outward normals, so the field's zero set is known.
#pragma once

#include <vector>

#include "recon/geometry/sample_surface.hpp"
#include "recon/surface/implicit_field.hpp"

namespace bodyscan::testing {

// n kernels on a sphere of `radius` about `centre`; tangents from the exact normal.
inline std::vector<Kernel> sphere_kernels(size_t n, double radius, const Vec3f& centre, float sigma_t, float sigma_n,
                                          float bend) {
  const PointCloud c = fibonacci_sphere(n, radius);
  std::vector<Kernel> ks(n);
  for (size_t i = 0; i < n; ++i) {
    Kernel& k = ks[i];
    k.center = c.positions[i] + centre;
    k.n = c.normals[i];
    k.t1 = k.n.unitOrthogonal();
    k.t2 = k.n.cross(k.t1);
    k.sigma_t1 = k.sigma_t2 = sigma_t;
    k.sigma_n = sigma_n;
    k.bend1 = k.bend2 = bend;
  }
  return ks;
}

}  // namespace bodyscan::testing
