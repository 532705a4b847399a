// A measurement the browser asks for, evaluated on a body's surface: the request
// is JSON in mm in the scan frame (what the user picked comes back as 3-D
// positions, never vertex indices), the answer the measurements schema's entry
// (docs/measurements.md) with the geometry to draw.
//
//   {"kind": "girth", "plane": {"point": [x,y,z], "normal": [x,y,z]}, "near": [x,y,z]?}
//   {"kind": "girth", "line": {"from": [..], "to": [..]}, "view": [x,y,z]}
//       a line drawn on screen and the view direction: the cutting plane holds
//       both; the girth goes round the loop nearest the line's midpoint (thesis §3.3)
//   {"kind": "arc", "plane" | "line"+"view", "from": [..], "to": [..]}
//       along the girth's tape between two points, the shorter way (fig. 3.43)
//   {"kind": "surface", "from": [..], "to": [..]}   over the skin (geodesic)
//   {"kind": "distance", "from": [..], "to": [..]}  straight
#pragma once

#include <nlohmann/json.hpp>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/plane_section.hpp"

namespace bodyscan::pipeline {

// The entry: "kind", "value_mm", "path" (a polyline, mm) and "closed", plus what
// the kind has ("plane", "tape", "loop", "from", "to", "min_confidence",
// "crosses_filled_hole", "algorithm"). Invalid argument for a malformed request
// (named field), or the measurement's own error (no section near the point ...).
StatusOr<nlohmann::json> evaluate_measurement(const TriangleMesh& mesh, const nlohmann::json& request);

// The request's cutting plane ("plane", or "line" with "view"), checked.
StatusOr<Plane> request_plane(const nlohmann::json& request);

}  // namespace bodyscan::pipeline
