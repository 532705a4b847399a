#include "hw/sim/renderer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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
    : camera_(camera), sim_(sim), model_(camera.model()) {}

const std::vector<Vec3f>& Renderer::rays() const {
  // Isolated: while it waits for its rows, the thread inside call_once must not pick
  // up another task that could ask for these rays again (a deadlock).
  std::call_once(rays_once_, [this] {
    rays_.assign(static_cast<size_t>(camera_.width) * camera_.height, Vec3f::Zero());
    tbb::this_task_arena::isolate([this] {
      tbb::parallel_for(0, camera_.height, [this](int y) {
        for (int x = 0; x < camera_.width; ++x) {
          const auto r = model_.ray(Vec2d(x, y));
          if (r) rays_[static_cast<size_t>(y) * camera_.width + x] = r->cast<float>();
        }
      });
    });
  });
  return rays_;
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

// The room, ambient and frame lights reaching the camera through pixel (x, y); the
// lasers are drawn by Renderer::add_laser_light.
template <typename CachedHit>
double light_at(const Scene& scene, const Lighting& lighting, const SimulationDescription& sim,
                const CameraModel& model, const std::vector<Vec3f>& rays, const CachedHit& cached, int width, int x,
                int y) {
  const Vec3f& rf = rays[static_cast<size_t>(y) * width + x];
  if (rf.isZero()) return 0;
  const Vec3d r = rf.cast<double>();
  const Vec3d& c = model.centre();
  Hit h;
  h.surface = cached.surface;
  h.position = cached.position.template cast<double>();
  h.normal = cached.normal.template cast<double>();
  const double ambient = lighting.room_lights ? sim.room_light : sim.ambient_light;
  if (h.surface == Surface::kNone) return 0.05 * ambient;  // the room beyond the rig
  const double a = albedo(h.surface);
  double out = a * ambient * (0.35 + 0.65 * std::abs(h.normal.dot(r)));

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
    out += sum / 16;
  }
  return out;
}

}  // namespace

std::vector<float> Renderer::irradiance(const Scene& scene, const Lighting& lighting) const {
  std::vector<float> out = base_irradiance(scene, lighting);
  add_laser_light(scene, lighting, out, 0, 0);
  return out;
}

namespace {

// The fraction of light arriving u pixels (along one axis) from a pixel's centre
// that the pixel collects: its box convolved with the lens's Gaussian spread.
double box_gauss(double u, double sigma) {
  if (sigma <= 0) return std::abs(u) < 0.5 ? 1.0 : (std::abs(u) == 0.5 ? 0.5 : 0.0);
  return 0.5 * (std::erf((u + 0.5) / (sigma * M_SQRT2)) - std::erf((u - 0.5) / (sigma * M_SQRT2)));
}

}  // namespace

