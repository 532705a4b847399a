// Synthetic point sets with known ground truth: samples of a mesh, evenly and unevenly
// spaced spheres, sensor-like noise. Tests and benchmarks feed these to the
// reconstruction and score the result against the surface they came from.
//
// Every random function is deterministic for its seed on every platform: it draws from
// std::mt19937_64 (whose output sequence the standard fixes) and converts the draws
// itself instead of using std::*_distribution, whose algorithms are left to the library.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recon/geometry/point_cloud.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

// n points distributed uniformly by area over the mesh: a triangle is drawn with
// probability proportional to its area, then a point uniformly inside it
// (Osada et al., "Shape distributions", ACM TOG 21(4), 2002, eq. 1). With
// `with_normals`, each point gets the unit normal of its triangle (outward for
// counter-clockwise winding), else normals stay empty. Units and frame are the mesh's.
//
// The mesh's indices must be in range. A mesh without area gives an empty cloud.
PointCloud sample_mesh_uniform(const TriangleMesh& mesh, size_t n, uint64_t seed, bool with_normals);

// n nearly evenly spaced points on a sphere of `radius` (mm) about the origin: the
// spherical Fibonacci lattice (González, "Measurement of areas on a sphere using
// Fibonacci and latitude-longitude lattices", Math. Geosci. 42, 2010), poles on ±Y.
// Normals are the exact outward unit normals. Deterministic, no seed.
PointCloud fibonacci_sphere(size_t n, double radius);

// Adds independent Gaussian noise of standard deviation `sigma` (mm) to each
// coordinate of every position (isotropic in 3-D). Normals and other attributes are
// left as they were: they still describe the noise-free surface.
void add_gaussian_noise(PointCloud& cloud, double sigma, uint64_t seed);

// n random points on a sphere of `radius` (mm) about the origin whose density (points
// per area) grows smoothly and exponentially with height, from the pole at -Y to
// `density_ratio` times that at the pole at +Y: density ∝ density_ratio^t with
// t = (y/radius + 1)/2. Because a sphere's area is uniform in y (Archimedes), y is drawn
// by the analytic inverse of that density's CDF and the longitude uniformly, so exactly
// n points come out and no draw is rejected. Normals are the exact outward unit normals.
//
// density_ratio must be > 0 (1 gives a uniform sphere, < 1 makes -Y the dense pole).
PointCloud nonuniform_sphere(size_t n, double radius, double density_ratio, uint64_t seed);

}  // namespace bodyscan
