#include "pipeline/acquire.hpp"

#include <algorithm>

namespace bodyscan::pipeline {

const char* to_string(ShotKind k) {
  switch (k) {
    case ShotKind::kDotGrid: return "dot_grid";
    case ShotKind::kRoom: return "room";
    case ShotKind::kLightsOff: return "lights_off";
    case ShotKind::kFrameLights: return "frame_lights";
    case ShotKind::kFrontLights: return "front_lights";
    case ShotKind::kLaserBase: return "laser_base";
    case ShotKind::kLaserIdentify: return "laser_identify";
    case ShotKind::kScanStep: return "scan_step";
  }
  return "?";
}

std::vector<int> group_lasers(const hw::RigDescription& rig, size_t group) {
  std::vector<int> ids;
  for (const std::string& id : rig.laser_groups.at(group))
    for (size_t i = 0; i < rig.lasers.size(); ++i)
      if (rig.lasers[i].id == id) ids.push_back(static_cast<int>(i));
  return ids;
}

int group_steps(const hw::RigDescription& rig, size_t group) {
  int steps = 0;
  for (int i : group_lasers(rig, group)) {
    const hw::LaserDescription& l = rig.lasers[static_cast<size_t>(i)];
    steps = std::max(steps, l.max_step - l.min_step + 1);
  }
  return steps;
}

namespace {

// Grabs camera c (or every camera) and hands the frames on.
Status grab(const Rig& rig, size_t c, Shot proto, const ShotSink& sink) {
  ASSIGN_OR_RETURN(hw::Frame frame, rig.cameras[c]->grab());
  proto.camera = c;
  proto.frame = std::move(frame);
  return sink(std::move(proto));
}

Status grab_all(const Rig& rig, const Shot& proto, const ShotSink& sink) {
  for (size_t c = 0; c < rig.cameras.size(); ++c) RETURN_IF_ERROR(grab(rig, c, proto, sink));
  return {};
}

Shot shot(ShotKind kind, int group = -1, int step_index = -1, std::vector<LaserState> lasers = {}) {
  Shot s;
  s.kind = kind;
  s.group = group;
  s.step_index = step_index;
  s.lasers = std::move(lasers);
  return s;
}

Status calibration_sequence(const Rig& rig, const ShotSink& sink, const ProgressFn& progress) {
  hw::Controller& ctl = *rig.controller;
  const hw::RigDescription& desc = *rig.description;
  RETURN_IF_ERROR(ctl.all_lasers_off());
  RETURN_IF_ERROR(ctl.set_frame_lights(false));
  RETURN_IF_ERROR(ctl.set_room_lights(true));
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    if (!report(progress, "calibration: lens", static_cast<double>(c) / rig.cameras.size())) {
      return cancelled("calibration cancelled");
    }
    if (!rig.hold_dot_grid) return failed_precondition("no way to hold the dot grid before the cameras");
    const bool person = rig.person_holds_dot_grid && rig.person_holds_dot_grid(c);
    // A simulated board leaves the view whatever happens; a person is not asked
    // to take it away from a sequence that failed.
    auto fail = [&](Status st) {
      if (!person) (void)rig.hold_dot_grid(c, false, {});
      return st;
    };
    std::string why;
    for (;;) {
      if (Status st = rig.hold_dot_grid(c, true, why); !st.ok()) return fail(st);
      StatusOr<hw::Frame> frame = rig.cameras[c]->grab();
      if (!frame.ok()) return fail(frame.status());
      Shot s = shot(ShotKind::kDotGrid);
      s.camera = c;
      s.frame = std::move(*frame);
      const Status used = sink(std::move(s));
      if (used.ok()) break;
      if (!person || used.code() != StatusCode::kFailedPrecondition) return fail(used);
      why = used.message();
      if (!report(progress, "calibration: lens", static_cast<double>(c) / rig.cameras.size())) {
        return cancelled("calibration cancelled");
      }
    }
    RETURN_IF_ERROR(rig.hold_dot_grid(c, false, {}));
  }
  RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kRoom), sink));
  if (!report(progress, "calibration: frame lights", 0)) return cancelled("calibration cancelled");
  RETURN_IF_ERROR(ctl.set_room_lights(false));
  RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kLightsOff), sink));
  RETURN_IF_ERROR(ctl.set_frame_light_circuits(true, true));
  RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kFrameLights), sink));
  RETURN_IF_ERROR(ctl.set_frame_light_circuits(true, false));
  RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kFrontLights), sink));
  RETURN_IF_ERROR(ctl.set_frame_lights(false));
  // Which camera sees which laser on the frame's poles.
  for (size_t i = 0; i < desc.lasers.size(); ++i) {
    if (!report(progress, "calibration: lasers", static_cast<double>(i) / desc.lasers.size())) {
      return cancelled("calibration cancelled");
    }
    const int l = static_cast<int>(i);
    RETURN_IF_ERROR(ctl.home(l));
    RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kLaserBase), sink));
    const int home = std::clamp(0, desc.lasers[i].min_step, desc.lasers[i].max_step);
    for (int step : {desc.lasers[i].min_step, home, desc.lasers[i].max_step}) {
      RETURN_IF_ERROR(ctl.move_to(l, step));
      RETURN_IF_ERROR(ctl.set_laser(l, true));
      RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kLaserIdentify, -1, -1, {{l, step}}), sink));
      RETURN_IF_ERROR(ctl.set_laser(l, false));
    }
  }
  return {};
}

