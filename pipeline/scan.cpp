#include "pipeline/scan.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace bodyscan::pipeline {

const char* to_string(PlaneSource s) { return s == PlaneSource::kSweepFit ? "sweep fit" : "per frame"; }

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

ScanProcessor::ScanProcessor(const RigCalibration& calibration, const ScanOptions& options)
    : cal_(calibration), options_(options) {
  finders_.reserve(cal_.cameras.size());
  for (const CameraCalibration& c : cal_.cameras) finders_.emplace_back(c, options_.laser_plane);
}

Status ScanProcessor::consume(Shot&& shot) {
  const auto t0 = std::chrono::steady_clock::now();
  if (shot.camera >= cal_.cameras.size()) return invalid_argument("scan: a frame from an unknown camera");
  if (shot.group < 0) return {};
  const size_t g = static_cast<size_t>(shot.group);
  if (base_.size() <= g) base_.resize(g + 1, std::vector<hw::Frame>(cal_.cameras.size()));
  if (shot.kind == ShotKind::kLaserBase) {
    base_[g][shot.camera] = std::move(shot.frame);
    return {};
  }
  if (shot.kind != ShotKind::kScanStep) return {};
  const hw::Frame& base = base_[g][shot.camera];
  if (base.pixels.empty()) return invalid_argument("scan: a step frame came before its group's base frame");
  if (shot.group != last_group_ || shot.step_index != last_step_) {
    ++frame_counter_;  // one frame number per step, shared by the cameras
    last_group_ = shot.group;
    last_step_ = shot.step_index;
  }
  ++stats_.frames;
  // The one laser of the step this camera sees on the poles (calibration made sure
  // it is at most one).
  const std::vector<int>& seen = cal_.lasers_seen[shot.camera];
  FrameRecord r;
  r.camera = shot.camera;
  r.laser = -1;
  for (const LaserState& l : shot.lasers) {
    if (std::find(seen.begin(), seen.end(), l.laser) != seen.end()) {
      r.laser = l.laser;
      r.step = l.step;
    } else {
      r.others.push_back(l);
    }
  }
  if (r.laser < 0) {
    ++stats_.frames_unseen;
    return {};
  }
  const ImageView f = view(shot.frame), b = view(base);
  r.frame = frame_counter_ - 1;
  r.full_scale = shot.frame.max_value();
  auto plane = finders_[shot.camera].find(f, b);
  if (!plane.ok()) {
    // Past the poles' reach (or a pole hidden): the sweep fit will give this step's
    // plane; keep every row's stripe until then.
    if (stats_.first_plane_error.empty()) stats_.first_plane_error = plane.status().message();
    ++stats_.frames_without_plane;
    ASSIGN_OR_RETURN(
        r.samples, extract_plane_stripe(cal_.cameras[shot.camera], nullptr, f, b, r.full_scale, options_.triangulate));
    stats_.samples += r.samples.size();
    records_.push_back(std::move(r));
    stats_.processing_seconds += seconds_since(t0);
    return {};
  }
  r.has_plane = true;
  if (plane->poles[static_cast<size_t>(Pole::kFarBottom)].estimated) ++stats_.far_bottom_estimated;
  if (plane->fourth_point_mm >= 0) {
    fourth_ss_ += plane->fourth_point_mm * plane->fourth_point_mm;
    ++fourth_n_;
    stats_.fourth_point_rms_mm = std::sqrt(fourth_ss_ / static_cast<double>(fourth_n_));
  }
  ASSIGN_OR_RETURN(r.samples,
                   extract_plane_stripe(cal_.cameras[shot.camera], &*plane, f, b, r.full_scale, options_.triangulate));
  r.plane = std::move(*plane);
  stats_.samples += r.samples.size();
  records_.push_back(std::move(r));
  stats_.processing_seconds += seconds_since(t0);
  return {};
}