void Renderer::add_laser_light(const Scene& scene, const Lighting& lighting, std::vector<float>& out,
                               uint64_t speckle_seed, double speckle_contrast) const {
  const std::vector<LaserPlane> planes = laser_planes(lighting);
  if (planes.empty()) return;
  const int w = camera_.width, h = camera_.height;
  if (w < 2 || h < 2) return;
  const std::vector<CachedHit>& hit = hits(scene);
  const std::vector<Vec3f>& pixel_rays = rays();
  const Vec3d& c = model_.centre();
  constexpr int k = kLaserSubpixels;
  const double psf = camera_.blur_px;
  // The lens's reach, pixels: 3 sigma and half a pixel (at most 7, as a 16-wide
  // block holds; a spread of over 2 pixels is no machine-vision lens).
  const int reach = psf > 0 ? std::min(7, static_cast<int>(std::ceil(3 * psf + 0.5))) : 0;
  const int span = 2 * reach + 1;

  // 1. The pixels that can hold laser light: those whose surface lies near a plane
  // for its footprint there (a dot product rules most out first). Where the surface
  // is its tangent plane over the pixel and its neighbours (within kFlatMm), the
  // light across the pixel follows from the centre's hit; elsewhere (silhouettes,
  // steps in depth, grazing curved skin) every sub-pixel ray is cast. A pixel beside
  // a near one across a silhouette or a step is cast too: the stripe may reach past
  // its centre ray.
  constexpr double kFlatMm = 0.25;
  enum : uint8_t { kFlat = 1, kCast = 2 };
  const size_t npx = static_cast<size_t>(w) * h;
  std::vector<uint8_t> near(npx, 0);
  std::vector<std::vector<int>> near_in_row(static_cast<size_t>(h));
  std::vector<Eigen::Vector4f> plane_f;  // the planes in float, for the first cut
  for (const LaserPlane& lp : planes)
    plane_f.emplace_back(lp.normal.cast<float>().x(), lp.normal.cast<float>().y(), lp.normal.cast<float>().z(),
                         static_cast<float>(lp.offset));
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const CachedHit& ch = hit[i];
      if (ch.surface == Surface::kNone) continue;
      bool coarse = false;
      for (size_t pi = 0; pi < planes.size(); ++pi)
        coarse = coarse || std::abs(plane_f[pi].head<3>().dot(ch.position) - plane_f[pi].w()) <
                               static_cast<float>(4 * planes[pi].sigma + 60);
      if (!coarse) continue;
      const Vec3d p = ch.position.cast<double>(), n = ch.normal.cast<double>(), r = pixel_rays[i].cast<double>();
      const double footprint = (p - c).norm() / model_.fx() / std::max(0.05, std::abs(n.dot(r)));
      for (const LaserPlane& lp : planes)
        if (std::abs(lp.normal.dot(p) - lp.offset) < 4 * lp.sigma + 2 * footprint) near[i] = 1;
      if (near[i]) near_in_row[static_cast<size_t>(y)].push_back(x);
    }
  });
  auto range = [&](size_t i) { return (hit[i].position.cast<double>() - c).norm(); };
  auto step_between = [&](size_t a, size_t b) {
    if (hit[a].surface != hit[b].surface) return true;
    if (hit[a].surface == Surface::kNone) return false;
    const double da = range(a), db = range(b);
    return std::abs(da - db) > 0.02 * std::min(da, db);  // 2 % of the range: a step, not a slope
  };
  // Per row, the pixels to draw and how.
  std::vector<std::vector<std::pair<int, uint8_t>>> take(static_cast<size_t>(h));
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<int> cand;
    for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
      for (int x : near_in_row[static_cast<size_t>(yy)])
        for (int dx = -1; dx <= 1; ++dx)
          if (x + dx >= 0 && x + dx < w) cand.push_back(x + dx);
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    for (int x : cand) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (near[i]) {
        bool flat = x > 0 && y > 0 && x + 1 < w && y + 1 < h;
        const Vec3d p = hit[i].position.cast<double>(), n = hit[i].normal.cast<double>();
        for (const size_t j : {i - 1, i + 1, i - w, i + w}) {
          if (!flat) break;
          flat = hit[j].surface == hit[i].surface && std::abs(n.dot(hit[j].position.cast<double>() - p)) < kFlatMm;
        }
        take[static_cast<size_t>(y)].emplace_back(x, flat ? kFlat : kCast);
        continue;
      }
      bool cast = false;
      for (int dy = -1; dy <= 1 && !cast; ++dy)
        for (int dx = -1; dx <= 1 && !cast; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const size_t j = static_cast<size_t>(yy) * w + xx;
          cast = near[j] && step_between(i, j);
        }
      if (cast) take[static_cast<size_t>(y)].emplace_back(x, kCast);
    }
  });

  // 2. Each such pixel: the laser light over k x k points of its area, then what
  // that light gives the pixels within the lens's reach (the spread acts before the
  // sensor samples, so a stripe on a silhouette spills past it as in a camera).
  // Kept per source row: the lit pixels' columns, and for each the span x span
  // light it gives the pixels round it (row-major, centred on it), one after another.
  std::vector<std::vector<int>> lit_x(static_cast<size_t>(h));
  std::vector<std::vector<float>> spill(static_cast<size_t>(h));
  const size_t block = static_cast<size_t>(span) * span;
  std::vector<double> weight(static_cast<size_t>(span * k));  // [offset + reach][sub]
  for (int o = -reach; o <= reach; ++o)
    for (int sidx = 0; sidx < k; ++sidx)
      weight[static_cast<size_t>((o + reach) * k + sidx)] = box_gauss(-0.5 + (sidx + 0.5) / k - o, psf) / k;
  // The light of the planes at a surface point, for a sample whose area spans ex
  // and ey (mm) on the surface, with a shadow ray of its own toward each laser
  // whose light arrives.
  // How squarely plane p's laser lights a surface point: 0 where it does not (the
  // point behind its fan, lit from the other side, or in shadow).
  auto incidence_of = [&](const LaserPlane& p, const Vec3d& position, const Vec3d& normal) {
    const Vec3d to_laser = p.laser->position - position;
    if (p.aim.dot(-to_laser) <= 0) return 0.0;  // behind the laser's fan
    const Vec3d toward = to_laser.normalized();
    const double incidence = normal.dot(toward);
    if (incidence <= 0) return 0.0;  // the laser lights the other side
    if (scene.occluded(position + 0.05 * normal, toward, to_laser.norm())) return 0.0;  // laser shadow
    return incidence;
  };
  auto point_light = [&](const Vec3d& position, const Vec3d& normal, Surface surface, const Vec3d& ex,
                         const Vec3d& ey) {
    double v = 0;
    for (const LaserPlane& p : planes) {
      const double d = p.normal.dot(position) - p.offset;
      const double gx = p.normal.dot(ex), gy = p.normal.dot(ey);
      const double var = p.sigma * p.sigma + (gx * gx + gy * gy) / 12.0;
      if (d * d > 16 * var) continue;
      const double incidence = incidence_of(p, position, normal);
      if (incidence <= 0) continue;
      v += p.laser->power * albedo(surface) * incidence * (p.sigma / std::sqrt(var)) * std::exp(-0.5 * d * d / var);
    }
    return v;
  };
  // Where the ray r + (u dx + v dy) meets the plane through `at` with normal n,
  // to first order in (u, v): the surface's step per unit of u and of v.
  auto tangent_steps = [&](const Vec3d& at, const Vec3d& n, const Vec3d& r, const Vec3d& dx, const Vec3d& dy, Vec3d& ex,
                           Vec3d& ey) {
    const double nr = n.dot(r);
    if (std::abs(nr) < 1e-6) {
      ex = ey = Vec3d::Zero();
      return;
    }
    const double t = (at - c).dot(n) / nr;
    ex = t * (dx - r * (n.dot(dx) / nr));
    ey = t * (dy - r * (n.dot(dy) / nr));
  };
  tbb::parallel_for(0, h, [&](int y) {
    std::array<double, k * k> fine;
    for (const auto& [x, how] : take[static_cast<size_t>(y)]) {
      const size_t pix = static_cast<size_t>(y) * w + x;
      // The pixel's ray and its change per pixel (the lens's distortion is smooth
      // over a pixel, so sub-pixel rays are linear in the offset).
      const auto ray_at = [&](int xx, int yy) {
        return pixel_rays[static_cast<size_t>(std::clamp(yy, 0, h - 1)) * w + std::clamp(xx, 0, w - 1)].cast<double>();
      };
      const Vec3d r0 = ray_at(x, y);
      if (r0.isZero()) continue;
      const Vec3d drx = 0.5 * (ray_at(x + 1, y) - ray_at(x - 1, y)), dry = 0.5 * (ray_at(x, y + 1) - ray_at(x, y - 1));
      if (how == kFlat) {
        // The tangent plane at the centre's hit: the plane distance is linear over
        // the pixel; incidence and shadow are the centre's.
        const Vec3d hp = hit[pix].position.cast<double>(), hn = hit[pix].normal.cast<double>();
        Vec3d ex, ey;
        tangent_steps(hp, hn, r0, drx, dry, ex, ey);
        fine.fill(0);
        for (const LaserPlane& p : planes) {
          const double gx = p.normal.dot(ex), gy = p.normal.dot(ey);  // plane distance per pixel
          const double dc = p.normal.dot(hp) - p.offset;
          const double var = p.sigma * p.sigma + (gx * gx + gy * gy) / (12.0 * k * k);
          if (std::abs(dc) - 0.5 * (std::abs(gx) + std::abs(gy)) > 4 * std::sqrt(var)) continue;
          const double incidence = incidence_of(p, hp, hn);
          if (incidence <= 0) continue;
          const double peak = p.laser->power * albedo(hit[pix].surface) * incidence * (p.sigma / std::sqrt(var));
          for (int j = 0; j < k; ++j)
            for (int i = 0; i < k; ++i) {
              const double d = dc + gx * (-0.5 + (i + 0.5) / k) + gy * (-0.5 + (j + 0.5) / k);
              fine[static_cast<size_t>(j * k + i)] += peak * std::exp(-0.5 * d * d / var);
            }
        }
      } else {
        // Every sub-pixel ray cast, each with its own hit and shadow.
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i) {
            double& v = fine[static_cast<size_t>(j * k + i)];
            v = 0;
            const double u = -0.5 + (i + 0.5) / k, t = -0.5 + (j + 0.5) / k;
            const Vec3d r = (r0 + u * drx + t * dry).normalized();
            const Hit hh = scene.intersect(c, r);
            if (hh.surface == Surface::kNone) continue;
            Vec3d ex, ey;
            tangent_steps(hh.position, hh.normal, r, drx / k, dry / k, ex, ey);
            v = point_light(hh.position, hh.normal, hh.surface, ex, ey);
          }
      }
      bool any = false;
      for (double v : fine) any = any || v > 0;
      if (!any) continue;
      // Separable: across first (each sub-row to each column offset), then down.
      std::array<double, k * 16> across;  // [sub-row][column offset], span <= 16
      for (int j = 0; j < k; ++j)
        for (int ox = 0; ox < span; ++ox) {
          double a = 0;
          for (int i = 0; i < k; ++i)
            a += weight[static_cast<size_t>(ox * k + i)] * fine[static_cast<size_t>(j * k + i)];
          across[static_cast<size_t>(j * 16 + ox)] = a;
        }
      std::vector<float>& out_row = spill[static_cast<size_t>(y)];
      lit_x[static_cast<size_t>(y)].push_back(x);
      for (int oy = 0; oy < span; ++oy)
        for (int ox = 0; ox < span; ++ox) {
          double a = 0;
          for (int j = 0; j < k; ++j)
            a += weight[static_cast<size_t>(oy * k + j)] * across[static_cast<size_t>(j * 16 + ox)];
          out_row.push_back(static_cast<float>(a));
        }
    }
  });

  // 3. Gathered row by row (no two threads write one pixel), with speckle: the
  // coherent light's grain, fixed per pixel for a frame.
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<float> acc;
    int lo = w, hi = -1;
    for (int sy = std::max(0, y - reach); sy <= std::min(h - 1, y + reach); ++sy) {
      const int oy = y - sy + reach;  // this row's offset from the source pixel's
      const std::vector<int>& xs = lit_x[static_cast<size_t>(sy)];
      for (size_t b = 0; b < xs.size(); ++b) {
        if (acc.empty()) acc.assign(static_cast<size_t>(w), 0.f);
        const float* from = spill[static_cast<size_t>(sy)].data() + b * block + static_cast<size_t>(oy * span);
        for (int ox = 0; ox < span; ++ox) {
          const int x = xs[b] + ox - reach;
          if (x < 0 || x >= w) continue;
          acc[static_cast<size_t>(x)] += from[ox];
          lo = std::min(lo, x), hi = std::max(hi, x);
        }
      }
    }
    for (int x = lo; x <= hi; ++x) {
      double v = acc[static_cast<size_t>(x)];
      if (v <= 0) continue;
      const size_t i = static_cast<size_t>(y) * w + x;
      if (speckle_contrast > 0) v *= std::max(0.0, 1.0 + speckle_contrast * standard_normal(speckle_seed ^ mix(i)));
      out[i] += static_cast<float>(v);
    }
  });
}

