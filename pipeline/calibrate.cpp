#include "pipeline/calibrate.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstring>

namespace bodyscan::pipeline {

ReferenceFrame reference_frame(const hw::FrameGeometry& f) {
  ReferenceFrame r;
  r.width = f.width;
  r.depth = f.depth;
  r.top_height = f.top_height;
  r.tube = f.tube;
  r.light_x = {f.light_x.at(0), f.light_x.at(1)};
  return r;
}

namespace {

// How far apart two planes are where a subject stands: the distance from the
// frame's centre, dropped onto plane a, to plane b.
double separation(const LaserPlane& a, const LaserPlane& b, const ReferenceFrame& f) {
  const Eigen::Vector3d centre(0, 0.5 * f.top_height, 0);
  const Eigen::Vector3d on_a = centre - (a.normal.dot(centre) - a.offset) * a.normal;
  return std::abs(b.normal.dot(on_a) - b.offset);
}

// Chooses each group's sweep directions: the first laser forward, the others each
// way, keeping the assignment whose planes come closest least (at the sweeps' ends).
void plan_sweeps(RigCalibration& cal, const hw::RigDescription& rig) {
  cal.sweep_reversed.assign(rig.lasers.size(), false);
  auto plane_at = [&](int laser, int step) -> const LaserPlane* {
    for (const LaserSighting& s : cal.sightings)
      if (s.laser == laser && s.step == step) return &s.plane;
    return nullptr;
  };
  for (size_t g = 0; g < rig.laser_groups.size(); ++g) {
    const std::vector<int> ids = group_lasers(rig, g);
    double best = -1;
    unsigned best_mask = 0;
    const unsigned options = ids.size() > 1 ? 1u << (ids.size() - 1) : 1u;
    for (unsigned mask = 0; mask < options; ++mask) {
      double closest = 1e30;
      for (int end = 0; end < 2; ++end) {
        std::vector<const LaserPlane*> planes;
        for (size_t k = 0; k < ids.size(); ++k) {
          const hw::LaserDescription& l = rig.lasers[static_cast<size_t>(ids[k])];
          const bool back = k > 0 && (mask >> (k - 1)) & 1u;
          planes.push_back(plane_at(ids[k], (end == 0) != back ? l.min_step : l.max_step));
        }
        for (size_t a = 0; a < planes.size(); ++a)
          for (size_t b = a + 1; b < planes.size(); ++b)
            if (planes[a] && planes[b]) closest = std::min(closest, separation(*planes[a], *planes[b], cal.frame));
      }
      if (closest > best) best = closest, best_mask = mask;
    }
    for (size_t k = 1; k < ids.size(); ++k)
      cal.sweep_reversed[static_cast<size_t>(ids[k])] = (best_mask >> (k - 1)) & 1u;
    cal.group_separation_mm.push_back(best >= 1e30 ? 0 : best);
  }
}

// The lens correction from camera `id`'s picture of the dot grid, or why that
// picture cannot give one (failed_precondition: a person can hold the board again).
StatusOr<LensCorrection> lens_from_dot_grid(const std::string& id, const hw::Frame& frame, const LensOptions& options) {
  if (frame.pixels.empty()) return failed_precondition("camera '" + id + "': the dot-grid frame is empty");
  // A black picture (a capped lens, a dead light) would only find noise.
  std::vector<uint16_t> sorted(frame.pixels);
  const size_t p99 = sorted.size() * 99 / 100;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(p99), sorted.end());
  if (sorted[p99] < frame.max_value() / 10) {
    return failed_precondition("camera '" + id + "': the dot-grid image is black (99 % of its pixels at or below " +
                               std::to_string(sorted[p99]) + " of " + std::to_string(frame.max_value()) +
                               "): is the lens capped, the exposure too short, or the room light off?");
  }
  auto lens = calibrate_lens(view(frame), options);
  if (!lens.ok()) {
    // Whatever the fit found wrong, the remedy is another picture of the board.
    std::string why = lens.status().message();
    for (const char* prefix : {"lens calibration: ", "lens correction: "})
      if (why.rfind(prefix, 0) == 0) why.erase(0, std::strlen(prefix));
    return failed_precondition("camera '" + id + "': lens calibration from the dot grid: " + why);
  }
  return lens;
}

}  // namespace

CalibrationBuilder::CalibrationBuilder(const hw::RigDescription& rig, const CalibrateOptions& options)
    : rig_(rig), options_(options), cameras_(rig.cameras.size()) {}

Status CalibrationBuilder::consume(Shot&& shot) {
  if (shot.camera >= cameras_.size()) return invalid_argument("calibration: a frame from an unknown camera");
  PerCamera& c = cameras_[shot.camera];
  switch (shot.kind) {
    case ShotKind::kDotGrid: {
      const auto t0 = std::chrono::steady_clock::now();
      StatusOr<LensCorrection> lens = lens_from_dot_grid(rig_.cameras[shot.camera].id, shot.frame, options_.lens);
      lens_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      RETURN_IF_ERROR(lens.status());
      c.lens = std::move(*lens);
      break;
    }
    case ShotKind::kLightsOff: c.lights_off = std::move(shot.frame); break;
    case ShotKind::kFrameLights: c.frame_lights = std::move(shot.frame); break;
    case ShotKind::kFrontLights: c.front_lights = std::move(shot.frame); break;
    case ShotKind::kLaserBase: c.laser_base = std::make_shared<const hw::Frame>(std::move(shot.frame)); break;
    case ShotKind::kLaserIdentify:
      if (shot.lasers.size() != 1 || !c.laser_base) {
        return invalid_argument("calibration: a laser frame without its base frame");
      }
      c.identify.push_back({shot.lasers[0].laser, shot.lasers[0].step, c.laser_base, std::move(shot.frame)});
      break;
    default: break;  // room views are for people
  }
  return {};
}

