// The scan pipeline on the simulated rig against its ground truth: calibration
// residuals (lens, markers, camera centres, laser planes), the point cloud's distance
// to the true body surface with both triangulation methods, coverage (and where the
// holes are), and the processing time from frames to points.
//
//   scan_benchmark [--rig thesis|square|FILE]... [--body BODY.ply]... [--every N] [--json OUT.json]
//
// Defaults: both shipped rigs, the rig's own demo body, every step. --json also
// writes each run's figures (bench/json_figures.hpp) for bench/tables.py: per camera
// its markers, centre and calibration bias, per method the cloud's distances to the
// truth, and the default method's coverage.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "bench/body_region.hpp"
#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "pipeline/rig_backend.hpp"
#include "pipeline/scan.hpp"
#include "recon/calib/plane_projection.hpp"
#include "recon/geometry/mesh_distance.hpp"
#include "recon/geometry/sample_surface.hpp"
#include "recon/spatial/knn_index.hpp"

using namespace bodyscan;
using Clock = std::chrono::steady_clock;

namespace {

double secs(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Distance between an estimated and the true laser plane over the part where a body
// stands (|x| < 400, |z| < 300, 0 < y < 1900): the largest of the corners'.
double plane_error(const LaserPlane& p, const hw::LaserDescription& l, int step) {
  const Eigen::Vector3d n = l.plane_normal(step);
  const double d = l.plane_offset(step);
  double worst = 0;
  for (double y : {0.0, 1900.0})
    for (double z : {-300.0, 300.0}) {
      // The point of the estimated plane at (y, z) along its normal's main axis (x).
      const double x = (p.offset - p.normal.y() * y - p.normal.z() * z) / p.normal.x();
      if (std::abs(x) > 2000) continue;
      worst = std::max(worst, std::abs(n.dot(Eigen::Vector3d(x, y, z)) - d));
    }
  return worst;
}

struct Quantiles {
  double mean = 0, p95 = 0, max = 0;
};
Quantiles quantiles(std::vector<double> v) {
  Quantiles q;
  if (v.empty()) return q;
  std::sort(v.begin(), v.end());
  for (double x : v) q.mean += x / static_cast<double>(v.size());
  q.p95 = v[static_cast<size_t>(0.95 * static_cast<double>(v.size() - 1))];
  q.max = v.back();
  return q;
}

double g_min_angle = 10;
int g_smooth = TriangulateOptions{}.smooth_rows;
int g_threshold = 0;
float g_redundant = 4;
float g_weak = -1;
int g_radius = -1;
double g_max_view = -1;
bool g_keep_sway = false;
nlohmann::json g_records = nlohmann::json::array();  // one per rig and body, for --json

int run(const std::string& rig_name, const std::string& body, int every) {
  pipeline::SimulatedSubject subject;
  subject.body = body;
  auto sim = pipeline::open_simulated_rig(rig_name, subject);
  if (!sim.ok()) return std::fprintf(stderr, "%s\n", sim.status().message().c_str()), 1;
  hw::sim::SimulatedRig& rig = **sim;
  const hw::RigDescription& desc = rig.description();
  const pipeline::Rig handle = pipeline::rig_handle(rig);
  const std::string body_path = body.empty() ? desc.simulation.subject : body;
  std::printf("\n== rig %s, body %s, every %d step(s)\n", desc.name.c_str(), body_path.c_str(), every);
  nlohmann::json record = {{"rig", desc.name},
                           {"body", std::filesystem::path(body_path).stem().string()},
                           {"every", every},
                           {"cameras", nlohmann::json::array()},
                           {"methods", nlohmann::json::array()}};

  // Calibration.
  auto t0 = Clock::now();
  pipeline::CalibrationBuilder builder(desc);
  double calib_acquire = 0;
  {
    const Status s =
        pipeline::acquire_calibration(handle, [&](pipeline::Shot&& shot) { return builder.consume(std::move(shot)); });
    if (!s.ok()) return std::fprintf(stderr, "%s\n", s.message().c_str()), 1;
    calib_acquire = secs(t0);
  }
  auto cal = builder.finish();
  if (!cal.ok()) return std::fprintf(stderr, "%s\n", cal.status().message().c_str()), 1;
  std::printf("calibration: acquisition (rendering) %.1f s, processing %.2f s\n", calib_acquire,
              cal->processing_seconds);
  for (size_t g = 0; g < cal->group_separation_mm.size(); ++g) {
    std::printf("group %zu:", g);
    for (int l : pipeline::group_lasers(desc, g))
      std::printf(" %s%s", desc.lasers[static_cast<size_t>(l)].id.c_str(),
                  cal->sweep_reversed[static_cast<size_t>(l)] ? " (reversed)" : "");
    std::printf(", planes at least %.0f mm apart at the sweep ends\n", cal->group_separation_mm[g]);
  }
  std::printf("%-12s %5s %6s %9s %9s %9s %9s %9s %9s\n", "camera", "side", "dots", "held-out", "lens-rms", "lens-max",
              "marker", "centre", "rays");
  std::printf("%-12s %5s %6s %9s %9s %9s %9s %9s %9s\n", "", "", "", "px", "px", "px", "px", "mm", "mm");
  for (size_t c = 0; c < cal->cameras.size(); ++c) {
    const CameraCalibration& cc = cal->cameras[c];
    const hw::CameraModel model = desc.cameras[c].model();
    // Lens against the truth: corrected vs the true pinhole image, up to a homography,
    // over the image on a 32-pixel grid.
    std::vector<Eigen::Vector2d> corrected, pinhole;
    for (int y = 0; y < model.height(); y += 32)
      for (int x = 0; x < model.width(); x += 32) {
        const auto u = model.undistort({(x - model.cx()) / model.fx(), (y - model.cy()) / model.fy()});
        if (!u) continue;
        corrected.push_back(cc.lens.correct({double(x), double(y)}));
        pinhole.emplace_back(model.fx() * u->x() + model.cx(), model.fy() * u->y() + model.cy());
      }
    const Eigen::Matrix3d h = *fit_homography(corrected, pinhole);
    std::vector<double> lens_err;
    for (size_t i = 0; i < corrected.size(); ++i)
      lens_err.push_back((apply_homography(h, corrected[i]) - pinhole[i]).norm());
    double lens_ss = 0;
    for (double e : lens_err) lens_ss += e * e;
    // Markers against the lights' true images.
    double marker_worst = 0;
    for (Pole p : kPoles)
      for (int i = 0; i < 2; ++i) {
        const auto truth = model.project(cc.frame.light(p, cc.side, i));
        marker_worst =
            std::max(marker_worst,
                     (cc.lens.distort(cc.markers[static_cast<size_t>(p)][static_cast<size_t>(i)]) - *truth).norm());
      }
    std::printf("%-12s %5s %6d %9.3f %9.3f %9.3f %9.3f %9.2f %9.2f\n", cc.camera_id.c_str(), to_string(cc.side),
                cc.lens.dots_used(), cc.lens.held_out_rms_px(), std::sqrt(lens_ss / lens_err.size()),
                quantiles(lens_err).max, marker_worst, (cc.centre - model.centre()).norm(), cc.ray_spread_mm);
    record["cameras"].push_back({{"camera", cc.camera_id},
                                 {"marker_worst_px", marker_worst},
                                 {"centre_mm", (cc.centre - model.centre()).norm()},
                                 {"rays_mm", cc.ray_spread_mm}});
  }

  // The scan, processed four times from the same frames: planes from the sweep fit
  // or from each frame's poles, pixels to 3-D by the two-plane ray or the thesis's
  // image-to-laser-plane transform. The first is the default.
  std::vector<std::unique_ptr<pipeline::ScanProcessor>> processors;
  std::vector<std::string> names;
  for (pipeline::PlaneSource ps : {pipeline::PlaneSource::kSweepFit, pipeline::PlaneSource::kPerFrame})
    for (TriangulationMethod m : {TriangulationMethod::kLaserHomography, TriangulationMethod::kTwoPlaneRay}) {
      pipeline::ScanOptions o;
      o.planes = ps;
      o.triangulate.method = m;
      o.triangulate.min_angle_deg = g_min_angle;
      o.triangulate.smooth_rows = g_smooth;
      if (g_radius >= 0) o.triangulate.stripe.radius = g_radius;
      if (g_threshold > 0) o.triangulate.stripe.threshold = g_threshold;
      o.redundant_radius_mm = g_redundant;
      o.compensate_sway = !g_keep_sway;
      if (g_weak >= 0) o.redundant_weak = g_weak;
      o.view.max_view_deg = g_max_view > 0 ? g_max_view : desc.processing.max_view_deg;
      processors.push_back(std::make_unique<pipeline::ScanProcessor>(*cal, o));
      names.push_back(std::string(pipeline::to_string(ps)) + ", " + to_string(m));
    }
  std::vector<LaserPlaneFinder> finders;
  for (const CameraCalibration& cc : cal->cameras) finders.emplace_back(cc);
  std::vector<std::vector<hw::Frame>> bases(desc.laser_groups.size(), std::vector<hw::Frame>(cal->cameras.size()));
  std::vector<double> plane_errors;
  t0 = Clock::now();
  const Status s = pipeline::acquire_scan(
      handle,
      [&](pipeline::Shot&& shot) -> Status {
        if (shot.kind == pipeline::ShotKind::kLaserBase)
          bases[static_cast<size_t>(shot.group)][shot.camera] = shot.frame;
        if (shot.kind == pipeline::ShotKind::kScanStep) {
          // The plane against the true plane of the laser this camera sees.
          const auto& seen = cal->lasers_seen[shot.camera];
          for (const pipeline::LaserState& l : shot.lasers) {
            if (std::find(seen.begin(), seen.end(), l.laser) == seen.end()) continue;
            auto plane = finders[shot.camera].find(pipeline::view(shot.frame),
                                                   pipeline::view(bases[static_cast<size_t>(shot.group)][shot.camera]));
            if (plane.ok())
              plane_errors.push_back(plane_error(*plane, desc.lasers[static_cast<size_t>(l.laser)], l.step));
          }
        }
        for (size_t k = 1; k < processors.size(); ++k) {
          pipeline::Shot copy = shot;
          RETURN_IF_ERROR(processors[k]->consume(std::move(copy)));
        }
        return processors[0]->consume(std::move(shot));
      },
      every, {}, cal->sweep_reversed);
  if (!s.ok()) return std::fprintf(stderr, "%s\n", s.message().c_str()), 1;
  const double scan_total = secs(t0);
  std::vector<PointCloud> clouds;
  for (auto& p : processors) {
    auto c = p->finish();
    if (!c.ok()) return std::fprintf(stderr, "%s\n", c.status().message().c_str()), 1;
    clouds.push_back(std::move(*c));
  }
  const pipeline::ScanStats stats = processors[0]->stats();
  const Quantiles pe = quantiles(plane_errors);
  std::printf(
      "grazing points dropped (seen more than %.0f deg from their normal): %zu; redundant points dropped (a "
      "point with twice the confidence within %.1f mm): %zu\n",
      processors[0]->options().view.max_view_deg, stats.points_grazing, g_redundant, stats.points_redundant);
  std::printf(
      "scan: %zu frames per camera-step, %zu without a plane, far bottom estimated in %zu; acquisition + "
      "processing %.1f s, processing (frames -> points, one method) %.2f s = %.2f ms per frame\n",
      stats.frames, stats.frames_without_plane, stats.far_bottom_estimated, scan_total, stats.processing_seconds,
      1e3 * stats.processing_seconds / std::max<size_t>(1, stats.frames));
  std::printf(
      "laser planes vs truth (worst corner of the body's box): mean %.3f mm, p95 %.3f, max %.3f over %zu; "
      "fourth pole point off the other three's plane: RMS %.3f mm\n",
      pe.mean, pe.p95, pe.max, plane_errors.size(), stats.fourth_point_rms_mm);

  // Against the body's true surface.
  const TriangleMesh& truth = rig.scene().subject();
  const MeshDistance distance(truth);
  for (const pipeline::LaserSweepReport& r : stats.sweeps) {
    const hw::LaserDescription& l = desc.lasers[static_cast<size_t>(r.laser)];
    // The true axis: the line through the laser's position along its axis.
    const Eigen::Vector3d d = r.axis_point - l.position;
    const double axis_off = (d - d.dot(l.axis.normalized()) * l.axis.normalized()).norm();
    std::printf(
        "laser %-12s sweep %s: %zu pole points (%zu rejected) %.3f mm RMS from their planes; %.5f deg/step "
        "(true %.5f), axis %.2f mm from the true one\n",
        l.id.c_str(), r.fitted ? "fitted" : r.error.c_str(), r.points_used, r.points_rejected, r.rms_mm,
        r.degrees_per_step, l.step_angle_deg, axis_off);
  }
  for (size_t k = 0; k < processors.size(); ++k) {
    const PointCloud& cloud = clouds[k];
    const std::vector<float> d = distance.distances(cloud.positions);
    std::vector<double> dd(d.begin(), d.end());
    const Quantiles q = quantiles(dd);
    size_t far = 0;
    for (double x : dd) far += x > 5;
    std::printf("%-36s %8zu points: distance to the true surface mean %.3f mm, p95 %.3f, max %.1f (%zu beyond 5 mm)\n",
                names[k].c_str(), cloud.size(), q.mean, q.p95, q.max, far);
    record["methods"].push_back(
        {{"method", names[k]}, {"points", cloud.size()}, {"mean_mm", q.mean}, {"p95_mm", q.p95}, {"max_mm", q.max}});
    for (size_t c = 0; c < cal->cameras.size(); ++c) {
      std::vector<double> dc;
      for (size_t i = 0; i < dd.size(); ++i)
        if (cloud.camera[i] == static_cast<int>(c)) dc.push_back(dd[i]);
      const Quantiles qc = quantiles(dc);
      std::printf("    camera %-12s %8zu points: mean %.3f mm, p95 %.3f\n", cal->cameras[c].camera_id.c_str(),
                  dc.size(), qc.mean, qc.p95);
    }
    if (k != 0) continue;
    // The far points' share of the mean, and where they are.
    {
      double far_sum = 0;
      size_t very_far = 0;
      for (double x : dd) far_sum += x > 5 ? x : 0, very_far += x > 50;
      std::printf("    beyond 5 mm: %zu points (%zu beyond 50 mm) add %.3f mm to the mean\n", far, very_far,
                  far_sum / static_cast<double>(std::max<size_t>(dd.size(), 1)));
      int shown = 0;
      for (size_t i = 0; i < dd.size() && shown < 5; ++i) {
        if (dd[i] <= 50) continue;
        ++shown;
        const Vec3f& p = cloud.positions[i];
        std::printf("      %.0f mm off at (%.0f, %.0f, %.0f): camera %s, laser %s, frame %d, confidence %.2f\n", dd[i],
                    p.x(), p.y(), p.z(), desc.cameras[static_cast<size_t>(cloud.camera[i])].id.c_str(),
                    desc.lasers[static_cast<size_t>(cloud.laser[i])].id.c_str(), cloud.frame[i], cloud.confidence[i]);
      }
    }
    // The points within 5 mm by confidence (contrast and triangulation angle) and by
    // the angle their camera saw the true surface at, each bin with its signed mean
    // error (outside +): far from 0 it is a bias, not noise. Grazing views shift a
    // stripe's peak towards the side that faces the camera more.
    {
      std::vector<double> err, signed_err, confidence, view;
      std::vector<double> camera_bias(cal->cameras.size(), 0.0);
      std::vector<size_t> camera_n(cal->cameras.size(), 0);
      for (size_t i = 0; i < dd.size(); ++i) {
        if (dd[i] > 5) continue;
        const ClosestPoint cp = distance.closest_point(cloud.positions[i]);
        const Triangle& t = truth.triangles[cp.triangle];
        const Eigen::Vector3d n = (truth.vertices[t[1]] - truth.vertices[t[0]])
                                      .cross(truth.vertices[t[2]] - truth.vertices[t[0]])
                                      .cast<double>()
                                      .normalized();
        const Eigen::Vector3d to_cam =
            (desc.cameras[static_cast<size_t>(cloud.camera[i])].position - cloud.positions[i].cast<double>())
                .normalized();
        err.push_back(dd[i]);
        signed_err.push_back(cp.signed_distance);
        camera_bias[static_cast<size_t>(cloud.camera[i])] += cp.signed_distance;
        camera_n[static_cast<size_t>(cloud.camera[i])]++;
        confidence.push_back(cloud.confidence[i]);
        view.push_back(std::acos(std::min(1.0, std::abs(n.dot(to_cam)))) * 180 / M_PI);
      }
      const auto report = [&](const char* label, const std::vector<double>& edges, const std::vector<double>& key) {
        for (size_t b = 0; b + 1 < edges.size(); ++b) {
          std::vector<double> in;
          double bias = 0;
          for (size_t j = 0; j < key.size(); ++j)
            if (key[j] >= edges[b] && key[j] < edges[b + 1]) in.push_back(err[j]), bias += signed_err[j];
          const Quantiles bucket = quantiles(in);
          std::printf("    %s %4.2f-%4.2f %8zu points within 5 mm: mean %.3f mm, p95 %.3f, signed mean %+.3f\n", label,
                      edges[b], std::floor(edges[b + 1] * 100) / 100, in.size(), bucket.mean, bucket.p95,
                      bias / static_cast<double>(std::max<size_t>(in.size(), 1)));
        }
      };
      report("confidence", {0.0, 0.1, 0.25, 0.5, 0.75, 1.0 + 1e-6}, confidence);
      report("view (deg)", {0, 60, 70, 75, 80, 85, 90.01}, view);
      // Each laser's share: the point lies on its estimated plane, so its distance
      // from the true plane of its step (the nearest of the laser's steps) is the
      // plane's error there; moved onto the true plane along its normal, what is
      // left of its distance to the body is the camera's and the stripe's.
      {
        std::vector<double> on_body(desc.lasers.size(), 0.0), plane_corrected(desc.lasers.size(), 0.0),
            plane_off(desc.lasers.size(), 0.0);
        std::vector<size_t> nl(desc.lasers.size(), 0);
        for (size_t i = 0; i < dd.size(); ++i) {
          if (dd[i] > 5) continue;
          const size_t li = static_cast<size_t>(cloud.laser[i]);
          const hw::LaserDescription& l = desc.lasers[li];
          const Eigen::Vector3d p = cloud.positions[i].cast<double>();
          double best = 1e9;
          Eigen::Vector3d bn = Eigen::Vector3d::UnitX();
          for (int st = l.min_step; st <= l.max_step; ++st) {
            const double e = l.plane_normal(st).dot(p) - l.plane_offset(st);
            if (std::abs(e) < std::abs(best)) best = e, bn = l.plane_normal(st);
          }
          const Eigen::Vector3d on_plane = p - best * bn;
          // Signed: + where the plane error moves the point out of the body.
          const ClosestPoint cp = distance.closest_point(cloud.positions[i]);
          const ClosestPoint cq = distance.closest_point(on_plane.cast<float>());
          on_body[li] += cp.signed_distance;
          plane_corrected[li] += cq.signed_distance;
          plane_off[li] += cp.signed_distance - cq.signed_distance;
          nl[li]++;
        }
        for (size_t li = 0; li < desc.lasers.size(); ++li) {
          const double n = static_cast<double>(std::max<size_t>(nl[li], 1));
          std::printf(
              "    laser %-16s %7zu points within 5 mm: signed mean %+.3f mm, of which the plane %+.3f, the rest "
              "(camera, stripe) %+.3f\n",
              desc.lasers[li].id.c_str(), nl[li], on_body[li] / n, plane_off[li] / n, plane_corrected[li] / n);
        }
      }
      std::printf("    signed mean within 5 mm by camera:");
      for (size_t c = 0; c < camera_n.size(); ++c) {
        const double bias = camera_bias[c] / static_cast<double>(std::max<size_t>(camera_n[c], 1));
        std::printf(" %s %+.3f", cal->cameras[c].camera_id.c_str(), bias);
        record["cameras"][c]["points_signed_mm"] = bias;
      }
      std::printf("\n");
    }
    // The calibration alone: each camera's image-to-laser-plane transform for the
    // true plane (every 10th step of each laser it sees), applied to where the true
    // camera sees the true body's vertices on that plane. The signed error along the
    // body's normal (outside +) is what the calibration adds to a perfect stripe.
    {
      std::printf("    calibration alone (true planes, true pixels):");
      const std::vector<Vec3f> vn = compute_vertex_normals(truth);
      for (size_t c = 0; c < cal->cameras.size(); ++c) {
        const CameraCalibration& cc = cal->cameras[c];
        const hw::CameraModel model = desc.cameras[c].model();
        double sum = 0, sum_abs = 0;
        size_t n = 0;
        for (int li : cal->lasers_seen[c]) {
          const hw::LaserDescription& l = desc.lasers[static_cast<size_t>(li)];
          for (int st = l.min_step; st <= l.max_step; st += 10) {
            LaserPlane plane;
            if (!complete_plane(cc, l.plane_normal(st), l.plane_offset(st), &plane).ok()) continue;
            for (size_t v = 0; v < truth.vertices.size(); v += 3) {
              const Eigen::Vector3d p = truth.vertices[v].cast<double>();
              if (std::abs(l.plane_normal(st).dot(p) - l.plane_offset(st)) > 1.0) continue;
              const Eigen::Vector3d to_cam = model.centre() - p;
              if (vn[v].cast<double>().dot(to_cam.normalized()) < 0.26) continue;  // beyond 75 degrees
              if (rig.scene().occluded(p + 0.5 * to_cam.normalized(), to_cam.normalized(), to_cam.norm() - 1)) continue;
              const auto raw = model.project(p);
              if (!raw) continue;
              // The vertex lies within 1 mm of the plane: the true point is where its
              // camera ray meets the plane.
              const Eigen::Vector3d ray = (p - model.centre()).normalized();
              const double den = l.plane_normal(st).dot(ray);
              if (std::abs(den) < 0.17) continue;  // under 10 degrees: no triangulation
              const Eigen::Vector3d t =
                  model.centre() + ((l.plane_offset(st) - l.plane_normal(st).dot(model.centre())) / den) * ray;
              const Eigen::Vector3d seen =
                  plane.triangulate(cc, cc.lens.correct(*raw), TriangulationMethod::kLaserHomography);
              const double e = (seen - t).dot(vn[v].cast<double>().normalized());
              sum += e, sum_abs += std::abs(e), ++n;
            }
          }
        }
        std::printf(" %s %+.3f (|.| %.3f, %zu)", cc.camera_id.c_str(), n ? sum / n : 0.0, n ? sum_abs / n : 0.0, n);
        record["cameras"][c]["calibration_signed_mm"] = n ? sum / n : 0.0;
        record["cameras"][c]["calibration_abs_mm"] = n ? sum_abs / n : 0.0;
      }
      std::printf("\n");
    }
    // Coverage: the share of the body's area within 5 mm of a point, and where the rest is.
    const PointCloud samples = sample_mesh_uniform(truth, 400000, 7, true);
    const KnnIndex index(cloud.positions);
    size_t covered = 0;
    std::map<std::string, size_t> holes;
    for (size_t i = 0; i < samples.size(); ++i) {
      uint32_t nn;
      float d2;
      if (index.knn(samples.positions[i], 1, &nn, &d2) == 1 && d2 <= 25.f) {
        ++covered;
        continue;
      }
      const Vec3f& x = samples.positions[i];
      const Vec3f& n = samples.normals[i];
      holes[bench::body_region(x.cast<double>(), n.cast<double>())]++;
    }
    std::printf("coverage within 5 mm: %.1f %% of the body's area; uncovered:", 100.0 * covered / samples.size());
    record["coverage_percent"] = 100.0 * covered / samples.size();
    std::vector<std::pair<size_t, std::string>> by_size;
    for (const auto& [region, count] : holes) by_size.emplace_back(count, region);
    std::sort(by_size.rbegin(), by_size.rend());
    for (size_t i = 0; i < std::min<size_t>(6, by_size.size()); ++i)
      std::printf("%s %s %.1f %%", i ? "," : "", by_size[i].second.c_str(), 100.0 * by_size[i].first / samples.size());
    std::printf("\n");
  }
  g_records.push_back(std::move(record));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> rigs, bodies;
  std::string json_out;
  int every = 1;
  CommandLine cl(
      "scan_benchmark",
      "usage: scan_benchmark [--rig thesis|square|FILE]... [--body BODY.ply]... [--every N] [--min-angle DEG] "
      "[--max-view DEG] [--smooth N] [--radius PX] [--threshold N] [--redundant MM] [--weak C] [--keep-sway] "
      "[--json OUT]\n");
  cl.option("--rig", &rigs);
  cl.option("--body", &bodies);
  cl.option("--every", integer_between(1, 1000000, [&every](long long n) { every = static_cast<int>(n); }));
  cl.option("--min-angle", &g_min_angle);
  cl.option("--smooth", &g_smooth);
  cl.option("--radius", &g_radius);
  cl.option("--max-view", &g_max_view);
  cl.flag("--keep-sway", &g_keep_sway);
  cl.option("--threshold", &g_threshold);
  cl.option("--redundant", &g_redundant);
  cl.option("--weak", &g_weak);
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);
  if (rigs.empty()) rigs = {"thesis", "square"};
  if (bodies.empty()) bodies = {""};
  for (const std::string& r : rigs)
    for (const std::string& b : bodies)
      if (const int rc = run(r, b, every); rc != 0) return rc;
  if (!json_out.empty() && !bench::write_figures(json_out, run_info, g_records)) return 1;
  return 0;
}
