// The rig description: a JSON file saying what a rig is made of (docs/rig-description.md
// documents every field). Real rigs use the frame and controller parts; the simulator
// also uses the true camera and laser poses and the subject. Calibration never reads
// the poses: it finds them (thesis §3.1).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/status.hpp"
#include "hw/camera_model.hpp"

namespace bodyscan::hw {

// Two equal rectangular frames of square white tubing, one on the floor (its light
// centres in Y = 0) and one above it (light centres in Y = top_height). Each frame
// has a front pole (Z = +depth/2) and a back pole (Z = -depth/2) running along X,
// joined by side poles. Every front and back pole carries a light on its outer face
// and one on its inner face at each of the two `light_x` positions. A camera on the
// front side thus sees, per frame, the front pole's outer lights and the back pole's
// inner ones: four lights at the corners of a rectangle in the frame's plane (thesis
// §2.1, §3.1.2: eight per camera, four per frame), which is what a plane transform
// needs - four lights along one pole would be collinear.
struct FrameGeometry {
  double width = 1800;                        // X distance between the side poles' centre lines, mm
  double depth = 1100;                        // Z distance between the front and back poles' centre lines
  double top_height = 2300;                   // Y of the top frame's light centres
  double tube = 40;                           // side of the square tubing
  std::vector<double> light_x = {-700, 700};  // along each front and back pole, both faces
  double light_diameter = 30;                 // the diffuser disc
};

// The centres of the eight frame lights a camera on the front (front = true) or back
// side sees: per frame (bottom first), the near pole's outer-face lights and the far
// pole's inner-face lights, each in light_x order.
std::vector<Vec3d> visible_lights(const FrameGeometry& frame, bool front);

enum class PixelFormat { kMono8, kMono12, kMono16 };
const char* to_string(PixelFormat f);
int bits_per_pixel(PixelFormat f);  // significant bits: 8, 12 or 16

// Which device a camera is: the simulator renders it, or a GenICam camera is
// opened through Aravis (hw/aravis). docs/rig-description.md, "Devices".
struct CameraDevice {
  std::string backend = "sim";       // "sim" or "aravis"
  std::string id;                    // aravis: as `bodyscan devices` lists it, or the camera's IP address
  std::string trigger = "software";  // "software", or the line a hardware trigger arrives on ("Line1")
  int timeout_ms = 2000;             // a frame not complete by then is an error
  int packet_size = 0;               // GigE Vision: bytes per stream packet; 0 negotiates the largest
};

struct CameraDescription {
  std::string id;
  CameraDevice device;
  Vec3d position = Vec3d::Zero();  // centre of projection, world mm
  Vec3d look_at = Vec3d::Zero();   // a world point on the optical axis
  double focal_mm = 6;
  double pixel_size_um = 5.3;
  int width = 1280, height = 1024;
  Distortion distortion;
  PixelFormat pixel_format = PixelFormat::kMono8;
  // Sensor (for the simulator): electrons at full scale, read noise in electrons,
  // and the exposure in microseconds the camera starts with.
  double full_well_e = 10000;
  double read_noise_e = 12;
  // The lens's blur (diffraction, residual focus): the Gaussian sigma of its point
  // spread, pixels. Real machine-vision lenses at f/4 on 5 um pixels spread a point
  // over about two pixels; a perfectly sharp image would let narrow features (a
  // laser line) fall inside one pixel and lose their sub-pixel position.
  double blur_px = 0.7;
  double exposure_us = 10000;
  double gain_db = 0;

  CameraModel model() const;  // the true model, for the simulator and tests only
};

// A line laser on a stepper motor. Its plane contains the rotation axis through
// `position`; at step s it holds the direction `aim` turned by s * step_angle about
// the axis (right-handed).
struct LaserDescription {
  std::string id;
  Vec3d position = Vec3d::Zero();
  Vec3d axis = Vec3d::UnitY();
  Vec3d aim = -Vec3d::UnitZ();  // horizontal pointing direction at step 0
  double step_angle_deg = 0.05;
  int min_step = -200, max_step = 200;
  double line_width_mm = 1.0;  // full width at half maximum of the stripe's cross profile
  double power = 1.0;          // stripe brightness relative to a full-scale white target

