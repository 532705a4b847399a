// How faithfully the simulated rig renders a laser stripe where a camera sees the
// surface at a grazing angle, and what that does to the points: the shipped renderer
// against a reference that integrates each pixel over its area (K x K rays, each with
// its own hit, plane distance and shadow) and then spreads the light with the lens's
// point spread in the image, as optics do, across silhouettes too.
//
// Both images are noise-free; the stripe is extracted from each as the scan does
// (brightest pixel, centroid within the radius), each sample's ray is met with the
// true laser plane, and the point's signed distance to the true body (outside +) is
// binned by the angle the camera sees the surface at. A bias that grows with the
// angle in one renderer and not the other is the renderer's.
//
//   stripe_fidelity [--rig NAME|FILE] [--body BODY.ply] [--every N] [--sub K] [--radius PX]
//   [--noisy [--smooth N]] [--json OUT.json]
//
// --json also writes all cameras' errors by view (bench/json_figures.hpp) for
// bench/tables.py.
//
// --noisy compares the noise-free image with the frame a camera delivers (sensor
// noise, speckle, its pixel format), extracted against a base frame and smoothed
// along the stripe exactly as the scan does, still with the true camera and plane:
// what the frame itself costs, apart from calibration.
//
// Each table also counts the points more than 2 and 4 mm off the skin, and a second
// table sorts the same points by where their sample lies along its stripe: the end
// of a run of consecutive rows (the next row has no sample, or one more than
// 1.5 px across: where the stripe fades, leaves the body or goes behind a limb),
// the row next to an end, or further in. With --noisy, the runs' ends are sorted
// further: by their run's length (a run of one row is a lone sample, which the scan
// drops: drop_short_runs), by their peak against the median of the run's next six,
// and by how far their raw column lies off the line through those six.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "hw/rig_description.hpp"
#include "hw/sim/renderer.hpp"
#include "hw/sim/sim_rig.hpp"
#include "recon/geometry/mesh_distance.hpp"
#include "recon/io/ply.hpp"
#include "recon/scan/stripe.hpp"

#include <tbb/parallel_for.h>

using namespace bodyscan;
using namespace bodyscan::hw;
using namespace bodyscan::hw::sim;

