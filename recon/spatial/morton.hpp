// Z-order (Morton) sorting: points near in space end up near in memory, so the
// neighbour queries, normal fits and field splatting that walk the cloud in order
// stay in cache: a cloud in sampling (scan) order scatters its neighbours
// across memory.
#pragma once

#include <cstdint>
#include <vector>

#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

// Interleaves the low 21 bits of x, y, z (x lowest).
uint64_t morton_code(uint32_t x, uint32_t y, uint32_t z);

// The permutation that sorts the points by the Morton code of their position in
// the bounding box quantised to 2^21 steps per axis; ties keep input order.
std::vector<uint32_t> morton_order(const std::vector<Vec3f>& points);

}  // namespace bodyscan
