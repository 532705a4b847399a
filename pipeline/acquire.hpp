// The rig's two acquisition sequences - what the lights, lasers and cameras do
// during a calibration and during a scan - written once, for every backend and
// every consumer: the scan job processes the frames as they come, `bodyscan sim
// render` writes them to disk, the render benchmark times them.
//
// Each grabbed frame goes to a sink with what was on when it was taken. A sink
// error, a failed grab or a controller error stops the sequence with that error;
// every laser is off whenever a sequence returns, however it returns.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/status.hpp"
#include "hw/camera.hpp"
#include "hw/controller.hpp"
#include "hw/rig_description.hpp"

namespace bodyscan::pipeline {

// What a backend offers a sequence.
struct Rig {
  const hw::RigDescription* description = nullptr;
  hw::Controller* controller = nullptr;
  std::vector<hw::Camera*> cameras;
  // Puts the lens dot-grid board before camera i (held) or takes it away, and
  // returns when that is done: the simulation places it itself; before a real
  // camera a person holds it, asked by whoever runs the sequence (the station's
  // prompt, a terminal; rig_backend.hpp). `why` is not empty when the last picture
  // of the board could not be used: the person is asked again, told why.
  std::function<Status(size_t camera, bool held, const std::string& why)> hold_dot_grid;
  // Whether a person holds the board before camera i (and so can be asked again);
  // null: nobody does.
  std::function<bool(size_t camera)> person_holds_dot_grid;
};

enum class ShotKind {
  kDotGrid,        // the lens board before this camera, room lights on
  kRoom,           // room lights on (for people to look at)
  kLightsOff,      // room and frame lights off: the base for the markers
  kFrameLights,    // both frame-light circuits on
  kFrontLights,    // the front poles' circuit only (which side a camera faces)
  kLaserBase,      // lasers off, just before a laser or a group comes on
  kLaserIdentify,  // one laser alone at an end or the middle of its sweep (which camera sees which laser)
  kScanStep,       // a group's lasers on at a step
};
const char* to_string(ShotKind k);

struct LaserState {
  int laser = 0;  // index into the description's lasers
  int step = 0;
};

struct Shot {
  ShotKind kind = ShotKind::kRoom;
  size_t camera = 0;
  int group = -1;                  // laser group (kLaserBase in a scan, kScanStep)
  int step_index = -1;             // 0.. within the group's sweep (kScanStep)
  std::vector<LaserState> lasers;  // the lasers on
  hw::Frame frame;
};

// Consumes a shot; an error stops the sequence.
using ShotSink = std::function<Status(Shot&&)>;

// Calibration: the dot grid before each camera; lights off, all frame lights on,
// the front circuit alone; then each laser alone at both ends and the middle (step
// 0) of its sweep after a base frame, seen by every camera.
//
// When a person holds the dot grid and the sink rejects its picture
// (failed_precondition: no dots found, a black image ...), the person is asked to
// hold it again with the sink's reason, until a picture is usable or `progress`
// cancels; a simulated board's rejected picture is an error at once.
Status acquire_calibration(const Rig& rig, const ShotSink& sink, const ProgressFn& progress = {});

// A scan: per laser group, a base frame (lasers off), then the group's lasers
// stepping together through their sweeps, every camera grabbing every `every`th step.
// Lasers marked in `reversed` (by index; empty: none) sweep from their last step to
// their first, so that lasers running together can be kept apart (calibration
// chooses; see RigCalibration::sweep_reversed).
Status acquire_scan(const Rig& rig, const ShotSink& sink, int every = 1, const ProgressFn& progress = {},
                    const std::vector<bool>& reversed = {});

// Steps in a group's sweep (the longest of its lasers'), and the lasers' indices.
std::vector<int> group_lasers(const hw::RigDescription& rig, size_t group);
int group_steps(const hw::RigDescription& rig, size_t group);

}  // namespace bodyscan::pipeline