namespace {

struct Bins {
  std::vector<double> edges{0, 30, 45, 60, 70, 75, 80, 85, 90.01};
  std::vector<std::vector<double>> all = std::vector<std::vector<double>>(edges.size() - 1);
  void add(double view, double err) {
    for (size_t b = 0; b + 1 < edges.size(); ++b)
      if (view >= edges[b] && view < edges[b + 1]) {
        all[b].push_back(err);
        return;
      }
  }
  void print(const char* label) const {
    std::printf("  %s: view (deg), signed mean (mm), median, |err| p50 / p90, samples, over 2 / 4 mm\n", label);
    for (size_t b = 0; b + 1 < edges.size(); ++b) {
      if (all[b].empty()) continue;
      std::printf("    %2.0f-%2.0f  ", edges[b], edges[b + 1]);
      print_row(all[b]);
    }
  }
  // Signed mean, median, |err| p50 / p90, count, and how many are over 2 and 4 mm.
  static nlohmann::json stats(std::vector<double> v) {
    std::vector<double> a;
    double s = 0;
    for (double e : v) a.push_back(std::abs(e)), s += e;
    std::sort(v.begin(), v.end());
    std::sort(a.begin(), a.end());
    const auto over = [&](double mm) { return a.end() - std::upper_bound(a.begin(), a.end(), mm); };
    return {{"signed_mean_mm", s / static_cast<double>(v.size())},
            {"median_mm", v[v.size() / 2]},
            {"abs_p50_mm", a[a.size() / 2]},
            {"abs_p90_mm", a[a.size() * 9 / 10]},
            {"samples", v.size()},
            {"over_2mm", over(2)},
            {"over_4mm", over(4)}};
  }
  static void print_row(const std::vector<double>& v) {
    const nlohmann::json j = stats(v);
    std::printf("%+.3f  %+.3f  %.3f / %.3f  %zu  %td / %td\n", j["signed_mean_mm"].get<double>(),
                j["median_mm"].get<double>(), j["abs_p50_mm"].get<double>(), j["abs_p90_mm"].get<double>(),
                j["samples"].get<size_t>(), j["over_2mm"].get<ptrdiff_t>(), j["over_4mm"].get<ptrdiff_t>());
  }
  // Per view bin with samples: its edges and stats.
  nlohmann::json to_json() const {
    nlohmann::json out = nlohmann::json::array();
    for (size_t b = 0; b + 1 < edges.size(); ++b) {
      if (all[b].empty()) continue;
      nlohmann::json j = stats(all[b]);
      j["view_from_deg"] = edges[b];
      j["view_to_deg"] = std::min(90.0, edges[b + 1]);
      out.push_back(std::move(j));
    }
    return out;
  }
};

// The same errors by where the sample lies along its run of consecutive rows.
struct RunBins {
  std::vector<double> by[3];  // at a run's end, next to it, further in
  void add(int from_end, double err) { by[std::min(from_end, 2)].push_back(err); }
  void print(const char* label) const {
    static const char* const names[3] = {"run end", "next row", "inside"};
    std::printf("  %s by place on the stripe: signed mean (mm), median, |err| p50 / p90, samples, over 2 / 4 mm\n",
                label);
    for (int k = 0; k < 3; ++k) {
      if (by[k].empty()) continue;
      std::printf("    %-9s ", names[k]);
      Bins::print_row(by[k]);
    }
  }
};

// The runs' last samples by two things the raw record keeps: the peak against the
// median peak of the run's next 6 samples, and the raw column's distance from the
// straight line through those 6 samples, extrapolated to the end's row (px).
struct EndFeatures {
  std::vector<double> ratio_edges{0, 0.3, 0.5, 0.7, 0.85, 1.0, 1e9};
  std::vector<double> resid_edges{0, 0.2, 0.4, 0.7, 1.0, 1.5, 1e9};
  std::vector<std::vector<double>> by_ratio = std::vector<std::vector<double>>(6);
  std::vector<std::vector<double>> by_resid = std::vector<std::vector<double>>(6);
  std::vector<std::vector<double>> both = std::vector<std::vector<double>>(36);
  std::vector<std::vector<double>> by_length = std::vector<std::vector<double>>(5);  // 1, 2, 3-5, 6-10, 11+
  static size_t bin(const std::vector<double>& e, double v) {
    for (size_t b = 0; b + 1 < e.size(); ++b)
      if (v < e[b + 1]) return b;
    return e.size() - 2;
  }
  void add(double ratio, double resid, double err) {
    const size_t a = bin(ratio_edges, ratio), b = bin(resid_edges, std::abs(resid));
    by_ratio[a].push_back(err);
    by_resid[b].push_back(err);
    both[a * 6 + b].push_back(err);
  }
  void add_length(int length, double err) {
    by_length[length <= 2 ? length - 1 : length <= 5 ? 2 : length <= 10 ? 3 : 4].push_back(err);
  }
  void print() const {
    static const char* const lengths[5] = {"1", "2", "3-5", "6-10", "11+"};
    std::printf("  run ends by their run's length (rows): signed mean, median, |err| p50 / p90, n, over 2 / 4\n");
    for (size_t b = 0; b < 5; ++b)
      if (!by_length[b].empty()) std::printf("    %-6s ", lengths[b]), Bins::print_row(by_length[b]);
    std::printf("  run ends by peak / the run's median peak: signed mean, median, |err| p50 / p90, n, over 2 / 4\n");
    for (size_t b = 0; b < 6; ++b)
      if (!by_ratio[b].empty())
        std::printf("    %.2f-%.2f  ", ratio_edges[b], std::min(9.0, ratio_edges[b + 1])), Bins::print_row(by_ratio[b]);
    std::printf("  run ends by |raw column - the run's line| (px)\n");
    for (size_t b = 0; b < 6; ++b)
      if (!by_resid[b].empty())
        std::printf("    %.2f-%.2f  ", resid_edges[b], std::min(9.0, resid_edges[b + 1])), Bins::print_row(by_resid[b]);
    std::printf("  over 2 mm / n, rows peak ratio, columns residual\n");
    for (size_t a = 0; a < 6; ++a) {
      std::printf("    %.2f-%.2f ", ratio_edges[a], std::min(9.0, ratio_edges[a + 1]));
      for (size_t b = 0; b < 6; ++b) {
        const auto& v = both[a * 6 + b];
        size_t o = 0;
        for (double e : v) o += std::abs(e) > 2;
        std::printf(" %4zu/%-5zu", o, v.size());
      }
      std::printf("\n");
    }
  }
};

// Rows from each sample to the nearer end of its run: consecutive rows whose
// columns differ by at most max_step px (smooth_stripe's continuation rule).
std::vector<int> rows_from_run_end(const std::vector<StripeSample>& s, double max_step = 1.5) {
  const auto continues = [&](size_t a, size_t b) {
    return s[b].row - s[a].row == 1 && std::abs(s[b].column - s[a].column) <= max_step;
  };
  std::vector<int> out(s.size(), 0);
  for (size_t i = 1; i < s.size(); ++i) out[i] = continues(i - 1, i) ? out[i - 1] + 1 : 0;
  int after = 0;
  for (size_t i = s.size(); i-- > 0;) {
    after = i + 1 < s.size() && continues(i, i + 1) ? after + 1 : 0;
    out[i] = std::min(out[i], after);
  }
  return out;
}

// The laser radiance seen along the ray through image point (px, py), before the
// lens's spread and the pixel's integration. The sub-ray's own footprint (1/k of a
// pixel) on the tangent plane widens the profile as a box: at that scale the
// surface is flat enough for it.
double laser_radiance(const Scene& scene, const CameraModel& model, const LaserDescription& l, int step, double px,
                      double py, int k) {
  const Vec3d n = l.plane_normal(step);
  const double offset = l.plane_offset(step), sigma = l.line_width_mm / 2.354820045;
  const Vec3d aim = Eigen::AngleAxisd(step * l.step_angle_deg * M_PI / 180.0, l.axis) * l.aim;
  const auto r = model.ray(Vec2d(px, py));
  if (!r) return 0;
  const Hit h = scene.intersect(model.centre(), *r);
  if (h.surface != Surface::kSubject && h.surface != Surface::kFrame) return 0;
  const double d = n.dot(h.position) - offset;
  if (std::abs(d) > 40) return 0;
  auto on_tangent = [&](double qx, double qy) -> Vec3d {
    const auto rn = model.ray(Vec2d(qx, qy));
    if (!rn) return h.position;
    const double den = rn->dot(h.normal);
    if (std::abs(den) < 1e-9) return h.position;
    return model.centre() + ((h.position - model.centre()).dot(h.normal) / den) * *rn;
  };
  const double e = 0.5 / k;
  const double gx = n.dot(on_tangent(px + e, py) - on_tangent(px - e, py));
  const double gy = n.dot(on_tangent(px, py + e) - on_tangent(px, py - e));
  const double var = sigma * sigma + (gx * gx + gy * gy) / 12.0;
  if (d * d > 25 * var) return 0;
  const Vec3d to_laser = l.position - h.position;
  const double dist = to_laser.norm();
  if (aim.dot(-to_laser) <= 0) return 0;
  const Vec3d toward = to_laser / dist;
  const double incidence = h.normal.dot(toward);
  if (incidence <= 0) return 0;
  if (scene.occluded(h.position + 0.05 * h.normal, toward, dist)) return 0;
  const double a = h.surface == Surface::kSubject ? 0.65 : 0.92;
  return l.power * a * incidence * (sigma / std::sqrt(var)) * std::exp(-0.5 * d * d / var);
}

// The weight of a point u pixels from a pixel's centre in that pixel's value: the
// pixel's box convolved with the lens's Gaussian spread (one axis).
double box_gauss(double u, double s) {
  if (s <= 0) return std::abs(u) <= 0.5 ? 1.0 : 0.0;
  return 0.5 * (std::erf((u + 0.5) / (s * M_SQRT2)) - std::erf((u - 0.5) / (s * M_SQRT2)));
}

std::vector<uint16_t> to_pixels(const std::vector<float>& img) {
  std::vector<uint16_t> out(img.size());
  for (size_t i = 0; i < img.size(); ++i) out[i] = static_cast<uint16_t>(std::clamp(img[i] * 20000.0f, 0.f, 65535.f));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string rig_name = "tiered", body;
  int every = 12, sub = 8, radius = 4;
  bool noisy = false;
  int smooth = 3;
  CommandLine cl("stripe_fidelity",
                 "usage: stripe_fidelity [--rig NAME|FILE] [--body BODY.ply] [--every N] [--sub K] [--radius PX] "
                 "[--noisy [--smooth N]] [--json OUT]\n");
  cl.option("--rig", &rig_name);
  cl.option("--body", &body);
  cl.option("--every", integer_between(1, 1000000, [&every](long long n) { every = static_cast<int>(n); }));
  cl.option("--sub", integer_between(1, 64, [&sub](long long n) { sub = static_cast<int>(n); }));
  cl.option("--radius", integer_between(1, 64, [&radius](long long n) { radius = static_cast<int>(n); }));
  cl.flag("--noisy", &noisy);
  std::string json_out;
  cl.option("--json", &json_out);
  cl.option("--smooth", integer_between(0, 1000, [&smooth](long long n) { smooth = static_cast<int>(n); }));
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);  // the tree as the run starts
  std::string path = rig_name;
  if (rig_name.find('/') == std::string::npos && rig_name.find(".json") == std::string::npos) {
    auto p = shipped_rig_path(rig_name);
    if (!p.ok()) return std::fprintf(stderr, "%s\n", p.status().message().c_str()), 1;
    path = *p;
  }
  auto desc = load_rig_description(path);
  if (!desc.ok()) return std::fprintf(stderr, "%s\n", desc.status().message().c_str()), 1;
  StatusOr<std::unique_ptr<SimulatedRig>> rig = internal_error("unset");
  if (body.empty()) {
    rig = SimulatedRig::create(*desc);
  } else {
    auto mesh = read_ply_mesh(body);
    if (!mesh.ok()) return std::fprintf(stderr, "%s\n", mesh.status().message().c_str()), 1;
    rig = SimulatedRig::create(*desc, *mesh);
  }
  if (!rig.ok()) return std::fprintf(stderr, "%s\n", rig.status().message().c_str()), 1;
  const Scene& scene = (*rig)->scene();
  const MeshDistance truth(scene.subject());
  std::printf("rig %s, body %s, every %d steps, %dx%d rays per pixel, centroid radius %d\n", desc->name.c_str(),
              body.empty() ? "(the rig's)" : body.c_str(), every, sub, sub, radius);
  Bins shipped_all, reference_all;
  RunBins shipped_runs, reference_runs;
  EndFeatures end_features;
  for (size_t c = 0; c < desc->cameras.size(); ++c) {
    const CameraDescription& cam = desc->cameras[c];
    const Renderer& renderer = (*rig)->renderer(c);
    const CameraModel& model = renderer.model();
    const int w = cam.width, h = cam.height;
    Bins shipped, reference;
    for (const LaserDescription& l : desc->lasers) {
      for (int step = l.min_step; step <= l.max_step; step += every) {
        Lighting lit;
        lit.lasers.push_back({&l, step});
        std::vector<float> with = renderer.irradiance(scene, lit);
        const std::vector<float> without = renderer.irradiance(scene, Lighting{});
        std::vector<float> shipped_img(with.size()), ref_img(with.size(), 0.f);
        std::vector<uint8_t> lit_mask(with.size(), 0);
        for (size_t i = 0; i < with.size(); ++i) {
          shipped_img[i] = std::max(0.f, with[i] - without[i]);
          lit_mask[i] = shipped_img[i] > 1e-4f;
        }
        if (!noisy) {
          // The reference: the radiance on a k-times finer grid around the stripe, each
          // pixel then the integral of it against the box convolved with the spread.
          const int k = sub, sw = w * k;
          const int reach = static_cast<int>(std::ceil(3 * cam.blur_px + 0.5));
          std::vector<uint8_t> want(with.size(), 0);
          for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
              if (!lit_mask[static_cast<size_t>(y) * w + x]) continue;
              for (int dy = -3 - reach; dy <= 3 + reach; ++dy)
                for (int dx = -3 - reach; dx <= 3 + reach; ++dx) {
                  const int xx = x + dx, yy = y + dy;
                  if (xx >= 0 && yy >= 0 && xx < w && yy < h) want[static_cast<size_t>(yy) * w + xx] = 1;
                }
            }
          std::vector<float> fine(static_cast<size_t>(sw) * h * k, 0.f);
          tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
              if (!want[static_cast<size_t>(y) * w + x]) continue;
              for (int j = 0; j < k; ++j)
                for (int i = 0; i < k; ++i)
                  fine[static_cast<size_t>(y * k + j) * sw + x * k + i] = static_cast<float>(
                      laser_radiance(scene, model, l, step, x - 0.5 + (i + 0.5) / k, y - 0.5 + (j + 0.5) / k, k));
            }
          });
          std::vector<double> wt(static_cast<size_t>((2 * reach + 1) * k));
          for (int q = 0; q < static_cast<int>(wt.size()); ++q)
            wt[static_cast<size_t>(q)] = box_gauss(-reach - 0.5 + (q + 0.5) / k, cam.blur_px) / k;
          tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
              const int lo_x = x - reach, lo_y = y - reach;
              bool near = false;
              for (int dy = -3; dy <= 3 && !near; ++dy)
                for (int dx = -3; dx <= 3 && !near; ++dx) {
                  const int xx = x + dx, yy = y + dy;
                  near = xx >= 0 && yy >= 0 && xx < w && yy < h && lit_mask[static_cast<size_t>(yy) * w + xx];
                }
              if (!near) continue;
              double acc = 0;
              for (int qy = 0; qy < static_cast<int>(wt.size()); ++qy) {
                const int fy = lo_y * k + qy;
                if (fy < 0 || fy >= h * k) continue;
                for (int qx = 0; qx < static_cast<int>(wt.size()); ++qx) {
                  const int fx = lo_x * k + qx;
                  if (fx < 0 || fx >= sw) continue;
                  acc += wt[static_cast<size_t>(qy)] * wt[static_cast<size_t>(qx)] *
                         fine[static_cast<size_t>(fy) * sw + fx];
                }
              }
              ref_img[static_cast<size_t>(y) * w + x] = static_cast<float>(acc);
            }
          });
        }
        const std::vector<uint16_t> zero(with.size(), 0);
        const ImageView base{zero.data(), w, h};
        StripeOptions so;
        so.radius = radius;
        so.threshold = 40;
        for (int which = 0; which < 2; ++which) {
          StatusOr<std::vector<StripeSample>> samples = internal_error("unset");
          std::vector<StripeSample> raw;
          if (which == 1 && noisy) {
            // As the scan sees it: the camera's frame against the base frame taken
            // with the lasers off, its threshold, smoothed along the stripe.
            Exposure e;
            e.format = cam.pixel_format;
            e.exposure_us = cam.exposure_us;
            e.gain_db = cam.gain_db;
            const uint64_t frame_id = 1000 + static_cast<uint64_t>(step - l.min_step);
            const Frame f = renderer.render(scene, lit, e, frame_id),
                        b0 = renderer.render(scene, Lighting{}, e, frame_id + 777);
            StripeOptions pso;
            pso.radius = radius;
            samples =
                extract_stripe(ImageView{f.pixels.data(), w, h}, ImageView{b0.pixels.data(), w, h}, pso, f.max_value());
            if (samples.ok()) raw = *samples;
            if (samples.ok() && smooth > 0) smooth_stripe(*samples, smooth);
          } else {
            const std::vector<uint16_t> px = to_pixels(which == 0 ? shipped_img : ref_img);
            samples = extract_stripe(ImageView{px.data(), w, h}, base, so, 1 << 30);
          }
          if (!samples.ok()) continue;
          const Vec3d n = l.plane_normal(step);
          const double off = l.plane_offset(step);
          const std::vector<int> from_end = rows_from_run_end(*samples);
          // Each raw run end's features (the raw and smoothed samples are row for row).
          std::vector<double> ratio(raw.size(), -1), resid(raw.size(), 0);
          std::vector<int> run_length(raw.size(), 0);
          std::vector<uint8_t> at_end(raw.size(), 0);
          if (!raw.empty()) {
            // Each raw sample's run length (the smoothing's continuation rule).
            size_t a = 0;
            for (size_t i = 1; i <= raw.size(); ++i)
              if (i == raw.size() || raw[i].row - raw[i - 1].row != 1 ||
                  std::abs(raw[i].column - raw[i - 1].column) > 1.5) {
                for (size_t j = a; j < i; ++j) run_length[j] = static_cast<int>(i - a);
                at_end[a] = at_end[i - 1] = 1;
                a = i;
              }
          }
          if (!raw.empty()) {
            const std::vector<int> raw_end = rows_from_run_end(raw);
            for (size_t i = 0; i < raw.size(); ++i) {
              if (raw_end[i] != 0) continue;
              for (int dir : {-1, 1}) {
                std::vector<size_t> in;
                for (long j = static_cast<long>(i) + dir; j >= 0 && j < static_cast<long>(raw.size()) && in.size() < 6;
                     j += dir) {
                  const size_t pj = in.empty() ? i : in.back();
                  if (std::abs(raw[j].row - raw[pj].row) != 1 || std::abs(raw[j].column - raw[pj].column) > 1.5) break;
                  in.push_back(static_cast<size_t>(j));
                }
                if (in.size() < 6) continue;
                std::vector<double> pk;
                double s0 = 0, s1 = 0, s2 = 0, t0 = 0, t1 = 0;
                for (size_t j : in) {
                  pk.push_back(raw[j].peak);
                  const double r = raw[j].row - raw[i].row, col = raw[j].column;
                  s0 += 1, s1 += r, s2 += r * r, t0 += col, t1 += r * col;
                }
                std::sort(pk.begin(), pk.end());
                const double med = 0.5 * (pk[2] + pk[3]);
                const double det = s0 * s2 - s1 * s1;
                ratio[i] = raw[i].peak / std::max(1.0, med);
                resid[i] = raw[i].column - (t0 * s2 - s1 * t1) / det;
              }
            }
          }
          for (size_t si = 0; si < samples->size(); ++si) {
            const StripeSample& s = (*samples)[si];
            const auto r = model.ray(Vec2d(s.column, s.row));
            if (!r) continue;
            const double den = n.dot(*r);
            if (std::abs(den) < 1e-9) continue;
            const double t = (off - n.dot(model.centre())) / den;
            if (t <= 0) continue;
            const Vec3d p = model.centre() + t * *r;
            const ClosestPoint cp = truth.closest_point(p.cast<float>());
            if (cp.distance > 10) continue;  // the frame, or lost
            const Triangle& tri = scene.subject().triangles[cp.triangle];
            const auto& v = scene.subject().vertices;
            const Vec3d nn = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]).cast<double>().normalized();
            const Vec3d to_cam = (model.centre() - p).normalized();
            const double view = std::acos(std::min(1.0, std::abs(nn.dot(to_cam)))) * 180 / M_PI;
            (which == 0 ? shipped : reference).add(view, cp.signed_distance);
            (which == 0 ? shipped_all : reference_all).add(view, cp.signed_distance);
            (which == 0 ? shipped_runs : reference_runs).add(from_end[si], cp.signed_distance);
            if (which == 1 && noisy && si < run_length.size() && at_end[si])
              end_features.add_length(run_length[si], cp.signed_distance);
            if (which == 1 && noisy && si < ratio.size() && ratio[si] >= 0)
              end_features.add(ratio[si], resid[si], cp.signed_distance);
          }
        }
      }
    }
    std::printf("camera %s\n", cam.id.c_str());
    shipped.print("shipped");
    reference.print(noisy ? "frames" : "reference");
    std::fflush(stdout);
  }
  std::printf("all cameras\n");
  shipped_all.print("shipped");
  reference_all.print(noisy ? "frames" : "reference");
  shipped_runs.print("shipped");
  reference_runs.print(noisy ? "frames" : "reference");
  if (noisy) end_features.print();
  if (!json_out.empty()) {
    const nlohmann::json record = {
        {"rig", desc->name},
        {"body", std::filesystem::path(body.empty() ? desc->simulation.subject : body).stem().string()},
        {"every", every},
        {"sub", sub},
        {"noisy", noisy},
        {"renderer", shipped_all.to_json()},
        {"reference", reference_all.to_json()}};
    if (!bench::write_figures(json_out, run_info, nlohmann::json::array({record}))) return 1;
  }
  return 0;
}
