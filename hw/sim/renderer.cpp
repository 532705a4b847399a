#include "hw/sim/renderer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace bodyscan::hw::sim {

namespace {

constexpr double kReferenceExposureUs = 10000;

double albedo(Surface s) {
  switch (s) {
    case Surface::kSubject: return 0.65;  // skin and underwear
    case Surface::kFrame: return 0.92;    // white tubing
    case Surface::kFloor: return 0.25;
    case Surface::kNone: return 0.0;
  }
  return 0.0;
}

struct Light {
  double base = 0;   // room, ambient and frame lights
  double laser = 0;  // laser stripes (speckled)
};

uint64_t mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A standard normal deviate for a key: 2^16 fixed deviates drawn once, picked by a
// hash of the key. Frames need millions per frame; drawing them afresh each time
// cost more than the rest of the rendering.
const std::vector<float>& normal_table() {
  static const std::vector<float> table = [] {
    std::vector<float> t(1 << 16);
    std::mt19937_64 rng(20091);
    std::normal_distribution<float> n;
    for (float& v : t) v = n(rng);
    return t;
  }();
  return table;
}
double standard_normal(uint64_t key) { return normal_table()[mix(key) & 0xffff]; }

}  // namespace

Renderer::Renderer(const CameraDescription& camera, const SimulationDescription& sim)
    : camera_(camera), sim_(sim), model_(camera.model()) {
  rays_.assign(static_cast<size_t>(camera.width) * camera.height, Vec3f::Zero());
  tbb::parallel_for(0, camera.height, [&](int y) {
    for (int x = 0; x < camera.width; ++x) {
      const auto r = model_.ray(Vec2d(x, y));
      if (r) rays_[static_cast<size_t>(y) * camera.width + x] = r->cast<float>();
    }
  });
}

Hit Renderer::surface_at(const Scene& scene, const Vec2d& pixel) const {
  const auto r = model_.ray(pixel);
  if (!r) return {};
  return scene.intersect(model_.centre(), *r);
}

namespace {

// The light reaching a surface point through pixel (x, y).
// An active laser's plane, worked out once per frame.
struct LaserPlane {
  const LaserDescription* laser;
  Vec3d normal, aim;
  double offset, sigma;
};
std::vector<LaserPlane> laser_planes(const Lighting& lighting) {
  std::vector<LaserPlane> out;
  for (const ActiveLaser& al : lighting.lasers) {
    const LaserDescription& l = *al.laser;
    out.push_back({&l, l.plane_normal(al.step),
                   Eigen::AngleAxisd(al.step * l.step_angle_deg * M_PI / 180.0, l.axis) * l.aim,
                   l.plane_offset(al.step), l.line_width_mm / 2.354820045});
  }
  return out;
}

// What a frame light emits toward the camera at a surface point, as a fraction of full
// scale (0 off the lights). With `margin` > 0, any point within that many mm of a
// light counts (returns 1): a test for pixels that need sub-pixel sampling.
double frame_light_emission(const FrameGeometry& f, const Lighting& lighting, const SimulationDescription& sim,
                            const Hit& h, double margin) {
  if (h.surface != Surface::kFrame || std::abs(h.normal.z()) <= 0.99) return 0;
  if (!(h.position.z() > 0 ? lighting.front_frame_lights : lighting.back_frame_lights)) return 0;
  // The lights sit on both Z faces of the front and back poles (not on the side
  // poles, whose faces point along X and Y).
  const double face = std::abs(std::abs(h.position.z()) - 0.5 * f.depth);
  if (std::abs(face - 0.5 * f.tube) >= 1.0) return 0;
  const double radius = 0.5 * f.light_diameter;
  double out = 0;
  for (double ly : {0.0, f.top_height})
    for (double lx : f.light_x) {
      const double rho = std::hypot(h.position.x() - lx, h.position.y() - ly);
      bool dead = false;
      for (const Vec3d& d : lighting.dead_lights)
        dead = dead || (std::abs(d.x() - lx) < 1 && std::abs(d.y() - ly) < 1 && std::abs(d.z() - h.position.z()) < 1);
      if (dead) continue;
      if (margin > 0) {
        if (rho < radius + margin) return 1;
      } else if (rho < radius) {
        // A diffuser: even in the middle, falling off over its outer fifth.
        const double edge = std::clamp((radius - rho) / (0.2 * radius), 0.0, 1.0);
        out += sim.frame_light * edge * edge * (3 - 2 * edge);
      }
    }
  return out;
}

template <typename CachedHit>
Light light_at(const Scene& scene, const Lighting& lighting, const std::vector<LaserPlane>& lasers,
               const SimulationDescription& sim, const CameraModel& model, const std::vector<Vec3f>& rays,
               const CachedHit& cached, int width, int height, int x, int y, double psf_px) {
  Light out;
  const Vec3f& rf = rays[static_cast<size_t>(y) * width + x];
  if (rf.isZero()) return out;
  const Vec3d r = rf.cast<double>();
  const Vec3d& c = model.centre();
  Hit h;
  h.surface = cached.surface;
  h.position = cached.position.template cast<double>();
  h.normal = cached.normal.template cast<double>();
  const double ambient = lighting.room_lights ? sim.room_light : sim.ambient_light;
  if (h.surface == Surface::kNone) {
    out.base = 0.05 * ambient;  // the room beyond the rig
    return out;
  }
  const double a = albedo(h.surface);
  out.base = a * ambient * (0.35 + 0.65 * std::abs(h.normal.dot(r)));

  // Frame lights: a sensor pixel integrates over its area, so pixels near a light
  // average 4 x 4 sub-pixel rays (point samples would put the lights' centroids off
  // by a tenth of a pixel).
  if (h.surface == Surface::kFrame && frame_light_emission(scene.rig().frame, lighting, sim, h, 10.0) > 0) {
    double sum = 0;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const auto sub = model.ray(Vec2d(x - 0.375 + 0.25 * i, y - 0.375 + 0.25 * j));
        if (!sub) continue;
        sum += frame_light_emission(scene.rig().frame, lighting, sim, scene.intersect(c, *sub), 0.0);
      }
    out.base += sum / 16;
  }

