#include "hw/rig_description.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/json_text.hpp"

namespace bodyscan::hw {

using nlohmann::json;

const char* to_string(PixelFormat f) {
  switch (f) {
    case PixelFormat::kMono8: return "mono8";
    case PixelFormat::kMono12: return "mono12";
    case PixelFormat::kMono16: return "mono16";
  }
  return "?";
}

int bits_per_pixel(PixelFormat f) {
  switch (f) {
    case PixelFormat::kMono8: return 8;
    case PixelFormat::kMono12: return 12;
    case PixelFormat::kMono16: return 16;
  }
  return 8;
}

std::vector<Vec3d> visible_lights(const FrameGeometry& f, bool front) {
  const double side = front ? 1.0 : -1.0;
  const double near_z = side * (0.5 * f.depth + 0.5 * f.tube), far_z = -side * (0.5 * f.depth - 0.5 * f.tube);
  std::vector<Vec3d> out;
  for (double y : {0.0, f.top_height})
    for (double z : {near_z, far_z})
      for (double x : f.light_x) out.emplace_back(x, y, z);
  return out;
}

CameraModel CameraDescription::model() const {
  return CameraModel::look_at(width, height, focal_mm, pixel_size_um * 1e-3, distortion, position, look_at);
}

Vec3d LaserDescription::plane_normal(int step) const {
  const Vec3d a = axis.normalized();
  const Eigen::AngleAxisd turn(step * step_angle_deg * M_PI / 180.0, a);
  const Vec3d dir = turn * aim;
  return a.cross(dir).normalized();
}

bool RigDescription::has_real_devices() const {
  if (controller.backend != "sim") return true;
  for (const CameraDescription& c : cameras)
    if (c.device.backend != "sim") return true;
  return false;
}

const LaserDescription* RigDescription::find_laser(const std::string& id) const {
  for (const LaserDescription& l : lasers)
    if (l.id == id) return &l;
  return nullptr;
}

namespace {

// Parsing reports the first problem with the JSON path of the offending field.
struct ParseError {
  std::string message;
};

class Reader {
 public:
  Reader(const json& j, std::string path) : j_(j), path_(std::move(path)) {}
  const json& raw() const { return j_; }
  const std::string& path() const { return path_; }
  bool has(const char* key) const { return j_.is_object() && j_.contains(key); }

  [[noreturn]] void fail(const std::string& what) const { throw ParseError{path_ + ": " + what}; }

  Reader child(const char* key) const {
    if (!has(key)) fail(std::string("missing field '") + key + "'");
    return Reader(j_.at(key), path_ + "." + key);
  }
  Reader at(size_t i) const { return Reader(j_.at(i), path_ + "[" + std::to_string(i) + "]"); }