namespace {

// The lens's Gaussian, normalised, 3 sigma either side (at least one pixel).
std::vector<float> blur_kernel(double sigma) {
  const int r = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<float> k(static_cast<size_t>(2 * r + 1));
  float sum = 0;
  for (int i = -r; i <= r; ++i)
    sum += k[static_cast<size_t>(i + r)] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
  for (float& v : k) v /= sum;
  return k;
}

// The blur's two passes over columns x0..x1 of row y (edges clamp). The whole
// image and a moving subject's part of it (Renderer::base_irradiance) go through
// the same code, so a part redrawn is what the whole would have been to the bit.
void blur_across(const std::vector<float>& in, std::vector<float>& out, int w, int y, const std::vector<float>& k,
                 int x0, int x1) {
  const int r = static_cast<int>(k.size() / 2);
  const float* row = in.data() + static_cast<size_t>(y) * w;
  float* o = out.data() + static_cast<size_t>(y) * w;
  for (int x = x0; x <= x1; ++x) {
    float acc = 0;
    for (int i = -r; i <= r; ++i) acc += k[static_cast<size_t>(i + r)] * row[std::clamp(x + i, 0, w - 1)];
    o[x] = acc;
  }
}
void blur_down(const std::vector<float>& in, std::vector<float>& out, int w, int h, int y, const std::vector<float>& k,
               int x0, int x1) {
  const int r = static_cast<int>(k.size() / 2);
  float* o = out.data() + static_cast<size_t>(y) * w;
  for (int x = x0; x <= x1; ++x) o[x] = 0;
  for (int i = -r; i <= r; ++i) {
    const float* row = in.data() + static_cast<size_t>(std::clamp(y + i, 0, h - 1)) * w;
    const float kk = k[static_cast<size_t>(i + r)];
    for (int x = x0; x <= x1; ++x) o[x] += kk * row[x];
  }
}

// Spans of columns (first, last): the spans of rows y - reach .. y + reach, each
// widened by `widen` within 0 .. w - 1, overlapping and touching ones joined.
using Spans = std::vector<std::pair<int, int>>;
Spans spans_near(const std::vector<Spans>& rows, int y, int reach, int widen, int w) {
  Spans out;
  const int h = static_cast<int>(rows.size());
  for (int yy = std::max(0, y - reach); yy <= std::min(h - 1, y + reach); ++yy)
    for (const auto& [a, b] : rows[static_cast<size_t>(yy)])
      out.emplace_back(std::max(0, a - widen), std::min(w - 1, b + widen));
  std::sort(out.begin(), out.end());
  size_t m = 0;
  for (const auto& sp : out) {
    if (m > 0 && sp.first <= out[m - 1].second + 1)
      out[m - 1].second = std::max(out[m - 1].second, sp.second);
    else
      out[m++] = sp;
  }
  out.resize(m);
  return out;
}

// Both passes over the whole image, rows then columns; `across` keeps the first
// (`out` may be `in`).
void blur_image(const std::vector<float>& in, std::vector<float>& across, std::vector<float>& out, int w, int h,
                const std::vector<float>& k) {
  across.resize(in.size());
  out.resize(in.size());
  tbb::parallel_for(0, h, [&](int y) { blur_across(in, across, w, y, k, 0, w - 1); });
  tbb::parallel_for(0, h, [&](int y) { blur_down(across, out, w, h, y, k, 0, w - 1); });
}

}  // namespace

