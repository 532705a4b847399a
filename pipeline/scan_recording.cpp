#include "pipeline/scan_recording.hpp"

#include <zlib.h>

#include <cmath>
#include <cstring>

#include "pipeline/scan.hpp"

namespace bodyscan::pipeline {

namespace {

nlohmann::json vec(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }
nlohmann::json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

bool read_vec(const nlohmann::json& j, Eigen::Vector2d* v) {
  if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number()) return false;
  *v = {j[0].get<double>(), j[1].get<double>()};
  return true;
}

}  // namespace

nlohmann::json calibration_record(const RigCalibration& cal) {
  nlohmann::json cams = nlohmann::json::array();
  for (size_t i = 0; i < cal.cameras.size(); ++i) {
    const CameraCalibration& c = cal.cameras[i];
    nlohmann::json dots = nlohmann::json::array();
    for (const GridDot& d : c.lens.grid_dots()) dots.push_back({d.col, d.row, d.centre.x(), d.centre.y()});
    const LensOptions& o = c.lens.options();
    nlohmann::json markers = nlohmann::json::array();
    for (const auto& pole : c.markers) markers.push_back({vec(pole[0]), vec(pole[1])});
    cams.push_back({{"id", c.camera_id},
                    {"width", c.width},
                    {"height", c.height},
                    {"side", to_string(c.side)},
                    {"markers", markers},
                    {"lasers_seen", cal.lasers_seen[i]},
                    {"lens",
                     {{"width", c.lens.width()},
                      {"height", c.lens.height()},
                      {"dots_found", c.lens.dots_found()},
                      {"centre_fraction", o.centre_fraction},
                      {"min_centre_dots", o.min_centre_dots},
                      {"min_dots", o.min_dots},
                      {"smoothing", o.smoothing},
                      {"degree", o.degree},
                      {"table_step", o.table_step},
                      {"dots", dots}}}});
  }
  nlohmann::json sightings = nlohmann::json::array();
  for (const LaserSighting& s : cal.sightings)
    sightings.push_back({{"laser", s.laser},
                         {"step", s.step},
                         {"camera", s.camera},
                         {"normal", vec(s.plane.normal)},
                         {"offset", s.plane.offset}});
  std::vector<int> reversed;
  for (bool b : cal.sweep_reversed) reversed.push_back(b ? 1 : 0);
  const ReferenceFrame& f = cal.frame;
  return {{"schema", kCalibrationRecordSchema},
          {"rig", cal.rig_name},
          {"frame",
           {{"width", f.width},
            {"depth", f.depth},
            {"top_height", f.top_height},
            {"tube", f.tube},
            {"light_x", f.light_x}}},
          {"cameras", cams},
          {"laser_ids", cal.laser_ids},
          {"sweep_reversed", reversed},
          {"group_separation_mm", cal.group_separation_mm},
          {"sightings", sightings}};
}

