// A scan's raw record: what it takes to make the scan's point cloud again, later,
// with newer processing, without keeping the camera frames (gigabytes). Two parts:
//
// - the calibration as fitted (calibration_record): per camera the lens's grid dots
//   and options, its named markers and side, from which the lens correction, the
//   plane transforms and the centre are rebuilt exactly; the laser sightings;
// - every step frame's stripe samples and laser plane (ScanProcessor::recording),
//   zlib-compressed binary.
//
// docs/archive.md describes both. A recording replayed through a ScanProcessor
// gives the same cloud, point for point, as the scan that made it.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>

#include "core/status.hpp"
#include "pipeline/calibrate.hpp"

namespace bodyscan::pipeline {

inline constexpr const char* kCalibrationRecordSchema = "bodyscan.calibration-record/1";

nlohmann::json calibration_record(const RigCalibration& cal);
StatusOr<RigCalibration> calibration_from_record(const nlohmann::json& record);

}  // namespace bodyscan::pipeline
