#include "hw/sim/scene.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace bodyscan::hw::sim {

struct Scene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  RTCGeometry subject = nullptr;
  std::vector<Surface> surface_of;  // geometry id -> surface
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void add_box(const Vec3d& lo, const Vec3d& hi, std::vector<Vec3f>& v, std::vector<Triangle>& t) {
  const uint32_t base = static_cast<uint32_t>(v.size());
  for (int i = 0; i < 8; ++i) {
    v.emplace_back(static_cast<float>((i & 1) ? hi.x() : lo.x()), static_cast<float>((i & 2) ? hi.y() : lo.y()),
                   static_cast<float>((i & 4) ? hi.z() : lo.z()));
  }
  const uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) t.push_back({base + f[0], base + f[1], base + f[2]});
}

RTCGeometry attach_mesh(RTCDevice device, RTCScene scene, const std::vector<Vec3f>& vertices,
                        const std::vector<Triangle>& triangles, RTCBuildQuality quality) {
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(g, quality);
  auto* vb = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices.size()));
  for (size_t i = 0; i < vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = vertices[i][k];
  auto* ib = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles.size()));
  for (size_t i = 0; i < triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) ib[3 * i + k] = triangles[i][k];
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  // The scene holds its own reference: the handle stays valid as long as the
  // scene, and the geometry goes with it.
  rtcReleaseGeometry(g);
  return g;
}

}  // namespace

Scene::~Scene() = default;

StatusOr<std::unique_ptr<Scene>> Scene::create(const RigDescription& rig, const TriangleMesh& subject) {
  std::unique_ptr<Scene> s(new Scene());
  static std::atomic<uint64_t> next_version{1};
  s->version_ = next_version.fetch_add(1ull << 32);  // each scene its own range
  s->rig_ = rig;
  s->rt_ = std::make_unique<Embree>();
  Embree& e = *s->rt_;
  e.device = rtcNewDevice(nullptr);
  if (!e.device)
    return internal_error("the ray tracer (Embree) could not start: error " +
                          std::to_string(rtcGetDeviceError(nullptr)));
  e.scene = rtcNewScene(e.device);
  rtcSetSceneFlags(e.scene, RTC_SCENE_FLAG_DYNAMIC);

  // The subject, stood on the floor, turned and moved as described.
  if (!subject.triangles.empty()) {
    if (!subject.is_consistent()) return invalid_argument("the subject mesh has an index out of range");
    TriangleMesh m = subject;
    Vec3d centre = Vec3d::Zero();
    double min_y = std::numeric_limits<double>::max(), max_y = std::numeric_limits<double>::lowest();
    for (const Vec3f& v : m.vertices) {
      centre += v.cast<double>();
      min_y = std::min(min_y, static_cast<double>(v.y()));
      max_y = std::max(max_y, static_cast<double>(v.y()));
    }
    centre /= static_cast<double>(m.vertices.size());
    const double yaw = rig.simulation.subject_yaw_deg * M_PI / 180.0;
    const Eigen::AngleAxisd turn(yaw, Vec3d::UnitY());
    const Vec3d shift(-centre.x(), s->floor_y() - min_y, -centre.z());
    for (Vec3f& v : m.vertices) {
      Vec3d p = v.cast<double>() + shift;
      p = turn * p + rig.simulation.subject_offset;
      v = p.cast<float>();
    }
    s->body_axis_ = rig.simulation.subject_offset;
    // Breathing moves the chest: a band around 72 % of the height, within a torso's
    // radius of the vertical axis, outward from the axis.
    const double h = max_y - min_y;
    s->breathing_weight_.resize(m.vertices.size());
    for (size_t i = 0; i < m.vertices.size(); ++i) {
      const Vec3d p = m.vertices[i].cast<double>() - s->body_axis_;
      const double u = (p.y() - s->floor_y() - 0.72 * h) / (0.1 * h);
      const double radial = std::hypot(p.x(), p.z());
      const double band = std::abs(u) < 1 ? std::pow(std::cos(0.5 * M_PI * u), 2) : 0.0;
      s->breathing_weight_[i] = radial < 0.15 * h ? static_cast<float>(band) : 0.f;
    }
    s->rest_ = m;
    s->posed_ = m;
    e.subject = attach_mesh(e.device, e.scene, m.vertices, m.triangles, RTC_BUILD_QUALITY_REFIT);
    e.surface_of.push_back(Surface::kSubject);
  }

  // The frames: front, back and side poles of square tubing, light centres on the
  // poles' centre lines (bottom frame at Y = 0, top at top_height).
  const FrameGeometry& f = rig.frame;
  const double a = 0.5 * f.tube, hw = 0.5 * f.width, hd = 0.5 * f.depth;
  for (double y : {0.0, f.top_height}) {
    for (double z : {-hd, hd})
      add_box(Vec3d(-hw - a, y - a, z - a), Vec3d(hw + a, y + a, z + a), s->frame_vertices_, s->frame_triangles_);
    for (double x : {-hw, hw})
      add_box(Vec3d(x - a, y - a, -hd + a), Vec3d(x + a, y + a, hd - a), s->frame_vertices_, s->frame_triangles_);
  }
  attach_mesh(e.device, e.scene, s->frame_vertices_, s->frame_triangles_, RTC_BUILD_QUALITY_HIGH);
  e.surface_of.push_back(Surface::kFrame);
  // The floor, 20 m square.
  const float fy = static_cast<float>(s->floor_y());
  attach_mesh(e.device, e.scene, {{-1e4f, fy, -1e4f}, {1e4f, fy, -1e4f}, {-1e4f, fy, 1e4f}, {1e4f, fy, 1e4f}},
              {{0, 2, 1}, {1, 2, 3}}, RTC_BUILD_QUALITY_HIGH);
  e.surface_of.push_back(Surface::kFloor);
  rtcCommitScene(e.scene);
  if (rtcGetDeviceError(e.device) != RTC_ERROR_NONE) return internal_error("the ray tracer (Embree) refused the scene");
  return s;
}