StatusOr<RigCalibration> calibration_from_record(const nlohmann::json& j) {
  auto bad = [](const std::string& what) { return invalid_argument("calibration record: " + what); };
  if (!j.is_object() || j.value("schema", "") != kCalibrationRecordSchema)
    return bad("not a " + std::string(kCalibrationRecordSchema) + " document");
  try {
    RigCalibration cal;
    cal.rig_name = j.at("rig").get<std::string>();
    const nlohmann::json& f = j.at("frame");
    cal.frame.width = f.at("width").get<double>();
    cal.frame.depth = f.at("depth").get<double>();
    cal.frame.top_height = f.at("top_height").get<double>();
    cal.frame.tube = f.at("tube").get<double>();
    cal.frame.light_x = f.at("light_x").get<std::array<double, 2>>();
    cal.laser_ids = j.at("laser_ids").get<std::vector<std::string>>();
    for (int b : j.at("sweep_reversed").get<std::vector<int>>()) cal.sweep_reversed.push_back(b != 0);
    cal.group_separation_mm = j.at("group_separation_mm").get<std::vector<double>>();
    for (const nlohmann::json& c : j.at("cameras")) {
      const nlohmann::json& l = c.at("lens");
      LensOptions o;
      o.centre_fraction = l.at("centre_fraction").get<double>();
      o.min_centre_dots = l.at("min_centre_dots").get<int>();
      o.min_dots = l.at("min_dots").get<int>();
      o.smoothing = l.at("smoothing").get<double>();
      o.degree = l.at("degree").get<int>();
      o.table_step = l.at("table_step").get<int>();
      std::vector<GridDot> dots;
      for (const nlohmann::json& d : l.at("dots")) {
        GridDot g;
        g.col = d.at(0).get<int>(), g.row = d.at(1).get<int>();
        g.centre = {d.at(2).get<double>(), d.at(3).get<double>()};
        dots.push_back(g);
      }
      const std::string id = c.at("id").get<std::string>();
      LensCorrection lens;
      if (!dots.empty()) {
        auto fitted = LensCorrection::fit(dots, l.at("width").get<int>(), l.at("height").get<int>(), o);
        if (!fitted.ok()) return bad("camera '" + id + "': " + fitted.status().message());
        lens = *fitted;
        lens.set_dots_found(l.at("dots_found").get<int>());
      }
      std::array<std::array<Eigen::Vector2d, 2>, 4> markers{};
      const nlohmann::json& m = c.at("markers");
      if (!m.is_array() || m.size() != 4) return bad("camera '" + id + "': four poles' markers expected");
      for (size_t p = 0; p < 4; ++p)
        for (size_t i = 0; i < 2; ++i)
          if (!read_vec(m[p].at(i), &markers[p][i])) return bad("camera '" + id + "': a marker is not [x, y]");
      const FrameSide side = c.at("side").get<std::string>() == "back" ? FrameSide::kBack : FrameSide::kFront;
      auto cam =
          camera_from_markers(id, c.at("width").get<int>(), c.at("height").get<int>(), cal.frame, lens, side, markers);
      if (!cam.ok()) return bad(cam.status().message());
      cal.cameras.push_back(*cam);
      cal.lasers_seen.push_back(c.at("lasers_seen").get<std::vector<int>>());
    }
    for (const nlohmann::json& s : j.at("sightings")) {
      LaserSighting ls;
      ls.laser = s.at("laser").get<int>();
      ls.step = s.at("step").get<int>();
      ls.camera = s.at("camera").get<size_t>();
      if (ls.camera >= cal.cameras.size()) return bad("a laser sighting names a camera that is not there");
      const auto n = s.at("normal").get<std::array<double, 3>>();
      RETURN_IF_ERROR(complete_plane(cal.cameras[ls.camera], Eigen::Vector3d(n[0], n[1], n[2]),
                                     s.at("offset").get<double>(), &ls.plane));
      cal.sightings.push_back(ls);
    }
    return cal;
  } catch (const nlohmann::json::exception& e) {
    return bad(std::string("a field is missing or of the wrong type (") + e.what() + ")");
  }
}

// --- the frames: ScanProcessor's records, binary ------------------------------