void blur(std::vector<float>& img, int w, int h, double sigma) {
  if (sigma <= 0) return;
  std::vector<float> tmp;
  blur_image(img, tmp, img, w, h, blur_kernel(sigma));
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
  std::vector<float> irradiance = base_irradiance(scene, lighting);
  const uint64_t seed = mix(sim_.seed ^ mix(frame_number) ^ mix(std::hash<std::string>()(camera_.id)));
  add_laser_light(scene, lighting, irradiance, seed, sim_.speckle_contrast);
  return expose(irradiance, camera_, exposure, seed);
}

const std::vector<float>& Renderer::base_irradiance(const Scene& scene, const Lighting& lighting) const {
  const std::vector<Vec3f>& pixel_rays = rays();
  const std::vector<CachedHit>& hit = hits(scene);
  std::lock_guard<std::mutex> lock(cache_mutex_);
  const int key =
      (lighting.room_lights ? 1 : 0) | (lighting.front_frame_lights ? 2 : 0) | (lighting.back_frame_lights ? 4 : 0);
  BaseCache& cache = base_[key];
  if (cache.version == scene.version() && !cache.irradiance.empty()) return cache.irradiance;
  const int w = camera_.width, h = camera_.height;
  const size_t n = static_cast<size_t>(w) * h;
  auto light = [&](int y, int x0, int x1) {
    for (int x = x0; x <= x1; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      cache.unblurred[i] = static_cast<float>(light_at(scene, lighting, sim_, model_, pixel_rays, hit[i], w, x, y));
    }
  };
  const bool blurs = camera_.blur_px > 0;
  const std::vector<float> k = blurs ? blur_kernel(camera_.blur_px) : std::vector<float>{1.f};
  const int r = static_cast<int>(k.size() / 2);
  // The same scene posed anew: only the part of the image hits() casts again as the
  // subject moves can change, and the blur carries that change r pixels farther.
  // A swaying scan drew the whole image's room and frame lights (each frame light's
  // pixels with 16 rays) and blurred it for every camera at every frame.
  if (moving_.size() == static_cast<size_t>(h) && moving_range_ == (scene.version() >> 32) &&
      cache.unblurred.size() == n && (cache.version >> 32) == (scene.version() >> 32)) {
    tbb::parallel_for(0, h, [&](int y) {
      // A row's spans all drawn before any is blurred across: two spans may lie
      // within the blur's reach of each other.
      const Spans& spans = moving_[static_cast<size_t>(y)];
      for (const auto& [a, b] : spans) light(y, a, b);
      if (blurs)
        for (const auto& [a, b] : spans)
          blur_across(cache.unblurred, cache.across, w, y, k, std::max(0, a - r), std::min(w - 1, b + r));
    });
    tbb::parallel_for(0, h, [&](int y) {
      for (const auto& [a, b] : spans_near(moving_, y, r, r, w)) {
        if (blurs) {
          blur_down(cache.across, cache.irradiance, w, h, y, k, a, b);
        } else {
          const size_t row = static_cast<size_t>(y) * w;
          std::copy(cache.unblurred.begin() + static_cast<std::ptrdiff_t>(row + a),
                    cache.unblurred.begin() + static_cast<std::ptrdiff_t>(row + b + 1),
                    cache.irradiance.begin() + static_cast<std::ptrdiff_t>(row + a));
        }
      }
    });
    cache.version = scene.version();
    return cache.irradiance;
  }
  // The whole image; a moving scene keeps the unblurred image and the blur's first
  // pass for the next pose.
  cache.unblurred.assign(n, 0.f);
  tbb::parallel_for(0, h, [&](int y) { light(y, 0, w - 1); });
  if (blurs)
    blur_image(cache.unblurred, cache.across, cache.irradiance, w, h, k);
  else
    cache.irradiance = cache.unblurred;
  if (!scene.moves()) {
    cache.unblurred = {};
    cache.across = {};
  }
  cache.version = scene.version();
  return cache.irradiance;
}