  double number(const char* key, double fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(std::string("missing field '") + key + "'");
      return fallback;
    }
    const json& v = j_.at(key);
    if (!v.is_number()) fail(std::string("'") + key + "' must be a number, got " + v.dump());
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(std::string("'") + key + "' is not finite");
    return x;
  }
  double positive(const char* key, double fallback, bool required = false) const {
    const double x = number(key, fallback, required);
    if (!(x > 0)) fail(std::string("'") + key + "' must be positive, got " + std::to_string(x));
    return x;
  }
  double non_negative(const char* key, double fallback) const {
    const double x = number(key, fallback);
    if (x < 0) fail(std::string("'") + key + "' must not be negative, got " + std::to_string(x));
    return x;
  }
  int integer(const char* key, int fallback, bool required = false) const {
    const double x = number(key, fallback, required);
    if (x != std::floor(x) || std::abs(x) > 1e9) fail(std::string("'") + key + "' must be an integer");
    return static_cast<int>(x);
  }
  std::string text(const char* key, const std::string& fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(std::string("missing field '") + key + "'");
      return fallback;
    }
    const json& v = j_.at(key);
    if (!v.is_string()) fail(std::string("'") + key + "' must be a string, got " + v.dump());
    return v.get<std::string>();
  }
  Vec3d vec3(const char* key, const Vec3d& fallback, bool required = false) const {
    if (!has(key)) {
      if (required) fail(std::string("missing field '") + key + "'");
      return fallback;
    }
    const json& v = j_.at(key);
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number()) {
      fail(std::string("'") + key + "' must be [x, y, z] in mm, got " + v.dump());
    }
    const Vec3d out(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    if (!out.allFinite()) fail(std::string("'") + key + "' is not finite");
    return out;
  }
  std::vector<Reader> array(const char* key, bool required) const {
    std::vector<Reader> out;
    if (!has(key)) {
      if (required) fail(std::string("missing field '") + key + "'");
      return out;
    }
    const json& v = j_.at(key);
    if (!v.is_array()) fail(std::string("'") + key + "' must be an array");
    Reader arr(v, path_ + "." + key);
    for (size_t i = 0; i < v.size(); ++i) out.push_back(arr.at(i));
    return out;
  }
  void only(std::initializer_list<const char*> keys) const {
    if (!j_.is_object()) fail("must be an object, got " + j_.dump());
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      bool known = false;
      for (const char* k : keys) known = known || it.key() == k;
      if (!known) fail("unknown field '" + it.key() + "' (a typo? see docs/rig-description.md)");
    }
  }

 private:
  const json& j_;
  std::string path_;
};

FrameGeometry read_frame(const Reader& r) {
  r.only({"width", "depth", "top_height", "tube", "light_x", "light_diameter"});
  FrameGeometry f;
  f.width = r.positive("width", f.width, true);
  f.depth = r.positive("depth", f.depth, true);
  f.top_height = r.positive("top_height", f.top_height, true);
  f.tube = r.positive("tube", f.tube);
  f.light_diameter = r.positive("light_diameter", f.light_diameter);
  if (f.light_diameter > f.tube) r.fail("light_diameter must fit on the tube's face");
  if (r.has("light_x")) {
    f.light_x.clear();
    for (const Reader& x : r.array("light_x", true)) {
      if (!x.raw().is_number()) x.fail("must be a number (mm along the pole)");
      f.light_x.push_back(x.raw().get<double>());
    }
  }
  if (f.light_x.size() != 2 || std::abs(f.light_x[0] - f.light_x[1]) < 2 * f.light_diameter) {
    r.fail(
        "light_x must list 2 distinct positions along the poles (each pole face carries 2 lights; a camera "
        "sees 4 per frame, thesis §2.1)");
  }
  for (double x : f.light_x) {
    if (std::abs(x) > 0.5 * f.width - f.tube) r.fail("a light lies beyond the pole's ends (|x| > width/2 - tube)");
  }
  return f;
}

Distortion read_distortion(const Reader& r) {
  r.only({"k1", "k2", "k3", "p1", "p2"});
  Distortion d;
  d.k1 = r.number("k1", 0);
  d.k2 = r.number("k2", 0);
  d.k3 = r.number("k3", 0);
  d.p1 = r.number("p1", 0);
  d.p2 = r.number("p2", 0);
  return d;
}