  // Unit normal of the plane at a step, and the plane's offset d (n . x = d).
  Vec3d plane_normal(int step) const;
  double plane_offset(int step) const { return plane_normal(step).dot(position); }
};

// The controller: the simulator's, or a TMCL stepper module (hw/usb) whose digital
// outputs switch the lasers and lights (through relays or the lasers' TTL enable)
// and whose axes turn the lasers. docs/rig-description.md, "Devices".
struct ControllerDescription {
  std::string backend = "sim";                         // "sim" or "tmcl"
  std::string port;                                    // a serial device node; empty: USB through libusb
  uint16_t usb_vendor = 0x2a3c, usb_product = 0x0100;  // Trinamic's TMCM modules
  std::string usb_serial;                              // to pick one of several boards; empty: the first
  int module_address = 1;
  struct LaserWiring {
    int output = -1;              // digital output switching this laser
    int axis = -1;                // motor axis turning it
    int microsteps_per_step = 1;  // motor microsteps per laser step (step_angle_deg)
    int home_offset = 0;          // microsteps from the reference switch to step 0
  };
  std::vector<LaserWiring> lasers;                                                 // by laser index
  int room_lights_output = -1, front_lights_output = -1, back_lights_output = -1;  // -1: not wired
  int reply_timeout_ms = 250;
  int move_timeout_ms = 10000;
  int home_timeout_ms = 60000;
  int watchdog_ms = 500;  // board-side laser watchdog period; 0: none
};

struct SubjectMotion {
  double sway_mm = 0, sway_hz = 0.25;            // side-to-side (X) and front-back (Z) sway
  double breathing_mm = 0, breathing_hz = 0.25;  // chest radius change
};

// How the simulated subject stands, where it differs from its mesh's rest pose
// (hw/sim/pose_body.hpp poses a MakeHuman body by skinning). Unset: as in the mesh.
struct SubjectPosture {
  // Left (+X), right: the upper arm (shoulder joint to elbow joint) from the
  // downward vertical, degrees, 0-80.
  std::array<std::optional<double>, 2> arm_abduction_deg;
  std::optional<double> ankle_distance_mm;  // between the ankle joints' centres, 100-700
  bool any() const { return arm_abduction_deg[0] || arm_abduction_deg[1] || ankle_distance_mm; }
};

struct SimulationDescription {
  std::string subject;                   // body mesh (PLY, mm, Y up), relative to the description file
  SubjectPosture posture;                // applied to the mesh first
  Vec3d subject_offset = Vec3d::Zero();  // added to the mesh (after standing it on the floor)
  double subject_yaw_deg = 0;            // turn about the vertical axis: + turns the face from +Z toward +X
  SubjectMotion motion;
  double frame_rate_hz = 30;
  uint64_t seed = 1;
  double room_light = 0.6;         // white-surface brightness with room lights on, fraction of full scale
  double ambient_light = 0.02;     // with room lights off
  double frame_light = 1.5;        // frame light brightness (saturates a little, like a real diffuser)
  double speckle_contrast = 0.25;  // std/mean of laser speckle
};

// How scans of this layout are best processed, where that depends on the layout.
struct ProcessingHints {
  // Points a camera saw more than this from the surface normal are dropped
  // (docs/scan-processing.md, "Grazing views"); 90 keeps them all. A layout that
  // lights the flanks but sees them edge-on wants a cut; one whose grazing points are
  // all it has of the flanks does not.
  double max_view_deg = 90;
};

struct RigDescription {
  std::string name;
  std::string source;  // the file it was read from, for messages
  FrameGeometry frame;
  std::vector<CameraDescription> cameras;
  std::vector<LaserDescription> lasers;
  // Lasers that may run together (thesis §2.3): each group's planes never cross
  // inside the frame at any pair of steps. Every laser is in exactly one group.
  std::vector<std::vector<std::string>> laser_groups;
  ControllerDescription controller;
  SimulationDescription simulation;
  ProcessingHints processing;

  // Whether any device is real (not simulated).
  bool has_real_devices() const;

  const LaserDescription* find_laser(const std::string& id) const;
};

// Parses and checks a description. `source` names it in messages and is the folder
// relative paths (the subject) are resolved against.
StatusOr<RigDescription> parse_rig_description(const std::string& json_text, const std::string& source);
StatusOr<RigDescription> load_rig_description(const std::string& path);
// The description as JSON (what parse_rig_description reads back unchanged).
std::string to_json(const RigDescription& rig);

// The shipped layouts: "thesis" (thesis fig. 2.2: 3 cameras, 4 lasers, run one at a
// time - docs/rig-description.md says why), "square" (thesis fig. 6.1: 4 cameras,
// 4 lasers) and "tiered" (the square's four columns, each with a camera and a laser
// low and high, so the crotch, the shoulders' tops and the forearms are seen). Their
// files live in hw/rigs/; this returns the path for a name, or an error listing the
// names.
const std::vector<std::string>& shipped_rig_names();
StatusOr<std::string> shipped_rig_path(const std::string& name);

}  // namespace bodyscan::hw