StatusOr<PointCloud> ScanProcessor::finish() {
  const auto t0 = std::chrono::steady_clock::now();
  // Each laser's sweep, from the pole points every camera measured.
  std::map<int, LaserSweep> sweeps;
  std::map<int, std::vector<SweepPoint>> points;
  std::map<int, std::vector<std::pair<int, SweepPlane>>> planes;
  for (const FrameRecord& r : records_) {
    if (!r.has_plane) continue;
    for (const PoleStripe& p : r.plane.poles)
      if (p.found && p.used && !p.estimated) points[r.laser].push_back({r.step, p.world});
    planes[r.laser].push_back({r.step, {r.plane.normal, r.plane.offset}});
  }
  stats_.sweeps.clear();
  for (const auto& [laser, pts] : points) {
    LaserSweepReport report;
    report.laser = laser;
    auto fit = LaserSweep::fit(pts, planes[laser]);
    if (fit.ok()) {
      report.fitted = true;
      report.rms_mm = fit->rms_mm();
      report.points_used = fit->points_used();
      report.points_rejected = fit->points_rejected();
      report.degrees_per_step = fit->degrees_per_step();
      report.axis_point = fit->axis_point();
      report.axis_direction = fit->axis_direction();
      sweeps.emplace(laser, *fit);
    } else {
      report.error = fit.status().message();
    }
    stats_.sweeps.push_back(report);
  }
  const bool use_sweeps = options_.planes == PlaneSource::kSweepFit;

  // Triangulate the frames in parallel, each into its own cloud, then join in order.
  std::vector<PointCloud> parts(records_.size());
  std::vector<Status> errors(records_.size());
  tbb::parallel_for(size_t{0}, records_.size(), [&](size_t i) {
    const FrameRecord& r = records_[i];
    const CameraCalibration& cam = cal_.cameras[r.camera];
    LaserPlane plane = r.plane;
    const auto it = sweeps.find(r.laser);
    if (!r.has_plane && it == sweeps.end()) return;  // counted below
    if (it != sweeps.end() && (use_sweeps || !r.has_plane)) {
      const SweepPlane sp = it->second.plane(r.step);
      // The fitted plane replaces the frame's; its pole points follow from it.
      plane = LaserPlane{};
      errors[i] = complete_plane(cam, sp.normal, sp.offset, &plane);
      if (!errors[i].ok()) return;
    }
    std::vector<StripeSample> kept;
    const std::vector<StripeSample>* samples = &r.samples;
    if (!r.has_plane) {
      // Searched along whole rows: keep what lies where this plane meets the subject.
      const std::vector<ColumnRange> w =
          stripe_windows(cam, plane, scan_volume(cam.frame), options_.triangulate.window_pad_px);
      for (const StripeSample& s : r.samples) {
        const ColumnRange& c = w[static_cast<size_t>(s.row)];
        if (s.column >= c.begin && s.column < c.end) kept.push_back(s);
      }
      samples = &kept;
    }
    // Lone samples dropped and the rest smoothed along the stripe here, not when
    // extracted: the raw record keeps the samples as the camera gave them, and a
    // replay treats them as today's code does. A format-1 record holds them as the
    // code of its day left them.
    std::vector<StripeSample> smoothed;
    if (!samples_smoothed_ && (options_.triangulate.smooth_rows > 0 || options_.triangulate.min_run_rows > 1)) {
      smoothed = *samples;
      drop_short_runs(smoothed, options_.triangulate.min_run_rows);
      if (options_.triangulate.smooth_rows > 0) smooth_stripe(smoothed, options_.triangulate.smooth_rows);
      samples = &smoothed;
    }
    std::vector<SweepPlane> others;
    for (const LaserState& o : r.others) {
      const auto other = sweeps.find(o.laser);
      if (other != sweeps.end()) others.push_back(other->second.plane(o.step));
    }
    triangulate_samples(cam, plane, *samples, r.full_scale, {static_cast<int>(r.camera), r.laser, r.frame},
                        options_.triangulate, others, &parts[i]);
  });
  for (const Status& s : errors) RETURN_IF_ERROR(s);
  stats_.frames_dropped = 0;
  for (const FrameRecord& r : records_) stats_.frames_dropped += !r.has_plane && !sweeps.count(r.laser);
  PointCloud cloud;
  size_t total = 0;
  for (const PointCloud& p : parts) total += p.size();
  for (auto* v : {&cloud.positions}) v->reserve(total);
  for (PointCloud& p : parts) {
    cloud.positions.insert(cloud.positions.end(), p.positions.begin(), p.positions.end());
    cloud.intensity.insert(cloud.intensity.end(), p.intensity.begin(), p.intensity.end());
    cloud.confidence.insert(cloud.confidence.end(), p.confidence.begin(), p.confidence.end());
    cloud.camera.insert(cloud.camera.end(), p.camera.begin(), p.camera.end());
    cloud.laser.insert(cloud.laser.end(), p.laser.begin(), p.laser.end());
    cloud.frame.insert(cloud.frame.end(), p.frame.begin(), p.frame.end());
  }
  for (const CameraCalibration& c : cal_.cameras) cloud.camera_centres.push_back(c.centre.cast<float>());
  records_.clear();
  stats_.sway = {};
  stats_.sway_not_estimated.clear();
  if (options_.compensate_sway) {
    auto sway = estimate_sway(cloud, options_.sway);
    if (sway.ok()) {
      undo_sway(cloud, *sway);
      stats_.sway_not_estimated = sway->not_estimated;
      stats_.sway = std::move(*sway);
    } else {
      stats_.sway_not_estimated = sway.status().message();
    }
  }
  if (options_.view.max_view_deg < 90) stats_.points_grazing = weigh_by_view_angle(cloud, options_.view).dropped;
  if (options_.redundant_radius_mm > 0) {
    stats_.points_redundant =
        drop_redundant_points(cloud, options_.redundant_radius_mm, options_.redundant_ratio, options_.redundant_weak);
  }
  stats_.points = cloud.size();
  stats_.processing_seconds += seconds_since(t0);
  return cloud;
}

}  // namespace bodyscan::pipeline