  if (!lasers.empty()) {
    // The pixel's footprint on the surface's tangent plane, for the stripe's
    // profile integrated over the pixel; needed only near a laser plane.
    const double footprint =
        (h.position - c).norm() / model.fx() / std::max(0.1, std::abs(h.normal.dot(r)));
    bool near = false;
    for (const LaserPlane& p : lasers) near = near || std::abs(p.normal.dot(h.position) - p.offset) < 4 * p.sigma + 4 * footprint;
    if (!near) return out;
    auto neighbour = [&](int nx, int ny) -> Vec3d {
      nx = std::clamp(nx, 0, width - 1);
      ny = std::clamp(ny, 0, height - 1);
      const Vec3d rn = rays[static_cast<size_t>(ny) * width + nx].cast<double>();
      const double den = rn.dot(h.normal);
      if (std::abs(den) < 1e-6) return h.position;
      return c + ((h.position - c).dot(h.normal) / den) * rn;
    };
    const Vec3d dx = neighbour(x + 1, y) - neighbour(x - 1, y), dy = neighbour(x, y + 1) - neighbour(x, y - 1);
    for (const LaserPlane& p : lasers) {
      const LaserDescription& l = *p.laser;
      const Vec3d& n = p.normal;
      const double d = n.dot(h.position) - p.offset;
      const double sigma = p.sigma;
      const double gx = 0.5 * n.dot(dx), gy = 0.5 * n.dot(dy);  // plane distance per pixel
      // The profile across the plane, widened by the pixel's footprint (a box) and
      // the lens's point spread (the frame's blur leaves the stripe alone, so that it
      // is spread before it is sampled, as in a camera).
      const double var = sigma * sigma + (gx * gx + gy * gy) * (1.0 / 12.0 + psf_px * psf_px);
      if (d * d > 16 * var) continue;
      const Vec3d to_laser = l.position - h.position;
      const double dist = to_laser.norm();
      if (p.aim.dot(-to_laser) <= 0) continue;  // behind the laser's fan
      const Vec3d toward = to_laser / dist;
      const double incidence = h.normal.dot(toward);
      if (incidence <= 0) continue;  // the laser lights the other side
      if (scene.occluded(h.position + 0.05 * h.normal, toward, dist)) continue;  // laser shadow
      out.laser += l.power * a * incidence * (sigma / std::sqrt(var)) * std::exp(-0.5 * d * d / var);
    }
  }
  return out;
}

}  // namespace

std::vector<float> Renderer::irradiance(const Scene& scene, const Lighting& lighting) const {
  const int w = camera_.width, h = camera_.height;
  std::vector<float> out = base_irradiance(scene, lighting);
  const std::vector<CachedHit>& hit = hits(scene);
  const std::vector<LaserPlane> planes = laser_planes(lighting);
  if (planes.empty()) return out;
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      out[i] += static_cast<float>(light_at(scene, lighting, planes, sim_, model_, rays_, hit[i], w, h, x, y, camera_.blur_px).laser);
    }
  });
  return out;
}

void blur(std::vector<float>& img, int w, int h, double sigma) {
  if (sigma <= 0) return;
  const int r = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<float> k(static_cast<size_t>(2 * r + 1));
  float sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[static_cast<size_t>(i + r)] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
  for (float& v : k) v /= sum;
  std::vector<float> tmp(img.size());
  // Rows, then columns; edges clamp.
  tbb::parallel_for(0, h, [&](int y) {
    const float* in = img.data() + static_cast<size_t>(y) * w;
    float* out = tmp.data() + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      float acc = 0;
      for (int i = -r; i <= r; ++i) acc += k[static_cast<size_t>(i + r)] * in[std::clamp(x + i, 0, w - 1)];
      out[x] = acc;
    }
  });
  tbb::parallel_for(0, h, [&](int y) {
    float* out = img.data() + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) out[x] = 0;
    for (int i = -r; i <= r; ++i) {
      const float* in = tmp.data() + static_cast<size_t>(std::clamp(y + i, 0, h - 1)) * w;
      const float kk = k[static_cast<size_t>(i + r)];
      for (int x = 0; x < w; ++x) out[x] += kk * in[x];
    }
  });
}