CameraDescription read_camera(const Reader& r) {
  r.only({"id", "position", "look_at", "focal_mm", "pixel_size_um", "width", "height", "distortion", "pixel_format",
          "full_well_e", "read_noise_e", "exposure_us", "gain_db", "blur_px", "device"});
  CameraDescription c;
  c.id = r.text("id", "", true);
  if (c.id.empty()) r.fail("id must not be empty");
  if (r.has("device")) {
    const Reader d = r.child("device");
    d.only({"backend", "id", "trigger", "timeout_ms", "packet_size"});
    c.device.backend = d.text("backend", "sim");
    if (c.device.backend != "sim" && c.device.backend != "aravis") {
      d.fail("backend must be 'sim' or 'aravis', got '" + c.device.backend + "'");
    }
    c.device.id = d.text("id", "");
    if (c.device.backend == "aravis" && c.device.id.empty()) {
      d.fail("an aravis camera needs its 'id' (as `bodyscan devices` lists it, or its IP address)");
    }
    c.device.trigger = d.text("trigger", "software");
    if (c.device.trigger.empty()) d.fail("trigger must be 'software' or a line name such as 'Line1'");
    c.device.timeout_ms = d.integer("timeout_ms", c.device.timeout_ms);
    if (c.device.timeout_ms < 10 || c.device.timeout_ms > 600000) d.fail("timeout_ms must be 10..600000");
    c.device.packet_size = d.integer("packet_size", 0);
    if (c.device.packet_size < 0 || c.device.packet_size > 16384) d.fail("packet_size must be 0..16384");
  }
  c.position = r.vec3("position", c.position, true);
  c.look_at = r.vec3("look_at", c.look_at, true);
  if ((c.look_at - c.position).norm() < 1) r.fail("look_at must differ from position");
  c.focal_mm = r.positive("focal_mm", c.focal_mm, true);
  c.pixel_size_um = r.positive("pixel_size_um", c.pixel_size_um, true);
  c.width = r.integer("width", c.width, true);
  c.height = r.integer("height", c.height, true);
  if (c.width < 16 || c.height < 16 || c.width > 20000 || c.height > 20000) {
    r.fail("width and height must be 16..20000 pixels");
  }
  if (r.has("distortion")) c.distortion = read_distortion(r.child("distortion"));
  const std::string fmt = r.text("pixel_format", "mono8");
  if (fmt == "mono8")
    c.pixel_format = PixelFormat::kMono8;
  else if (fmt == "mono12")
    c.pixel_format = PixelFormat::kMono12;
  else if (fmt == "mono16")
    c.pixel_format = PixelFormat::kMono16;
  else
    r.fail("pixel_format must be mono8, mono12 or mono16, got '" + fmt + "'");
  c.full_well_e = r.positive("full_well_e", c.full_well_e);
  c.read_noise_e = r.non_negative("read_noise_e", c.read_noise_e);
  c.blur_px = r.non_negative("blur_px", c.blur_px);
  c.exposure_us = r.positive("exposure_us", c.exposure_us);
  c.gain_db = r.number("gain_db", c.gain_db);
  // The distortion must stay invertible over the whole sensor, or the model is
  // not a lens.
  const CameraModel m = c.model();
  for (double u : {0.0, 0.5, 1.0})
    for (double v : {0.0, 0.5, 1.0}) {
      if (!m.ray({u * (c.width - 1), v * (c.height - 1)})) {
        r.fail("the distortion cannot be inverted at the image's corners: the lens model folds over");
      }
    }
  return c;
}

LaserDescription read_laser(const Reader& r) {
  r.only({"id", "position", "axis", "aim", "step_angle_deg", "min_step", "max_step", "line_width_mm", "power"});
  LaserDescription l;
  l.id = r.text("id", "", true);
  if (l.id.empty()) r.fail("id must not be empty");
  l.position = r.vec3("position", l.position, true);
  l.axis = r.vec3("axis", l.axis);
  if (l.axis.norm() < 1e-9) r.fail("axis must not be zero");
  l.axis.normalize();
  l.aim = r.vec3("aim", l.aim, true);
  l.aim -= l.aim.dot(l.axis) * l.axis;  // the aim is taken across the axis
  if (l.aim.norm() < 1e-9) r.fail("aim must not be parallel to the axis");
  l.aim.normalize();
  l.step_angle_deg = r.positive("step_angle_deg", l.step_angle_deg, true);
  l.min_step = r.integer("min_step", l.min_step, true);
  l.max_step = r.integer("max_step", l.max_step, true);
  if (l.max_step < l.min_step) r.fail("max_step must not be below min_step");
  if ((l.max_step - l.min_step) * l.step_angle_deg > 170) r.fail("the sweep spans more than 170 degrees");
  l.line_width_mm = r.positive("line_width_mm", l.line_width_mm);
  l.power = r.positive("power", l.power);
  return l;
}

