// Calibrating a rig from what its cameras see (thesis §3.1.1-3.1.2), given only
// the reference frames' measured geometry: each camera's lens, side, markers and
// plane transforms, and which laser each camera sees on the frame's poles.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "pipeline/acquire.hpp"
#include "recon/calib/camera_calibration.hpp"
#include "recon/scan/laser_plane.hpp"

namespace bodyscan::pipeline {

ReferenceFrame reference_frame(const hw::FrameGeometry& frame);

struct LaserSighting {
  int laser = 0, step = 0;
  size_t camera = 0;
  LaserPlane plane;  // at that step
};

struct RigCalibration {
  std::string rig_name;
  ReferenceFrame frame;
  std::vector<CameraCalibration> cameras;
  // Per camera, the lasers (description indices) whose stripe it sees on the poles.
  std::vector<std::vector<int>> lasers_seen;
  std::vector<LaserSighting> sightings;
  std::vector<std::string> laser_ids;
  // Per laser: sweep it from its last step to its first. Chosen so that the lasers
  // of a group stay as far apart as they can (measured: their planes at both ends of
  // their sweeps), which keeps each camera's stripe search clear of the others'.
  std::vector<bool> sweep_reversed;
  std::vector<double> group_separation_mm;  // per group, the closest the planes come at the sweep ends
  double processing_seconds = 0;            // from frames to calibration, acquisition excluded
};

struct CalibrateOptions {
  MarkerOptions markers;
  LaserPlaneOptions laser_plane;
  LensOptions lens;
};

// The calibration frames (acquire_calibration) to a calibration. Errors name the
// camera or laser and what went wrong: a black dot-grid image, a frame light that
// stayed off, a laser no camera sees on the poles.
//
// A dot-grid picture is turned into its lens correction as it comes: consume()
// rejects one that cannot be used (failed_precondition, saying why), so that the
// person holding the board can be asked again at once (acquire.hpp).
class CalibrationBuilder {
 public:
  explicit CalibrationBuilder(const hw::RigDescription& rig, const CalibrateOptions& options = {});
  Status consume(Shot&& shot);  // a ShotSink
  StatusOr<RigCalibration> finish();

 private:
  const hw::RigDescription& rig_;
  CalibrateOptions options_;
  struct Identify {
    int laser = 0, step = 0;
    std::shared_ptr<const hw::Frame> base;
    hw::Frame frame;
  };
  double lens_seconds_ = 0;  // spent in consume() on the dot grids
  struct PerCamera {
    std::optional<LensCorrection> lens;  // from the dot grid
    hw::Frame lights_off, frame_lights, front_lights;
    std::shared_ptr<const hw::Frame> laser_base;
    std::vector<Identify> identify;
  };
  std::vector<PerCamera> cameras_;
};

// Runs the calibration sequence on a rig and processes it.
StatusOr<RigCalibration> calibrate_rig(const Rig& rig, const CalibrateOptions& options = {},
                                       const ProgressFn& progress = {});

// A summary for people and the archive: per camera its side, centre, lens and ray
// figures; per laser the cameras that see it.
nlohmann::json to_json(const RigCalibration& cal);

inline ImageView view(const hw::Frame& f) { return {f.pixels.data(), f.width, f.height}; }

}  // namespace bodyscan::pipeline