Frame expose(const std::vector<float>& irradiance, const CameraDescription& camera, const Exposure& exposure,
             uint64_t seed) {
  const int w = camera.width, h = camera.height;
  Frame frame;
  frame.width = w;
  frame.height = h;
  frame.format = exposure.format;
  frame.exposure_us = exposure.exposure_us;
  frame.gain_db = exposure.gain_db;
  frame.pixels.resize(static_cast<size_t>(w) * h);
  const double max_value = (1 << bits_per_pixel(exposure.format)) - 1;
  const double electrons_per_unit = camera.full_well_e * exposure.exposure_us / kReferenceExposureUs;
  const double dn_per_electron = std::pow(10.0, exposure.gain_db / 20.0) * max_value / camera.full_well_e;
  const float* table = normal_table().data();
  const float epu = static_cast<float>(electrons_per_unit), dpe = static_cast<float>(dn_per_electron);
  const float read = static_cast<float>(camera.read_noise_e), top = static_cast<float>(max_value);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      // One hash per pixel gives both deviates (shot and read noise).
      const uint64_t key = mix(seed ^ (static_cast<uint64_t>(i) * 0x9e3779b97f4a7c15ULL));
      float e = irradiance[i] * epu;
      e += std::sqrt(std::max(e, 0.f)) * table[key & 0xffff] + read * table[(key >> 16) & 0xffff];
      const float dn = std::clamp(std::nearbyint(e * dpe), 0.f, top);
      frame.pixels[i] = static_cast<uint16_t>(dn);
    }
  });
  return frame;
}

Frame Renderer::render(const Scene& scene, const Lighting& lighting, const Exposure& exposure,
                       uint64_t frame_number) const {
  const int w = camera_.width, h = camera_.height;
  const std::vector<CachedHit>& hit = hits(scene);
  const std::vector<LaserPlane> planes = laser_planes(lighting);
  std::vector<float> irradiance = base_irradiance(scene, lighting);
  const uint64_t seed = mix(sim_.seed ^ mix(frame_number) ^ mix(std::hash<std::string>()(camera_.id)));
  if (!planes.empty()) {
    // Only pixels whose surface lies near a laser plane can take laser light; a
    // dot product per pixel finds them (60 mm covers any pixel footprint here).
    tbb::parallel_for(0, h, [&](int y) {
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (hit[i].surface == Surface::kNone) continue;
        const Vec3d p = hit[i].position.cast<double>();
        bool near = false;
        for (const LaserPlane& lp : planes) near = near || std::abs(lp.normal.dot(p) - lp.offset) < 4 * lp.sigma + 60;
        if (!near) continue;
        const Light l = light_at(scene, lighting, planes, sim_, model_, rays_, hit[i], w, h, x, y, camera_.blur_px);
        if (l.laser > 0) {
          irradiance[i] += static_cast<float>(l.laser * std::max(0.0, 1.0 + sim_.speckle_contrast * standard_normal(seed ^ mix(i))));
        }
      }
    });
  }
  return expose(irradiance, camera_, exposure, seed);
}

const std::vector<float>& Renderer::base_irradiance(const Scene& scene, const Lighting& lighting) const {
  const std::vector<CachedHit>& hit = hits(scene);
  std::lock_guard<std::mutex> lock(cache_mutex_);
  const int key = (lighting.room_lights ? 1 : 0) | (lighting.front_frame_lights ? 2 : 0) | (lighting.back_frame_lights ? 4 : 0);
  BaseCache& cache = base_[key];
  if (cache.version == scene.version() && !cache.irradiance.empty()) return cache.irradiance;
  const int w = camera_.width, h = camera_.height;
  Lighting no_lasers = lighting;
  no_lasers.lasers.clear();
  const std::vector<LaserPlane> none;
  cache.irradiance.assign(static_cast<size_t>(w) * h, 0.f);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      cache.irradiance[i] = static_cast<float>(light_at(scene, no_lasers, none, sim_, model_, rays_, hit[i], w, h, x, y, camera_.blur_px).base);
    }
  });
  blur(cache.irradiance, w, h, camera_.blur_px);
  cache.version = scene.version();
  return cache.irradiance;
}

void Renderer::forget_lights() {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  for (BaseCache& c : base_) c.irradiance.clear();
}

const std::vector<Renderer::CachedHit>& Renderer::hits(const Scene& scene) const {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (hits_version_ == scene.version() && !hits_.empty()) return hits_;
  const int w = camera_.width, h = camera_.height;
  hits_.assign(static_cast<size_t>(w) * h, CachedHit{});
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (rays_[i].isZero()) continue;
      const Hit hh = scene.intersect(model_.centre(), rays_[i].cast<double>());
      hits_[i] = {hh.position.cast<float>(), hh.normal.cast<float>(), hh.surface};
    }
  });
  hits_version_ = scene.version();
  return hits_;
}

}  // namespace bodyscan::hw::sim