uint16_t usb_id(const Reader& r, const char* key, uint16_t fallback) {
  if (!r.has(key)) return fallback;
  const std::string t = r.text(key, "");
  char* end = nullptr;
  const unsigned long v = std::strtoul(t.c_str(), &end, 16);
  if (t.empty() || t.size() > 4 || *end != '\0')
    r.fail(std::string("'") + key + "' must be 4 hex digits, got '" + t + "'");
  return static_cast<uint16_t>(v);
}

ControllerDescription read_controller(const Reader& r, const std::vector<LaserDescription>& lasers) {
  r.only({"backend", "port", "usb", "module_address", "lasers", "room_lights_output", "front_lights_output",
          "back_lights_output", "reply_timeout_ms", "move_timeout_ms", "home_timeout_ms", "watchdog_ms"});
  ControllerDescription c;
  c.backend = r.text("backend", "sim");
  if (c.backend != "sim" && c.backend != "tmcl") r.fail("backend must be 'sim' or 'tmcl', got '" + c.backend + "'");
  c.port = r.text("port", "");
  if (r.has("usb")) {
    const Reader u = r.child("usb");
    u.only({"vendor", "product", "serial"});
    c.usb_vendor = usb_id(u, "vendor", c.usb_vendor);
    c.usb_product = usb_id(u, "product", c.usb_product);
    c.usb_serial = u.text("serial", "");
  }
  c.module_address = r.integer("module_address", 1);
  if (c.module_address < 0 || c.module_address > 255) r.fail("module_address must be 0..255");
  c.room_lights_output = r.integer("room_lights_output", -1);
  c.front_lights_output = r.integer("front_lights_output", -1);
  c.back_lights_output = r.integer("back_lights_output", -1);
  c.reply_timeout_ms = r.integer("reply_timeout_ms", c.reply_timeout_ms);
  c.move_timeout_ms = r.integer("move_timeout_ms", c.move_timeout_ms);
  c.home_timeout_ms = r.integer("home_timeout_ms", c.home_timeout_ms);
  c.watchdog_ms = r.integer("watchdog_ms", c.watchdog_ms);
  if (c.reply_timeout_ms < 10 || c.move_timeout_ms < 10 || c.home_timeout_ms < 10)
    r.fail("timeouts must be at least 10 ms");
  if (c.watchdog_ms != 0 && (c.watchdog_ms < 100 || c.watchdog_ms > 60000)) {
    r.fail("watchdog_ms must be 0 (none) or 100..60000");
  }
  c.lasers.assign(lasers.size(), {});
  if (c.backend == "sim") return c;
  // Real lasers point at people: when the process dies in a way no handler sees
  // (SIGKILL, a hung machine, the USB cable pulled), the board's watchdog is what
  // switches them off (docs/hardware.md).
  if (c.watchdog_ms == 0 && !lasers.empty())
    r.fail(
        "watchdog_ms 0 (none) is refused for a board that switches lasers: its watchdog switches them off "
        "when the workstation dies unseen");
  std::set<int> outputs, axes;
  auto output = [&](const Reader& at, int o, const std::string& what) {
    if (o < 0) return;
    if (o > 255) at.fail(what + ": output " + std::to_string(o) + " does not exist");
    if (!outputs.insert(o).second) at.fail(what + ": output " + std::to_string(o) + " is wired twice");
  };
  output(r, c.room_lights_output, "room lights");
  output(r, c.front_lights_output, "front frame lights");
  output(r, c.back_lights_output, "back frame lights");
  const Reader lw = r.child("lasers");
  if (!lw.raw().is_object()) lw.fail("must map each laser id to its wiring");
  for (auto it = lw.raw().begin(); it != lw.raw().end(); ++it) {
    size_t i = 0;
    while (i < lasers.size() && lasers[i].id != it.key()) ++i;
    if (i == lasers.size()) lw.fail("unknown laser id '" + it.key() + "'");
    const Reader w(it.value(), lw.path() + "." + it.key());
    w.only({"output", "axis", "microsteps_per_step", "home_offset"});
    ControllerDescription::LaserWiring& l = c.lasers[i];
    l.output = w.integer("output", -1, true);
    l.axis = w.integer("axis", -1, true);
    l.microsteps_per_step = w.integer("microsteps_per_step", 1);
    l.home_offset = w.integer("home_offset", 0);
    if (l.output < 0) w.fail("output must be 0 or more");
    output(w, l.output, "laser '" + it.key() + "'");
    if (l.axis < 0 || l.axis > 255) w.fail("axis must be 0..255");
    if (!axes.insert(l.axis).second) w.fail("axis " + std::to_string(l.axis) + " turns two lasers");
    if (l.microsteps_per_step < 1) w.fail("microsteps_per_step must be at least 1");
  }
  for (size_t i = 0; i < lasers.size(); ++i)
    if (c.lasers[i].output < 0) lw.fail("laser '" + lasers[i].id + "' is not wired (give its output and axis)");
  return c;
}

