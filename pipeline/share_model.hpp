// The model a customer's share link shows: the scan's surface without the head
// unless staff chose to include it. A body scan with a face is recognisable;
// the link shows the body, so the server never sends what it does not need.
#pragma once

#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::pipeline {

// The height (mm, Y) above which the head and neck are cut away: the lowest
// point of the scan's neck girth (the narrowest tape round the neck, square to
// its axis, so the cut passes under the chin and the back of the skull).
// not_found when the scan has no neck girth: then no model without the head can
// be made, and none is served.
StatusOr<double> head_cut_height(const std::vector<storage::MeasurementRecord>& measurements);

// The triangles wholly at or below `cut_y`, with only the vertices they use
// (normals and confidence kept with their vertices).
TriangleMesh below_height(const TriangleMesh& mesh, double cut_y);

}  // namespace bodyscan::pipeline