StatusOr<RigCalibration> CalibrationBuilder::finish() {
  const auto t0 = std::chrono::steady_clock::now();
  RigCalibration out;
  out.rig_name = rig_.name;
  out.frame = reference_frame(rig_.frame);
  for (const hw::LaserDescription& l : rig_.lasers) out.laser_ids.push_back(l.id);
  for (size_t i = 0; i < cameras_.size(); ++i) {
    const PerCamera& c = cameras_[i];
    const std::string& id = rig_.cameras[i].id;
    for (const hw::Frame* f : {&c.lights_off, &c.frame_lights, &c.front_lights}) {
      if (f->pixels.empty()) return failed_precondition("camera '" + id + "': a calibration frame is missing");
    }
    if (!c.lens) return failed_precondition("camera '" + id + "': the dot-grid frame is missing");
    ASSIGN_OR_RETURN(CameraCalibration cal,
                     calibrate_camera(id, *c.lens, {view(c.lights_off), view(c.frame_lights), view(c.front_lights)},
                                      out.frame, options_.markers));
    out.cameras.push_back(std::move(cal));
  }
  out.lasers_seen.assign(cameras_.size(), {});
  for (size_t i = 0; i < cameras_.size(); ++i) {
    const LaserPlaneFinder finder(out.cameras[i], options_.laser_plane);
    for (const Identify& id : cameras_[i].identify) {
      auto plane = finder.find(view(id.frame), view(*id.base));
      if (!plane.ok()) continue;  // this camera does not see that laser on the poles
      if (std::find(out.lasers_seen[i].begin(), out.lasers_seen[i].end(), id.laser) == out.lasers_seen[i].end()) {
        out.lasers_seen[i].push_back(id.laser);
      }
      out.sightings.push_back({id.laser, id.step, i, std::move(*plane)});
    }
  }
  for (size_t l = 0; l < rig_.lasers.size(); ++l) {
    bool seen = false;
    for (const auto& s : out.sightings) seen = seen || s.laser == static_cast<int>(l);
    if (!seen) {
      return failed_precondition("laser '" + rig_.lasers[l].id +
                                 "': no camera sees its stripe cross the frame's poles - is it off, blocked, or "
                                 "aimed past the frame?");
    }
  }
  // Lasers that run together must be told apart by which camera sees them.
  for (size_t g = 0; g < rig_.laser_groups.size(); ++g) {
    const std::vector<int> group = group_lasers(rig_, g);
    for (size_t i = 0; i < cameras_.size(); ++i) {
      std::vector<std::string> both;
      for (int l : out.lasers_seen[i])
        if (std::find(group.begin(), group.end(), l) != group.end())
          both.push_back(rig_.lasers[static_cast<size_t>(l)].id);
      if (both.size() > 1) {
        return failed_precondition("camera '" + rig_.cameras[i].id + "' sees lasers '" + both[0] + "' and '" + both[1] +
                                   "' on the frame's poles, but they run together: put them in different "
                                   "laser groups");
      }
    }
  }
  plan_sweeps(out, rig_);
  out.processing_seconds = lens_seconds_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

StatusOr<RigCalibration> calibrate_rig(const Rig& rig, const CalibrateOptions& options, const ProgressFn& progress) {
  CalibrationBuilder builder(*rig.description, options);
  RETURN_IF_ERROR(acquire_calibration(
      rig, [&](Shot&& s) { return builder.consume(std::move(s)); }, progress));
  return builder.finish();
}

nlohmann::json to_json(const RigCalibration& cal) {
  nlohmann::json j;
  j["rig"] = cal.rig_name;
  j["cameras"] = nlohmann::json::array();
  for (size_t i = 0; i < cal.cameras.size(); ++i) {
    const CameraCalibration& c = cal.cameras[i];
    nlohmann::json lasers = nlohmann::json::array();
    for (int l : cal.lasers_seen[i]) lasers.push_back(cal.laser_ids[static_cast<size_t>(l)]);
    j["cameras"].push_back({{"id", c.camera_id},
                            {"side", to_string(c.side)},
                            {"centre_mm", {c.centre.x(), c.centre.y(), c.centre.z()}},
                            {"ray_spread_mm", c.ray_spread_mm},
                            {"lens",
                             {{"dots_found", c.lens.dots_found()},
                              {"dots_used", c.lens.dots_used()},
                              {"fit_rms_px", c.lens.fit_rms_px()},
                              {"held_out_rms_px", c.lens.held_out_rms_px()}}},
                            {"lasers_seen", lasers}});
  }
  j["lasers"] = nlohmann::json::array();
  for (const LaserSighting& s : cal.sightings) {
    j["lasers"].push_back({{"id", cal.laser_ids[static_cast<size_t>(s.laser)]},
                           {"camera", cal.cameras[s.camera].camera_id},
                           {"step", s.step},
                           {"normal", {s.plane.normal.x(), s.plane.normal.y(), s.plane.normal.z()}},
                           {"offset_mm", s.plane.offset},
                           {"fourth_point_mm", s.plane.fourth_point_mm}});
  }
  j["sweep_reversed"] = nlohmann::json::array();
  for (size_t l = 0; l < cal.sweep_reversed.size(); ++l)
    if (cal.sweep_reversed[l]) j["sweep_reversed"].push_back(cal.laser_ids[l]);
  j["group_separation_mm"] = cal.group_separation_mm;
  j["processing_seconds"] = cal.processing_seconds;
  return j;
}

}  // namespace bodyscan::pipeline