namespace {

// The last byte is the format: '2' holds the stripe samples as extracted (a replay
// smooths them), '1' (before 2026-11-27) as smoothed then (a replay takes them so).
constexpr char kMagic[8] = {'B', 'S', 'S', 'T', 'R', 'I', 'P', '2'};
constexpr size_t kFormatByte = sizeof kMagic - 1;

class Writer {
 public:
  template <typename T>
  void put(T v) {
    const size_t n = out_.size();
    out_.resize(n + sizeof(T));
    std::memcpy(out_.data() + n, &v, sizeof(T));
  }
  void put(const Eigen::Vector2d& v) { put(v.x()), put(v.y()); }
  void put(const Eigen::Vector3d& v) { put(v.x()), put(v.y()), put(v.z()); }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view b) : b_(b) {}
  template <typename T>
  bool get(T* v) {
    if (b_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool get(Eigen::Vector2d* v) { return get(&v->x()) && get(&v->y()); }
  bool get(Eigen::Vector3d* v) { return get(&v->x()) && get(&v->y()) && get(&v->z()); }
  bool done() const { return pos_ == b_.size(); }

 private:
  std::string_view b_;
  size_t pos_ = 0;
};

}  // namespace

std::string ScanProcessor::recording() const {
  Writer w;
  w.put(static_cast<uint64_t>(stats_.frames));
  w.put(static_cast<uint64_t>(stats_.frames_unseen));
  w.put(static_cast<uint64_t>(stats_.frames_without_plane));
  w.put(static_cast<uint64_t>(stats_.far_bottom_estimated));
  w.put(static_cast<uint64_t>(stats_.samples));
  w.put(fourth_ss_);
  w.put(static_cast<uint64_t>(fourth_n_));
  w.put(static_cast<uint64_t>(records_.size()));
  for (const FrameRecord& r : records_) {
    w.put(static_cast<uint32_t>(r.camera));
    w.put(static_cast<int32_t>(r.laser)), w.put(static_cast<int32_t>(r.step)), w.put(static_cast<int32_t>(r.frame));
    w.put(static_cast<int32_t>(r.full_scale));
    w.put(static_cast<uint8_t>(r.has_plane));
    const LaserPlane& p = r.plane;
    w.put(p.normal), w.put(p.offset), w.put(p.fourth_point_mm);
    for (const PoleStripe& s : p.poles) {
      w.put(static_cast<uint8_t>((s.found ? 1 : 0) | (s.used ? 2 : 0) | (s.estimated ? 4 : 0)));
      w.put(s.pixel), w.put(s.world), w.put(s.peak);
    }
    for (int k = 0; k < 9; ++k) w.put(p.image_to_plane(k));
    w.put(p.origin), w.put(p.axis_a), w.put(p.axis_b);
    w.put(static_cast<uint32_t>(r.others.size()));
    for (const LaserState& o : r.others) w.put(static_cast<int32_t>(o.laser)), w.put(static_cast<int32_t>(o.step));
    w.put(static_cast<uint32_t>(r.samples.size()));
    // Column by column: rows climb by one, so their differences compress to nothing.
    int prev = 0;
    for (const StripeSample& s : r.samples) w.put(static_cast<int16_t>(s.row - prev)), prev = s.row;
    for (const StripeSample& s : r.samples) w.put(s.column);
    for (const StripeSample& s : r.samples) w.put(s.peak);
    for (const StripeSample& s : r.samples) w.put(static_cast<uint8_t>(s.saturated));
  }
  const std::string& raw = w.bytes();
  uLongf packed_size = compressBound(raw.size());
  std::string out(sizeof kMagic + 8 + packed_size, '\0');
  std::memcpy(out.data(), kMagic, sizeof kMagic);
  // A format-1 record replayed and recorded again stays format 1: its samples are
  // the smoothed ones.
  if (samples_smoothed_) out[kFormatByte] = '1';
  const uint64_t n = raw.size();
  std::memcpy(out.data() + sizeof kMagic, &n, 8);
  compress2(reinterpret_cast<Bytef*>(out.data() + sizeof kMagic + 8), &packed_size,
            reinterpret_cast<const Bytef*>(raw.data()), raw.size(), 6);
  out.resize(sizeof kMagic + 8 + packed_size);
  return out;
}

Status ScanProcessor::load_recording(std::string_view bytes) {
  auto bad = [](const std::string& what) { return invalid_argument("scan record: " + what); };
  if (bytes.size() < sizeof kMagic + 8 || std::memcmp(bytes.data(), kMagic, kFormatByte) != 0)
    return bad("not a bodyscan stripe record");
  const char format = bytes[kFormatByte];
  if (format != '1' && format != '2')
    return bad(std::string("format ") + format + " is not one this build reads (1 and 2)");
  uint64_t n = 0;
  std::memcpy(&n, bytes.data() + sizeof kMagic, 8);
  if (n > (uint64_t{1} << 34)) return bad("its size field is impossible");
  std::string raw(n, '\0');
  uLongf raw_size = n;
  if (uncompress(reinterpret_cast<Bytef*>(raw.data()), &raw_size,
                 reinterpret_cast<const Bytef*>(bytes.data() + sizeof kMagic + 8),
                 bytes.size() - sizeof kMagic - 8) != Z_OK ||
      raw_size != n)
    return bad("the compressed data is damaged");
  Reader rd(raw);
  uint64_t frames, unseen, without, far, samples, fourth_n, count;
  double fourth_ss;
  if (!rd.get(&frames) || !rd.get(&unseen) || !rd.get(&without) || !rd.get(&far) || !rd.get(&samples) ||
      !rd.get(&fourth_ss) || !rd.get(&fourth_n) || !rd.get(&count))
    return bad("cut short");
  std::vector<FrameRecord> records;
  for (uint64_t i = 0; i < count; ++i) {
    FrameRecord r;
    uint32_t camera, others, nsamples;
    int32_t laser, step, frame, full_scale;
    uint8_t has_plane;
    if (!rd.get(&camera) || !rd.get(&laser) || !rd.get(&step) || !rd.get(&frame) || !rd.get(&full_scale) ||
        !rd.get(&has_plane))
      return bad("cut short");
    if (camera >= cal_.cameras.size()) return bad("a frame names a camera the calibration does not have");
    r.camera = camera, r.laser = laser, r.step = step, r.frame = frame, r.full_scale = full_scale;
    r.has_plane = has_plane != 0;
    LaserPlane& p = r.plane;
    if (!rd.get(&p.normal) || !rd.get(&p.offset) || !rd.get(&p.fourth_point_mm)) return bad("cut short");
    for (PoleStripe& s : p.poles) {
      uint8_t flags;
      if (!rd.get(&flags) || !rd.get(&s.pixel) || !rd.get(&s.world) || !rd.get(&s.peak)) return bad("cut short");
      s.found = flags & 1, s.used = flags & 2, s.estimated = flags & 4;
    }
    for (int k = 0; k < 9; ++k)
      if (!rd.get(&p.image_to_plane(k))) return bad("cut short");
    if (!rd.get(&p.origin) || !rd.get(&p.axis_a) || !rd.get(&p.axis_b) || !rd.get(&others)) return bad("cut short");
    for (uint32_t k = 0; k < others; ++k) {
      LaserState o;
      int32_t l, s;
      if (!rd.get(&l) || !rd.get(&s)) return bad("cut short");
      o.laser = l, o.step = s;
      r.others.push_back(o);
    }
    if (!rd.get(&nsamples) || nsamples > (1u << 20)) return bad("cut short");
    r.samples.resize(nsamples);
    int row = 0;
    for (StripeSample& s : r.samples) {
      int16_t d;
      if (!rd.get(&d)) return bad("cut short");
      s.row = row += d;
    }
    for (StripeSample& s : r.samples)
      if (!rd.get(&s.column)) return bad("cut short");
    for (StripeSample& s : r.samples)
      if (!rd.get(&s.peak)) return bad("cut short");
    for (StripeSample& s : r.samples) {
      uint8_t sat;
      if (!rd.get(&sat)) return bad("cut short");
      s.saturated = sat != 0;
    }
    records.push_back(std::move(r));
  }
  if (!rd.done()) return bad("trailing bytes");
  records_ = std::move(records);
  samples_smoothed_ = format == '1';
  stats_ = {};
  stats_.frames = frames, stats_.frames_unseen = unseen, stats_.frames_without_plane = without;
  stats_.far_bottom_estimated = far, stats_.samples = samples;
  fourth_ss_ = fourth_ss;
  fourth_n_ = fourth_n;
  if (fourth_n_ > 0) stats_.fourth_point_rms_mm = std::sqrt(fourth_ss_ / static_cast<double>(fourth_n_));
  return Status::Ok();
}

}  // namespace bodyscan::pipeline