bool Scene::moves() const {
  const SubjectMotion& m = rig_.simulation.motion;
  return rt_->subject && (m.sway_mm > 0 || m.breathing_mm > 0);
}

Vec3d subject_sway(const SubjectMotion& m, double time_s) {
  const double w = 2 * M_PI * m.sway_hz * time_s;
  return {m.sway_mm * std::sin(w), 0, 0.5 * m.sway_mm * std::sin(w + 1.3)};
}

void Scene::set_time(double time_s) {
  if (time_s == time_ && time_s != 0) return;
  time_ = time_s;
  if (!moves()) return;
  const SubjectMotion& m = rig_.simulation.motion;
  const Vec3d sway = subject_sway(m, time_s);
  const double breath = 0.5 * m.breathing_mm * (1 - std::cos(2 * M_PI * m.breathing_hz * time_s));
  auto* vb = static_cast<float*>(rtcGetGeometryBufferData(rt_->subject, RTC_BUFFER_TYPE_VERTEX, 0));
  for (size_t i = 0; i < rest_.vertices.size(); ++i) {
    Vec3d p = rest_.vertices[i].cast<double>();
    if (breathing_weight_[i] > 0) {
      Vec3d out(p.x() - body_axis_.x(), 0, p.z() - body_axis_.z());
      const double r = out.norm();
      if (r > 1e-9) p += (breath * breathing_weight_[i] / r) * out;
    }
    p += sway;
    posed_.vertices[i] = p.cast<float>();
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = posed_.vertices[i][k];
  }
  rtcUpdateGeometryBuffer(rt_->subject, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(rt_->subject);
  rtcCommitScene(rt_->scene);
  ++version_;
}

Hit Scene::intersect(const Vec3d& origin, const Vec3d& dir, double t_min, double t_max) const {
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(dir.x());
  rh.ray.dir_y = static_cast<float>(dir.y());
  rh.ray.dir_z = static_cast<float>(dir.z());
  rh.ray.tnear = static_cast<float>(t_min);
  rh.ray.tfar = static_cast<float>(std::min(t_max, 1e30));
  rh.ray.mask = 0xffffffffu;
  rh.ray.flags = 0;
  rh.ray.time = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcIntersect1(rt_->scene, &ctx, &rh);
  Hit h;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
  h.surface = rt_->surface_of[rh.hit.geomID];
  // Refine the hit point in double from the float distance: one step along the
  // exact ray, so the position is on the ray to double precision.
  h.t = rh.ray.tfar;
  h.position = origin + h.t * dir;
  Vec3d n(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  n.normalize();
  if (n.dot(dir) > 0) n = -n;
  h.normal = n;
  return h;
}

bool Scene::occluded(const Vec3d& origin, const Vec3d& dir, double t_max) const {
  RTCRay ray;
  ray.org_x = static_cast<float>(origin.x());
  ray.org_y = static_cast<float>(origin.y());
  ray.org_z = static_cast<float>(origin.z());
  ray.dir_x = static_cast<float>(dir.x());
  ray.dir_y = static_cast<float>(dir.y());
  ray.dir_z = static_cast<float>(dir.z());
  ray.tnear = 1e-2f;
  ray.tfar = static_cast<float>(t_max);
  ray.mask = 0xffffffffu;
  ray.flags = 0;
  ray.time = 0;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcOccluded1(rt_->scene, &ctx, &ray);
  return ray.tfar < 0;
}

}  // namespace bodyscan::hw::sim
