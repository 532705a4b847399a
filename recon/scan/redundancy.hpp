// A scan sees much of the body several times: from two cameras, under two lasers,
// in neighbouring steps. Where it does, the better measurement should stand for the
// place and the worse one go: a point is dropped when another point within `radius`
// (from another frame or camera) has at least `ratio` times its confidence. A point
// nothing better is near keeps its place, so coverage stays; grazing and faint
// samples go where a clear one covers the same skin.
#pragma once

#include <cstddef>

#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

// Returns how many points were dropped. Needs confidence; frame and camera (when
// present) tell measurements apart. Every attribute is kept in step. A weak point
// (confidence below `weak`) goes for any more confident point nearby.
size_t drop_redundant_points(PointCloud& cloud, float radius, float ratio = 2.f, float weak = 0.f);

}  // namespace bodyscan
