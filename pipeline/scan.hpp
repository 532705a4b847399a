// Scan frames to one world point cloud (thesis §3.1.3-3.1.4). As the frames come,
// each camera's step frame gives the laser plane from the stripe on the frame's
// poles and the stripe's samples where that plane can meet the subject. When the
// scan is over, each laser's sweep is fitted to all its pole points (LaserSweep),
// and every sample is taken to its step's plane. Every camera's points land in the
// frame's world directly; there is no registration between cameras. The subject's
// sway between sweeps is estimated from the cloud and undone (subject_sway.hpp).
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/calibrate.hpp"
#include "recon/geometry/point_cloud.hpp"
#include "recon/scan/laser_sweep.hpp"
#include "recon/scan/redundancy.hpp"
#include "recon/scan/subject_sway.hpp"
#include "recon/scan/triangulate.hpp"
#include "recon/scan/view_angle.hpp"

namespace bodyscan::pipeline {

// Where each frame's laser plane comes from.
enum class PlaneSource {
  kSweepFit,  // the laser's whole sweep fitted to every pole point (default)
  kPerFrame,  // the frame's own three or four pole points (thesis §3.1.3)
};
const char* to_string(PlaneSource s);

struct ScanOptions {
  TriangulateOptions triangulate;
  LaserPlaneOptions laser_plane;
  PlaneSource planes = PlaneSource::kSweepFit;
  // drop_redundant_points: radius (mm; 0: keep every point) and confidence ratio.
  float redundant_radius_mm = 4.f;
  float redundant_ratio = 2.f;
  float redundant_weak = 0.4f;
  // Grazing views (weigh_by_view_angle), before the redundancy rule. Off by default
  // (max_view_deg >= 90 keeps every point and its confidence): on the shipped rigs
  // the grazing points are the only ones on the flanks, and dropping them costs the
  // thesis rig its coverage must (docs/scan-processing.md, "Grazing views").
  ViewAngleOptions view = {.max_view_deg = 90};
  // The subject's sway between sweeps, estimated from the cloud and undone before
  // the redundancy rule (subject_sway.hpp).
  bool compensate_sway = true;
  SwayOptions sway;
};

struct LaserSweepReport {
  int laser = 0;
  bool fitted = false;  // else the per-frame planes were used
  std::string error;    // why not
  double rms_mm = 0;    // pole points to their step's fitted plane
  size_t points_used = 0, points_rejected = 0;
  double degrees_per_step = 0;
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero(), axis_direction = Eigen::Vector3d::Zero();
};

struct ScanStats {
  size_t frames = 0;                // step frames (per camera)
  size_t frames_unseen = 0;         // the camera sees none of the step's lasers
  size_t frames_without_plane = 0;  // the stripe missed too many poles: the sweep fit gives the plane
  size_t frames_dropped = 0;        // ... and there was no sweep fit either: no points
  size_t far_bottom_estimated = 0;  // frames whose far bottom pole point was hidden
  double fourth_point_rms_mm = 0;   // over frames with all four pole points measured
  size_t samples = 0;               // stripe samples kept for triangulation
  size_t points = 0;
  size_t points_redundant = 0;  // dropped for a better point nearby
  size_t points_grazing = 0;    // dropped for a grazing view (ScanOptions::view)
  std::vector<LaserSweepReport> sweeps;
  SwayEstimate sway;               // empty when not compensated
  std::string sway_not_estimated;  // why there is no sway estimate (the cloud is kept as measured)
  double processing_seconds = 0;   // frames to points, acquisition excluded
  std::string first_plane_error;   // the first frame without a plane, for the log
};

class ScanProcessor {
 public:
  explicit ScanProcessor(const RigCalibration& calibration, const ScanOptions& options = {});
  Status consume(Shot&& shot);  // a ShotSink
  // Fits the sweeps and triangulates: the cloud (positions, intensity, confidence,
  // camera, laser, frame, camera centres). Call once, after the scan.
  StatusOr<PointCloud> finish();
  const ScanStats& stats() const { return stats_; }
  const ScanOptions& options() const { return options_; }

  // The frames' stripe samples and planes, compressed (scan_recording.hpp): call
  // before finish(). load_recording() puts a recording in place of consumed frames,
  // so that finish() makes the same cloud again; with another ScanOptions, a new one.
  std::string recording() const;
  Status load_recording(std::string_view bytes);

 private:
  struct FrameRecord {
    size_t camera = 0;
    int laser = 0, step = 0, frame = 0;
    int full_scale = 255;
    bool has_plane = false;             // the stripe crossed enough poles
    LaserPlane plane;                   // from this frame's poles
    std::vector<LaserState> others;     // the other lasers lit
    std::vector<StripeSample> samples;  // as extracted (smoothed when triangulated)
  };
  const RigCalibration& cal_;
  ScanOptions options_;
  std::vector<LaserPlaneFinder> finders_;
  std::vector<std::vector<hw::Frame>> base_;  // per group, per camera
  std::vector<FrameRecord> records_;
  bool samples_smoothed_ = false;  // loaded from a format-1 record: already smoothed
  ScanStats stats_;
  double fourth_ss_ = 0;
  size_t fourth_n_ = 0;
  int frame_counter_ = 0, last_group_ = -1, last_step_ = -1;
};

}  // namespace bodyscan::pipeline