Status scan_sequence(const Rig& rig, const ShotSink& sink, int every, const ProgressFn& progress,
                     const std::vector<bool>& reversed) {
  hw::Controller& ctl = *rig.controller;
  const hw::RigDescription& desc = *rig.description;
  RETURN_IF_ERROR(ctl.set_room_lights(false));
  RETURN_IF_ERROR(ctl.set_frame_lights(false));
  size_t total = 0, done = 0;
  for (size_t g = 0; g < desc.laser_groups.size(); ++g)
    total += static_cast<size_t>((group_steps(desc, g) + every - 1) / every);
  for (size_t g = 0; g < desc.laser_groups.size(); ++g) {
    const std::vector<int> ids = group_lasers(desc, g);
    for (int i : ids) RETURN_IF_ERROR(ctl.home(i));
    RETURN_IF_ERROR(ctl.all_lasers_off());
    RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kLaserBase, static_cast<int>(g)), sink));
    const int steps = group_steps(desc, g);
    for (int k = 0; k < steps; k += every) {
      std::vector<LaserState> on;
      for (int i : ids) {
        const hw::LaserDescription& l = desc.lasers[static_cast<size_t>(i)];
        const bool back = static_cast<size_t>(i) < reversed.size() && reversed[static_cast<size_t>(i)];
        const int step = back ? std::max(l.min_step, l.max_step - k) : std::min(l.max_step, l.min_step + k);
        RETURN_IF_ERROR(ctl.move_to(i, step));
        RETURN_IF_ERROR(ctl.set_laser(i, true));
        on.push_back({i, step});
      }
      RETURN_IF_ERROR(grab_all(rig, shot(ShotKind::kScanStep, static_cast<int>(g), k, on), sink));
      if (!report(progress, "scan", static_cast<double>(++done) / total)) return cancelled("scan cancelled");
    }
    RETURN_IF_ERROR(ctl.all_lasers_off());
  }
  return {};
}

}  // namespace

Status acquire_calibration(const Rig& rig, const ShotSink& sink, const ProgressFn& progress) {
  hw::LasersOff off(*rig.controller);
  return calibration_sequence(rig, sink, progress);
}

Status acquire_scan(const Rig& rig, const ShotSink& sink, int every, const ProgressFn& progress,
                    const std::vector<bool>& reversed) {
  if (every < 1) return invalid_argument("scan: every must be at least 1");
  hw::LasersOff off(*rig.controller);
  return scan_sequence(rig, sink, every, progress, reversed);
}

}  // namespace bodyscan::pipeline