SimulationDescription read_simulation(const Reader& r, const std::string& source) {
  r.only({"subject", "posture", "subject_offset", "subject_yaw_deg", "motion", "frame_rate_hz", "seed", "room_light",
          "ambient_light", "frame_light", "speckle_contrast"});
  SimulationDescription s;
  s.subject = r.text("subject", "");
  if (!s.subject.empty() && std::filesystem::path(s.subject).is_relative()) {
    s.subject =
        std::filesystem::absolute(std::filesystem::path(source).parent_path() / s.subject).lexically_normal().string();
  }
  if (r.has("posture")) {
    const Reader p = r.child("posture");
    p.only({"arm_abduction_deg", "ankle_distance_mm"});
    if (p.has("arm_abduction_deg")) {
      // One angle for both arms, or [left, right] (null: that arm as in the mesh).
      const json& a = p.raw().at("arm_abduction_deg");
      const auto angle = [](const json& x) { return x.is_number() || x.is_null(); };
      const bool pair = a.is_array() && a.size() == 2 && angle(a[0]) && angle(a[1]);
      if (!a.is_number() && !pair) p.fail("'arm_abduction_deg' must be degrees or [left, right] in degrees");
      for (int k = 0; k < 2; ++k) {
        const json& v = pair ? a[k] : a;
        if (v.is_null()) continue;
        const double x = v.get<double>();
        if (!(x >= 0 && x <= 80)) p.fail("'arm_abduction_deg' must be 0-80 degrees from the vertical");
        s.posture.arm_abduction_deg[k] = x;
      }
    }
    if (p.has("ankle_distance_mm")) {
      const double x = p.number("ankle_distance_mm", 0);
      if (!(x >= 100 && x <= 700)) p.fail("'ankle_distance_mm' must be 100-700 mm");
      s.posture.ankle_distance_mm = x;
    }
  }
  s.subject_offset = r.vec3("subject_offset", s.subject_offset);
  s.subject_yaw_deg = r.number("subject_yaw_deg", 0);
  if (r.has("motion")) {
    const Reader m = r.child("motion");
    m.only({"sway_mm", "sway_hz", "breathing_mm", "breathing_hz"});
    s.motion.sway_mm = m.non_negative("sway_mm", 0);
    s.motion.sway_hz = m.positive("sway_hz", s.motion.sway_hz);
    s.motion.breathing_mm = m.non_negative("breathing_mm", 0);
    s.motion.breathing_hz = m.positive("breathing_hz", s.motion.breathing_hz);
  }
  s.frame_rate_hz = r.positive("frame_rate_hz", s.frame_rate_hz);
  const double seed = r.non_negative("seed", 1);
  s.seed = static_cast<uint64_t>(seed);
  s.room_light = r.non_negative("room_light", s.room_light);
  s.ambient_light = r.non_negative("ambient_light", s.ambient_light);
  s.frame_light = r.positive("frame_light", s.frame_light);
  s.speckle_contrast = r.non_negative("speckle_contrast", s.speckle_contrast);
  if (s.speckle_contrast > 1) r.fail("speckle_contrast must be at most 1");
  return s;
}