void Renderer::forget_lights() {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  for (BaseCache& c : base_) c = BaseCache{};
}

const std::vector<Renderer::CachedHit>& Renderer::hits(const Scene& scene) const {
  const std::vector<Vec3f>& pixel_rays = rays();
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (hits_version_ == scene.version() && !hits_.empty()) return hits_;
  const int w = camera_.width, h = camera_.height;
  const size_t n = static_cast<size_t>(w) * h;
  auto cast = [&](size_t i) {
    if (pixel_rays[i].isZero()) return;
    const Hit hh = scene.intersect(model_.centre(), pixel_rays[i].cast<double>());
    hits_[i] = {hh.position.cast<float>(), hh.normal.cast<float>(), hh.surface};
  };
  // The same scene posed anew (each scene numbers its versions in a range of its
  // own): only the subject moved, by at most its whole motion's range, so only
  // pixels that saw it, or lie within that range of one that did, can change. A
  // swaying subject covers a fifth of the image; the frames and floor stay put.
  if (hits_.size() == n && (hits_version_ >> 32) == (scene.version() >> 32)) {
    const SubjectMotion& m = scene.rig().simulation.motion;
    const double motion_mm = 2 * (1.12 * m.sway_mm + m.breathing_mm) + 1;
    // Per row, the runs of pixels that saw the subject, and the nearest of them.
    std::vector<Spans> runs(static_cast<size_t>(h));
    std::vector<double> nearest_in(static_cast<size_t>(h), std::numeric_limits<double>::infinity());
    tbb::parallel_for(0, h, [&](int y) {
      Spans& row = runs[static_cast<size_t>(y)];
      for (int x = 0; x < w; ++x) {
        const CachedHit& c = hits_[static_cast<size_t>(y) * w + x];
        if (c.surface != Surface::kSubject) continue;
        if (!row.empty() && row.back().second == x - 1)
          row.back().second = x;
        else
          row.emplace_back(x, x);
        nearest_in[static_cast<size_t>(y)] =
            std::min(nearest_in[static_cast<size_t>(y)], (c.position.cast<double>() - model_.centre()).norm());
      }
    });
    const double nearest = *std::min_element(nearest_in.begin(), nearest_in.end());
    if (std::isfinite(nearest)) {
      const int reach = static_cast<int>(std::ceil(motion_mm * model_.fx() / nearest)) + 1;
      // Any two poses differ only within the motion's range, so these spans hold
      // every pixel that can differ between any two poses: base_irradiance redraws
      // only them.
      moving_.assign(static_cast<size_t>(h), {});
      tbb::parallel_for(0, h, [&](int y) {
        moving_[static_cast<size_t>(y)] = spans_near(runs, y, reach, reach, w);
        for (const auto& [a, b] : moving_[static_cast<size_t>(y)])
          for (int x = a; x <= b; ++x) cast(static_cast<size_t>(y) * w + x);
      });
      moving_range_ = scene.version() >> 32;
      hits_version_ = scene.version();
      return hits_;
    }
  }
  moving_.clear();
  hits_.assign(n, CachedHit{});
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) cast(static_cast<size_t>(y) * w + x);
  });
  hits_version_ = scene.version();
  return hits_;
}

}  // namespace bodyscan::hw::sim
