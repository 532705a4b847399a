// A scan's surface errs smoothly: where the cloud sat a little off the skin the
// reconstruction's kernels spread it over centimetres, so two scans of one body
// differ by gentle swells, not vertex by vertex. This lays such an error on a true
// mesh, to see how far each measurement rule moves under it (measure_benchmark
// --noise-study, and the rules' tests).
#pragma once

#include <cstdint>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

// A smooth random field over space: value noise on a cubic
// lattice of `spacing` mm, standard normal values at the nodes (hashed from `seed`
// and the node), smoothstep interpolation between them. The same seed gives the
// same field.
double smooth_noise(const Vec3f& p, double spacing, uint64_t seed);

// The mesh with each vertex moved along its normal by the sum of one such field
// per spacing, each scaled to `rms_mm` RMS over the vertices.
TriangleMesh with_smooth_skin_noise(const TriangleMesh& mesh, double rms_mm, uint64_t seed,
                                    const std::vector<double>& spacings_mm = {40, 10});

}  // namespace bodyscan
