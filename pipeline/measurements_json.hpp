// The measurements document (docs/measurements.md): what `bodyscan measure` prints
// and the scan job writes as measurements.json, one schema for both.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "recon/measure/body_measurements.hpp"
#include "recon/measure/girth.hpp"
#include "recon/measure/surface_path.hpp"

namespace bodyscan::pipeline {

inline constexpr const char* kMeasurementsSchema = "bodyscan.measurements/1";
inline constexpr const char* kGirthAlgorithm = "girth/convex-hull-1";
inline constexpr const char* kSurfaceAlgorithm = "surface/geodesic-funnel-2";

// Positions (mm) rounded to the micrometre.
nlohmann::json point_json(const Eigen::Vector3d& p);
nlohmann::json polyline_json(const std::vector<Eigen::Vector3d>& points);
nlohmann::json plane_json(const Plane& plane);

// What filled-in skin does to a value (recon/measure/fill_bound.hpp):
// "min_confidence", "crosses_filled_hole", "fill_bound_mm" (how far the fill
// could move it; null where not known) and "estimated" (by more than
// kEstimateThresholdMm, or by an amount not known).
void add_fill_fields(float min_confidence, const std::optional<double>& fill_bound_mm, nlohmann::json* j);

// A document with no measurements yet: schema, file, kind ("mesh" or "points").
nlohmann::json measurements_document(const std::string& file, const std::string& kind);

// One automatic measurement, and the whole automatic set (landmarks, measurements,
// skipped) added to a document.
nlohmann::json to_json(const BodyMeasurement& m);
void add_body_measurements(const BodyMeasurements& body, nlohmann::json* document);

// How the body stood (arms, feet, head, turn, place) and each part checked
// against the scanning posture; "ok" when every part is inside it.
nlohmann::json to_json(const BodyPosture& posture, const std::vector<PostureCheck>& checks);

// A surface length between two points.
nlohmann::json to_json(const SurfacePath& p, const std::string& name);

}  // namespace bodyscan::pipeline