// Where two lasers' vertical planes cross: outside the frame for every pair of steps
// (thesis §2.3). Planes are vertical when the axes are; otherwise the line of
// intersection is tested against the frame's box.
bool planes_cross_inside(const LaserDescription& a, const LaserDescription& b, const FrameGeometry& f, int* step_a,
                         int* step_b) {
  const Eigen::AlignedBox3d box(Vec3d(-0.5 * f.width, 0, -0.5 * f.depth),
                                Vec3d(0.5 * f.width, f.top_height, 0.5 * f.depth));
  for (int sa = a.min_step; sa <= a.max_step; ++sa) {
    const Vec3d na = a.plane_normal(sa);
    const double da = na.dot(a.position);
    for (int sb = b.min_step; sb <= b.max_step; ++sb) {
      const Vec3d nb = b.plane_normal(sb);
      const double db = nb.dot(b.position);
      const Vec3d dir = na.cross(nb);
      if (dir.norm() < 1e-9) continue;  // parallel planes never cross
      // A point on the line: the least-norm solution of the two plane equations.
      const Vec3d p = (da * nb.cross(dir) + db * dir.cross(na)) / dir.squaredNorm();
      // Clip the line p + t dir against the box (slabs).
      double t0 = -1e18, t1 = 1e18;
      bool outside = false;
      for (int k = 0; k < 3 && !outside; ++k) {
        if (std::abs(dir[k]) < 1e-12) {
          outside = p[k] < box.min()[k] || p[k] > box.max()[k];
        } else {
          double u0 = (box.min()[k] - p[k]) / dir[k], u1 = (box.max()[k] - p[k]) / dir[k];
          if (u0 > u1) std::swap(u0, u1);
          t0 = std::max(t0, u0);
          t1 = std::min(t1, u1);
        }
      }
      if (!outside && t0 <= t1) {
        *step_a = sa;
        *step_b = sb;
        return true;
      }
    }
  }
  return false;
}

RigDescription read_rig(const json& j, const std::string& source) {
  const Reader r(j, "rig");
  r.only({"name", "frame", "cameras", "lasers", "laser_groups", "controller", "simulation", "processing"});
  RigDescription rig;
  rig.source = source;
  rig.name = r.text("name", std::filesystem::path(source).stem().string());
  rig.frame = read_frame(r.child("frame"));
  std::set<std::string> ids;
  for (const Reader& c : r.array("cameras", true)) {
    rig.cameras.push_back(read_camera(c));
    if (!ids.insert(rig.cameras.back().id).second) c.fail("camera id '" + rig.cameras.back().id + "' is used twice");
  }
  if (rig.cameras.empty()) r.fail("a rig needs at least one camera");
  ids.clear();
  for (const Reader& l : r.array("lasers", true)) {
    rig.lasers.push_back(read_laser(l));
    if (!ids.insert(rig.lasers.back().id).second) l.fail("laser id '" + rig.lasers.back().id + "' is used twice");
  }
  std::set<std::string> grouped;
  for (const Reader& g : r.array("laser_groups", false)) {
    if (!g.raw().is_array() || g.raw().empty()) g.fail("a laser group is a non-empty array of laser ids");
    std::vector<std::string> group;
    for (size_t i = 0; i < g.raw().size(); ++i) {
      const json& id = g.raw()[i];
      if (!id.is_string() || !ids.count(id.get<std::string>())) g.fail("unknown laser id " + id.dump());
      if (!grouped.insert(id.get<std::string>()).second) g.fail("laser " + id.dump() + " is in two groups");
      group.push_back(id.get<std::string>());
    }
    for (size_t i = 0; i < group.size(); ++i)
      for (size_t k = i + 1; k < group.size(); ++k) {
        int sa = 0, sb = 0;
        if (planes_cross_inside(*rig.find_laser(group[i]), *rig.find_laser(group[k]), rig.frame, &sa, &sb)) {
          g.fail("lasers '" + group[i] + "' and '" + group[k] +
                 "' cannot run together: their planes cross inside the frame (steps " + std::to_string(sa) + " and " +
                 std::to_string(sb) + ")");
        }
      }
    rig.laser_groups.push_back(std::move(group));
  }
  for (const LaserDescription& l : rig.lasers)
    if (!grouped.count(l.id)) rig.laser_groups.push_back({l.id});  // runs alone
  rig.controller.lasers.assign(rig.lasers.size(), {});
  if (r.has("controller")) rig.controller = read_controller(r.child("controller"), rig.lasers);
  if (r.has("simulation")) rig.simulation = read_simulation(r.child("simulation"), source);
  if (r.has("processing")) {
    const Reader p = r.child("processing");
    p.only({"max_view_deg"});
    rig.processing.max_view_deg = p.positive("max_view_deg", rig.processing.max_view_deg);
    if (rig.processing.max_view_deg > 90) p.fail("max_view_deg must be at most 90 (degrees from the surface normal)");
  }
  return rig;
}

json vec(const Vec3d& v) { return json::array({v.x(), v.y(), v.z()}); }

}  // namespace

StatusOr<RigDescription> parse_rig_description(const std::string& json_text, const std::string& source) {
  const json j = parse_json(json_text);
  if (j.is_discarded())
    return invalid_argument(source + ": not valid JSON, or nested more than " + std::to_string(kMaxJsonDepth) +
                            " levels deep");
  try {
    return read_rig(j, source);
  } catch (const ParseError& e) {
    return invalid_argument(source + ": " + e.message);
  } catch (const json::exception& e) {
    return invalid_argument(source + ": " + e.what());
  }
}

StatusOr<RigDescription> load_rig_description(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return not_found("cannot open rig description '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return io_error("cannot read rig description '" + path + "'");
  return parse_rig_description(text.str(), path);
}

std::string to_json(const RigDescription& rig) {
  json j;
  j["name"] = rig.name;
  const FrameGeometry& f = rig.frame;
  j["frame"] = {{"width", f.width}, {"depth", f.depth},     {"top_height", f.top_height},
                {"tube", f.tube},   {"light_x", f.light_x}, {"light_diameter", f.light_diameter}};
  j["cameras"] = json::array();
  for (const CameraDescription& c : rig.cameras) {
    j["cameras"].push_back({{"id", c.id},
                            {"position", vec(c.position)},
                            {"look_at", vec(c.look_at)},
                            {"focal_mm", c.focal_mm},
                            {"pixel_size_um", c.pixel_size_um},
                            {"width", c.width},
                            {"height", c.height},
                            {"distortion",
                             {{"k1", c.distortion.k1},
                              {"k2", c.distortion.k2},
                              {"k3", c.distortion.k3},
                              {"p1", c.distortion.p1},
                              {"p2", c.distortion.p2}}},
                            {"pixel_format", to_string(c.pixel_format)},
                            {"full_well_e", c.full_well_e},
                            {"read_noise_e", c.read_noise_e},
                            {"blur_px", c.blur_px},
                            {"exposure_us", c.exposure_us},
                            {"gain_db", c.gain_db}});
    if (c.device.backend != "sim") {
      j["cameras"].back()["device"] = {{"backend", c.device.backend},
                                       {"id", c.device.id},
                                       {"trigger", c.device.trigger},
                                       {"timeout_ms", c.device.timeout_ms},
                                       {"packet_size", c.device.packet_size}};
    }
  }
  j["lasers"] = json::array();
  for (const LaserDescription& l : rig.lasers) {
    j["lasers"].push_back({{"id", l.id},
                           {"position", vec(l.position)},
                           {"axis", vec(l.axis)},
                           {"aim", vec(l.aim)},
                           {"step_angle_deg", l.step_angle_deg},
                           {"min_step", l.min_step},
                           {"max_step", l.max_step},
                           {"line_width_mm", l.line_width_mm},
                           {"power", l.power}});
  }
  j["laser_groups"] = rig.laser_groups;
  if (rig.controller.backend != "sim") {
    const ControllerDescription& c = rig.controller;
    char vendor[8], product[8];
    std::snprintf(vendor, sizeof vendor, "%04x", c.usb_vendor);
    std::snprintf(product, sizeof product, "%04x", c.usb_product);
    json lasers_j = json::object();
    for (size_t i = 0; i < rig.lasers.size() && i < c.lasers.size(); ++i) {
      const auto& w = c.lasers[i];
      lasers_j[rig.lasers[i].id] = {{"output", w.output},
                                    {"axis", w.axis},
                                    {"microsteps_per_step", w.microsteps_per_step},
                                    {"home_offset", w.home_offset}};
    }
    j["controller"] = {{"backend", c.backend},
                       {"port", c.port},
                       {"usb", {{"vendor", vendor}, {"product", product}, {"serial", c.usb_serial}}},
                       {"module_address", c.module_address},
                       {"lasers", lasers_j},
                       {"room_lights_output", c.room_lights_output},
                       {"front_lights_output", c.front_lights_output},
                       {"back_lights_output", c.back_lights_output},
                       {"reply_timeout_ms", c.reply_timeout_ms},
                       {"move_timeout_ms", c.move_timeout_ms},
                       {"home_timeout_ms", c.home_timeout_ms},
                       {"watchdog_ms", c.watchdog_ms}};
  }
  const SimulationDescription& s = rig.simulation;
  json posture = json::object();
  if (s.posture.arm_abduction_deg[0] || s.posture.arm_abduction_deg[1])
    for (int k = 0; k < 2; ++k)
      posture["arm_abduction_deg"][k] = s.posture.arm_abduction_deg[k] ? json(*s.posture.arm_abduction_deg[k]) : json();
  if (s.posture.ankle_distance_mm) posture["ankle_distance_mm"] = *s.posture.ankle_distance_mm;
  j["simulation"] = {{"subject", s.subject},
                     {"posture", posture},
                     {"subject_offset", vec(s.subject_offset)},
                     {"subject_yaw_deg", s.subject_yaw_deg},
                     {"motion",
                      {{"sway_mm", s.motion.sway_mm},
                       {"sway_hz", s.motion.sway_hz},
                       {"breathing_mm", s.motion.breathing_mm},
                       {"breathing_hz", s.motion.breathing_hz}}},
                     {"frame_rate_hz", s.frame_rate_hz},
                     {"seed", s.seed},
                     {"room_light", s.room_light},
                     {"ambient_light", s.ambient_light},
                     {"frame_light", s.frame_light},
                     {"speckle_contrast", s.speckle_contrast}};
  j["processing"] = {{"max_view_deg", rig.processing.max_view_deg}};
  return j.dump(2);
}

const std::vector<std::string>& shipped_rig_names() {
  static const std::vector<std::string> names = {"thesis", "square", "tiered"};
  return names;
}

StatusOr<std::string> shipped_rig_path(const std::string& name) {
  const char* env = std::getenv("BODYSCAN_DATA_DIR");
  const std::filesystem::path root = env && *env ? env : BODYSCAN_DATA_DIR;
  std::string list;
  for (const std::string& known : shipped_rig_names()) {
    if (name == known) return (root / "hw" / "rigs" / (name + ".json")).string();
    list += (list.empty() ? "" : ", ") + known;
  }
  return not_found("no shipped rig named '" + name + "' (shipped: " + list + "; or give a description file)");
}

}  // namespace bodyscan::hw
