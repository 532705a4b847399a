// Measurements from a simulated scan against the same measurements on the body's
// true mesh (docs/benchmarks.md §7), as ISO 20685-1 judges a scanner: girths in
// fixed horizontal planes, the automatic ISO 8559-1 set, its repeatability over two
// scans (other noise, a swaying subject), and the time the automatic set takes.
// For the swaying scan it also prints how far the sway the scan job estimated (and
// undid) lies from the simulator's.
//
//   measure_benchmark [--rig thesis|square|tiered|FILE]... [--body BODY.ply]... [--repeat]
//                     [--sway MM] [--every N] [--fairing membrane|thin] [--save DIR | --saved DIR]
//                     [--resurface] [--seed N] [--min-weight W] [--voxel MM]
//                     [--posture ARMS,FEET,TURN] [--json OUT.json]
//   measure_benchmark --noise-study N [--noise-rms MM] [--noisy-out DIR] --body BODY.ply...
//
// --save writes each scan's surface, its point cloud and the posed true body as PLY
// into DIR (with --repeat, the second scan's surface and cloud too). --saved DIR
// measures what --save kept again, with today's rules, without scanning (--body
// names the files, --rig gives the floor): about two minutes for six bodies instead
// of an hour. With --resurface it first builds each surface again from the saved
// cloud with today's reconstruction (as the scan job does, half a minute a scan),
// so a change to the surface is judged on the same scans.
// --min-weight sets the surface's ReconstructOptions::min_relative_weight, --voxel
// its voxel_size (mm; default: chosen from the cloud).
// --posture ARMS,FEET,TURN has the simulated subject of every scan stand otherwise
// than the rig description says, as `bodyscan scan --arms --feet --turn` does
// (pipeline::SimulatedSubject): both upper arms ARMS degrees from the downward
// vertical, the ankle joints FEET mm apart (hw/sim/pose_body.hpp: a MakeHuman body
// only), turned TURN degrees about the vertical (+ turns the face from +Z toward +X).
// The truth is then the posed body exactly as the simulator rendered it (posture,
// turn and place), and --save keeps that one. With --saved it only names the
// posture the saved scans were taken in, for the JSON records.
// --noise-study N measures each body's own mesh N times under smooth skin noise
// (tests/support/skin_noise.hpp: fields at 40 and 10 mm, each --noise-rms RMS, default
// 0.25 mm) and ranks the measurements and landmarks by how far they move: no scan,
// a few seconds a body. --noisy-out DIR also writes each noisy mesh there
// (noisyN.ply, N the field's seed), to look at one with `bodyscan measure`.
//
// Defaults: the thesis rig, its demo body. ISO 20685-1 allows scan-derived values
// 9 mm off on large girths, 4 mm on small girths and heights, 5 mm on lengths. The
// issue's must for the fixed planes is half of that, its aim a sixth; for the
// automatic set the must is the allowance itself. Marks: aim (a sixth), must
// (half), iso (the allowance), OVER; "crosses fill" where the scan's value runs
// over surface hole filling invented, "outside posture" where the body stood
// outside the posture the value's definition assumes (body_posture.hpp), as the
// truth's set or the scan's reads it. The posture both sets read is printed too.
// --json OUT.json also writes, per rig and body, the automatic set of the truth and
// the scan value by value with the allowance and the fill's marks, the fixed
// planes' largest difference and the repeat pair's differences; it is rewritten
// after each body (bench/json_figures.hpp). bench/tables.py renders
// docs/benchmarks.md's measure_accuracy and measure_fill tables from it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "hw/sim/scene.hpp"
#include "pipeline/rig_backend.hpp"
#include "pipeline/scan_job.hpp"
#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "recon/measure/body_slicer.hpp"
#include "tests/support/skin_noise.hpp"

using namespace bodyscan;
using Clock = std::chrono::steady_clock;

namespace {

double secs(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Scan {
  TriangleMesh mesh, truth;
  PointCloud cloud;
  float voxel = 0;
  std::optional<BodyMeasurements> body;
  double floor = 0;
  std::string sway;  // the estimated sway against the simulator's (a swaying scan)
};

// How far a scan's estimated sway lies from the simulator's, over the points'
// moments (each point counts once), both taken to mean zero, since the scan cannot
// tell where the body stands on average. A scan frame's moment is its camera clock
// less the frames the cameras took before the scan (calibration), which the scan
// job does not report: that offset is fitted, in half frames over one sway period.
std::string sway_error(const SwayEstimate& est, const std::vector<int32_t>& frames, const hw::SubjectMotion& m,
                       double fps) {
  if (est.empty()) return "not estimated (" + est.not_estimated + ")";
  std::map<int, double> count;
  for (int32_t f : frames)
    if (f >= 0) count[f] += 1;
  if (count.empty() || m.sway_hz <= 0) return "no moments";
  double total = 0;
  Eigen::Vector3d est_mean = Eigen::Vector3d::Zero();
  for (const auto& [f, c] : count) total += c, est_mean += c * est.at(f);
  est_mean /= total;
  auto error = [&](double offset, Eigen::Vector3d* per_axis, double* truth_rms) {
    Eigen::Vector3d true_mean = Eigen::Vector3d::Zero();
    for (const auto& [f, c] : count) true_mean += c * hw::sim::subject_sway(m, (f + offset) / fps);
    true_mean /= total;
    Eigen::Vector3d e2 = Eigen::Vector3d::Zero();
    double t2 = 0;
    for (const auto& [f, c] : count) {
      const Eigen::Vector3d t = hw::sim::subject_sway(m, (f + offset) / fps) - true_mean;
      e2 += c * (est.at(f) - est_mean - t).cwiseAbs2();
      t2 += c * t.squaredNorm();
    }
    if (per_axis) *per_axis = (e2 / total).cwiseSqrt();
    if (truth_rms) *truth_rms = std::sqrt(t2 / total);
    return e2.sum();
  };
  double best = 0, best_e = error(0, nullptr, nullptr);
  for (double o = 0.5; o < fps / m.sway_hz; o += 0.5)
    if (const double e = error(o, nullptr, nullptr); e < best_e) best = o, best_e = e;
  Eigen::Vector3d axis;
  double truth = 0;
  error(best, &axis, &truth);
  char hold[96];
  if (est.regularization.still) {
    std::snprintf(hold, sizeof hold, "held still (no path explained held-out skin better)");
  } else {
    std::snprintf(hold, sizeof hold, "hold %s, size x%.2g%s", est.regularization.per_axis ? "per axis" : "on all pairs",
                  est.regularization.ridge_scale, est.regularization.slow_scale > 0 ? ", slow part held" : "");
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "%.2f mm RMS off the simulator's %.2f mm RMS (x %.2f, z %.2f; frame offset %.1f); %s", axis.norm(),
                truth, axis.x(), axis.z(), best, hold);
  return line;
}

// The scan job's surface options with --fairing and --min-weight applied: every
// surface here (the scans', the coarse one, --resurface's) is built with them.
ReconstructOptions g_surface = pipeline::body_surface_options();
std::string g_save;
std::string g_json_out;
nlohmann::json g_json = nlohmann::json::array();
nlohmann::json g_run;  // --json's provenance (bench/json_figures.hpp)
bool g_resurface = false;
uint64_t g_seed = 1;
// --posture: applied over every scan's rig description.
pipeline::SimulatedSubject g_subject;

// "ARMS,FEET,TURN" into g_subject; false when it is not three numbers.
// ARMS,FEET,TURN: both arms ARMS degrees from the vertical, the ankles FEET mm
// apart, turned TURN degrees.
std::string parse_posture(const std::string& text) {
  const auto v = parse_number_list(text, 3);
  if (!v) return "expects ARMS,FEET,TURN, got '" + text + "'";
  g_subject.posture.arm_abduction_deg = {(*v)[0], (*v)[0]};
  g_subject.posture.ankle_distance_mm = (*v)[1];
  g_subject.turn_deg = (*v)[2];
  return "";
}

// A shipped rig by name, or a description file.
StatusOr<hw::RigDescription> rig_description(const std::string& rig_name) {
  std::string path = rig_name;
  if (rig_name.find('/') == std::string::npos && rig_name.find(".json") == std::string::npos) {
    ASSIGN_OR_RETURN(path, hw::shipped_rig_path(rig_name));
  }
  return hw::load_rig_description(path);
}

StatusOr<Scan> scan(const std::string& rig_name, const std::string& body, uint64_t seed, double sway, int every) {
  ASSIGN_OR_RETURN(hw::RigDescription loaded, rig_description(rig_name));
  hw::RigDescription desc = g_subject.applied_to(std::move(loaded));
  desc.simulation.seed = seed;
  desc.simulation.motion.sway_mm = sway;
  TriangleMesh subject;
  if (!body.empty()) {
    ASSIGN_OR_RETURN(subject, read_ply_mesh(body));
  }
  ASSIGN_OR_RETURN(auto sim,
                   body.empty() ? hw::sim::SimulatedRig::create(desc) : hw::sim::SimulatedRig::create(desc, subject));
  pipeline::ScanJobOptions o;
  o.every = every;
  o.surface = g_surface;
  ASSIGN_OR_RETURN(pipeline::ScanJobResult r, pipeline::run_scan_job(pipeline::rig_handle(*sim), o));
  if (!r.surface_error.empty()) return internal_error("surface: " + r.surface_error);
  Scan s;
  s.mesh = std::move(r.mesh);
  s.cloud = std::move(r.cloud);
  s.voxel = r.surface.voxel_size;
  s.body = std::move(r.body);
  if (!s.body) return internal_error("measurements: " + r.measure_error);
  // The subject as the scene holds it: the body posed (SimulatedRig::create poses
  // it before the scene stands, turns and places it), at the last frame's moment.
  // For a still subject (the first scan: no sway, and the shipped rigs do not
  // breathe) that is what every frame rendered.
  s.truth = sim->scene().subject();
  s.floor = -0.5 * desc.frame.tube;
  if (sway > 0) s.sway = sway_error(r.scan.sway, s.cloud.frame, desc.simulation.motion, desc.simulation.frame_rate_hz);
  return s;
}

// One part of the posture as the truth's set and the scan's read it.
std::string posture_pair(const std::optional<double>& truth, const std::optional<double>& scan) {
  char t[32] = "-", s[32] = "-";
  if (truth) std::snprintf(t, sizeof t, "%.1f", *truth);
  if (scan) std::snprintf(s, sizeof s, "%.1f", *scan);
  return std::string(t) + " / " + s;
}

nlohmann::json posture_json(const BodyPosture& p) {
  auto value = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
  return {{"turn_deg", p.turn_deg},
          {"arms_deg", {value(p.arm_abduction_deg[0]), value(p.arm_abduction_deg[1])}},
          {"ankles_mm", value(p.ankle_distance_mm)}};
}

// A body file's name without its folder and ".ply"; "demo" for the rig's own.
std::string body_name(const std::string& path) {
  if (path.empty()) return "demo";
  std::string name = path.substr(path.find_last_of('/') + 1);
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".ply") == 0) name.resize(name.size() - 4);
  return name;
}

// Keeps a body's record (when it was measured) and rewrites --json's file, so a long
// run leaves what it has finished; passes `rc` through.
int finish(nlohmann::json& record, int rc) {
  if (rc == 0) g_json.push_back(std::move(record));
  if (!g_json_out.empty() && !bench::write_figures(g_json_out, g_run, g_json) && rc == 0) return 1;
  return rc;
}

const char* mark(double diff, double allow) {
  const double d = std::abs(diff);
  return d <= allow / 6 ? "aim" : d <= allow / 2 ? "must" : "FAIL";
}

// Fixed planes, the automatic set against the truth's, and (with a second scan's
// set) the repeatability.
// `record` gains the --json fields.
int report(const TriangleMesh& truth_mesh, const TriangleMesh& mesh, const BodyMeasurements& scan_body, double floor,
           const BodyMeasurements* second, double sway, nlohmann::json& record) {
  BodyMeasureOptions mo;
  mo.floor_y = floor;
  auto t0 = Clock::now();
  auto truth = measure_body(truth_mesh, mo);
  const double t_truth = secs(t0);
  if (!truth.ok()) return std::fprintf(stderr, "truth: %s\n", truth.status().message().c_str()), 1;
  t0 = Clock::now();
  auto again = measure_body(mesh, mo);
  const double t_scan = secs(t0);
  std::printf("automatic set: %.3f s on the scan (%zu triangles), %.3f s on the truth (%zu triangles)\n", t_scan,
              mesh.triangles.size(), t_truth, truth_mesh.triangles.size());
  if (!again.ok()) return std::fprintf(stderr, "scan set: %s\n", again.status().message().c_str()), 1;
  const BodyPosture &tp = truth->posture, &sp = scan_body.posture;
  std::printf("posture, truth / scan: turn %s deg, arms left %s, right %s deg, ankles %s mm\n",
              posture_pair(tp.turn_deg, sp.turn_deg).c_str(),
              posture_pair(tp.arm_abduction_deg[0], sp.arm_abduction_deg[0]).c_str(),
              posture_pair(tp.arm_abduction_deg[1], sp.arm_abduction_deg[1]).c_str(),
              posture_pair(tp.ankle_distance_mm, sp.ankle_distance_mm).c_str());

  // Fixed planes: horizontal girths at fractions of the stature, round the torso and
  // each leg as the truth's cut finds them.
  const double h = truth->find("stature")->value_mm;
  BodySlicer ts(truth_mesh, floor, floor + h + 1, 2);
  BodySlicer ss(mesh, floor - 5, floor + h + 10, 2);
  std::printf("\nfixed planes         height    truth     scan     diff  vs 4.5/1.5 (large) 2/0.67 (small)\n");
  double worst_fixed = 0;
  for (double f : {0.05, 0.10, 0.20, 0.30, 0.40}) {
    const double y = floor + f * h;
    for (int s : {1, -1}) {
      const std::vector<Ring> r = ts.rings(y);
      const Ring* leg = nullptr;
      for (const Ring& x : r)
        if (s * x.centroid.x() > 0 && (!leg || s * x.centroid.x() < s * leg->centroid.x())) leg = &x;
      if (!leg) continue;
      auto gt = ts.girth(y, leg->centroid), gs = ss.girth(y, leg->centroid);
      if (!gt.ok() || !gs.ok()) {
        std::printf("leg %-5s %4.0f %%: %s\n", s > 0 ? "left" : "right", 100 * f,
                    (gt.ok() ? gs : gt).status().message().c_str());
        continue;
      }
      const double d = gs->value_mm - gt->value_mm;
      worst_fixed = std::max(worst_fixed, std::abs(d));
      std::printf("leg %-5s %4.0f %%  %7.1f  %7.1f  %7.1f  %+6.2f  %s%s\n", s > 0 ? "left" : "right", 100 * f, y,
                  gt->value_mm, gs->value_mm, d, mark(d, 4), gs->min_confidence < 0.5f ? "  (crosses fill)" : "");
    }
  }
  for (double f : {0.50, 0.55, 0.60, 0.65, 0.70, 0.72}) {
    const double y = floor + f * h;
    const Eigen::Vector3d c(0, y, truth->landmark("waist_back_point")->position.z() + 100);
    auto gt = ts.girth(y, c), gs = ss.girth(y, c);
    if (!gt.ok() || !gs.ok()) continue;
    const double d = gs->value_mm - gt->value_mm;
    worst_fixed = std::max(worst_fixed, std::abs(d));
    std::printf("torso     %4.0f %%  %7.1f  %7.1f  %7.1f  %+6.2f  %s%s\n", 100 * f, y, gt->value_mm, gs->value_mm, d,
                mark(d, 9), gs->min_confidence < 0.5f ? "  (crosses fill)" : "");
  }
  std::printf("largest fixed-plane difference %.2f mm\n", worst_fixed);
  record["fixed_planes_largest_mm"] = worst_fixed;
  record["posture"] = {{"truth", posture_json(tp)}, {"scan", posture_json(sp)}};
  nlohmann::json& values = record["measurements"] = nlohmann::json::array();

  std::printf("\n%-24s %6s %8s %8s %7s %6s  %s\n", "automatic set", "ISO", "truth", "scan", "diff", "allow", "");
  size_t n = 0, iso = 0, must = 0, aim = 0;
  // The fill's marks: values over filled skin, those marked as estimates, and how
  // the differences compare with the bound (recon/measure/fill_bound.hpp).
  size_t crossing = 0, marked = 0, unmarked_over = 0, marked_past_bound = 0;
  for (const BodyMeasurement& m : truth->measurements) {
    const BodyMeasurement* s = scan_body.find(m.name);
    if (!s) {
      std::printf("%-24s missing on the scan\n", m.name.c_str());
      values.push_back({{"name", m.name}, {"truth_mm", m.value_mm}, {"scan_mm", nullptr}});
      continue;
    }
    const double d = s->value_mm - m.value_mm, al = iso20685_allowance_mm(m);
    ++n;
    iso += std::abs(d) <= al;
    must += std::abs(d) <= al / 2;
    aim += std::abs(d) <= al / 6;
    crossing += s->crosses_filled_hole();
    marked += s->estimated();
    unmarked_over += !s->estimated() && std::abs(d) > al;
    // Past its bound by more than half the allowance (the scan's own error on seen skin).
    marked_past_bound += s->estimated() && s->fill_bound_mm && std::abs(d) > *s->fill_bound_mm + al / 2;
    values.push_back({{"name", m.name},
                      {"iso_clause", m.iso_clause},
                      {"truth_mm", m.value_mm},
                      {"scan_mm", s->value_mm},
                      {"allowance_mm", al},
                      {"crosses_fill", s->crosses_filled_hole()},
                      {"estimated", s->estimated()},
                      {"fill_bound_mm", s->fill_bound_mm ? nlohmann::json(*s->fill_bound_mm) : nlohmann::json()},
                      {"outside_posture", m.outside_posture || s->outside_posture}});
    char fill[48] = "";
    if (s->estimated())
      s->fill_bound_mm ? std::snprintf(fill, sizeof fill, "  (estimate, fill bound %.1f)", *s->fill_bound_mm)
                       : std::snprintf(fill, sizeof fill, "  (estimate, fill bound not known)");
    std::printf("%-24s %6s %8.1f %8.1f %+7.2f %6.1f  %s%s%s\n", m.name.c_str(), m.iso_clause.c_str(), m.value_mm,
                s->value_mm, d, al, std::abs(d) <= al ? (std::abs(d) <= al / 2 ? mark(d, al) : "iso") : "OVER", fill,
                m.outside_posture || s->outside_posture ? "  (outside posture)" : "");
  }
  std::printf("%zu measurements: %zu within the ISO allowance, %zu within half, %zu within a sixth\n", n, iso, must,
              aim);
  std::printf(
      "filled skin: %zu cross it, %zu marked as estimates (bound over %.0f mm or not known); %zu unmarked "
      "over their allowance, %zu marked off by more than their bound and half the allowance\n",
      crossing, marked, kEstimateThresholdMm, unmarked_over, marked_past_bound);
  for (const std::string& k : scan_body.skipped) std::printf("skipped on the scan: %s\n", k.c_str());

  if (second) {
    double worst = 0;
    std::string worst_name;
    std::vector<double> diffs;
    for (const BodyMeasurement& m : scan_body.measurements) {
      const BodyMeasurement* o = second->find(m.name);
      if (!o) continue;
      const double d = std::abs(o->value_mm - m.value_mm);
      diffs.push_back(d);
      if (d > worst) worst = d, worst_name = m.name;
    }
    std::sort(diffs.begin(), diffs.end());
    record["repeat"] = {{"sway_mm", sway},
                        {"count", diffs.size()},
                        {"over_2mm", std::count_if(diffs.begin(), diffs.end(), [](double x) { return x > 2.0; })},
                        {"median_mm", diffs.empty() ? 0.0 : diffs[diffs.size() / 2]},
                        {"largest_mm", worst},
                        {"largest", worst_name}};
    std::printf("\nrepeatability (seed +1, sway %.0f mm): %zu measurements, median %.2f mm, largest %.2f mm (%s)\n",
                sway, diffs.size(), diffs.empty() ? 0.0 : diffs[diffs.size() / 2], worst, worst_name.c_str());
    for (const BodyMeasurement& m : scan_body.measurements)
      if (const BodyMeasurement* o = second->find(m.name); o && std::abs(o->value_mm - m.value_mm) > 1.0)
        std::printf("  %-24s %8.1f %8.1f %+6.2f\n", m.name.c_str(), m.value_mm, o->value_mm, o->value_mm - m.value_mm);
  }
  return 0;
}

// The posture --posture asked for (the scan's, or with --saved the one the saved
// scan was taken in), as the JSON record's "posed".
void add_posture(nlohmann::json& record) {
  if (g_subject.turn_deg)
    record["posed"] = {{"arms_deg", *g_subject.posture.arm_abduction_deg[0]},
                       {"ankles_mm", *g_subject.posture.ankle_distance_mm},
                       {"turn_deg", *g_subject.turn_deg}};
}

int run(const std::string& rig, const std::string& body, bool repeat, double sway, int every) {
  std::printf("\n== rig %s, body %s", rig.c_str(), body.empty() ? "(the rig's)" : body.c_str());
  if (g_subject.turn_deg)
    std::printf(", posture arms %g deg, feet %g mm, turn %g deg", *g_subject.posture.arm_abduction_deg[0],
                *g_subject.posture.ankle_distance_mm, *g_subject.turn_deg);
  std::printf("\n");
  auto t0 = Clock::now();
  auto a = scan(rig, body, g_seed, 0, every);
  if (!a.ok()) return std::fprintf(stderr, "scan: %s\n", a.status().message().c_str()), 1;
  const double scan_seconds = secs(t0);
  std::printf("scan job %.0f s, mesh %zu triangles\n", scan_seconds, a->mesh.triangles.size());
  const std::string stem =
      g_save + "/" + (body.empty() ? std::string("demo") : body.substr(body.find_last_of('/') + 1));
  if (!g_save.empty()) {
    for (const Status& w : {write_ply(stem + "-scan.ply", a->mesh), write_ply(stem + "-truth.ply", a->truth),
                            write_ply(stem + "-cloud.ply", a->cloud)})
      if (!w.ok()) std::fprintf(stderr, "--save: %s\n", w.message().c_str());
  }
  {
    // The same scan surfaced on a coarser grid, about 500k triangles.
    ReconstructOptions ro = g_surface;
    ro.voxel_size = a->voxel * 1.77f;
    ro.normal_source = NormalSource::kCameras;
    auto coarse = reconstruct_surface(a->cloud, ro);
    if (coarse.ok()) {
      BodyMeasureOptions mo;
      mo.floor_y = a->floor;
      t0 = Clock::now();
      auto c = measure_body(coarse->mesh, mo);
      std::printf("automatic set: %.3f s on the scan surfaced at %.2f mm voxels (%zu triangles)%s\n", secs(t0),
                  ro.voxel_size, coarse->mesh.triangles.size(), c.ok() ? "" : " (failed)");
    }
  }
  std::optional<Scan> b;
  if (repeat) {
    auto s = scan(rig, body, g_seed + 1, sway, every);
    if (!s.ok()) return std::fprintf(stderr, "second scan: %s\n", s.status().message().c_str()), 1;
    if (!g_save.empty()) {
      for (const Status& w : {write_ply(stem + "-scan2.ply", s->mesh), write_ply(stem + "-cloud2.ply", s->cloud)})
        if (!w.ok()) std::fprintf(stderr, "--save: %s\n", w.message().c_str());
    }
    if (!s->sway.empty()) std::printf("second scan's sway, as estimated: %s\n", s->sway.c_str());
    b = std::move(*s);
  }
  nlohmann::json record = {{"rig", rig}, {"body", body_name(body)}, {"scan_seconds", scan_seconds}};
  add_posture(record);
  return finish(record, report(a->truth, a->mesh, *a->body, a->floor, b ? &*b->body : nullptr, sway, record));
}

// A saved scan's surface: B-scanN.ply, or with --resurface one built again from
// B-cloudN.ply as the scan job builds it.
StatusOr<TriangleMesh> saved_surface(const std::string& stem, const std::string& n) {
  if (!g_resurface) return read_ply_mesh(stem + "-scan" + n + ".ply");
  ASSIGN_OR_RETURN(PlyData ply, read_ply(stem + "-cloud" + n + ".ply"));
  PointCloud& cloud = ply.cloud;
  const ReconstructOptions ro = pipeline::with_scan_normals(g_surface, cloud);
  const auto t0 = Clock::now();
  ASSIGN_OR_RETURN(ReconstructResult r, reconstruct_surface(cloud, ro));
  std::printf("surfaced again from %s-cloud%s.ply: %zu triangles, %.0f s\n", stem.c_str(), n.c_str(),
              r.mesh.triangles.size(), secs(t0));
  return std::move(r.mesh);
}

// What --save kept, measured again with today's rules: DIR/B-truth.ply, B-scan.ply
// and, where there, B-scan2.ply (the repeat).
int remeasure(const std::string& dir, const std::string& rig, const std::string& body, double sway) {
  const std::string stem = dir + "/" + body.substr(body.find_last_of('/') + 1);
  std::printf("\n== saved %s, rig %s\n", stem.c_str(), rig.c_str());
  auto desc = rig_description(rig);
  if (!desc.ok()) return std::fprintf(stderr, "%s\n", desc.status().message().c_str()), 1;
  const double floor = -0.5 * desc->frame.tube;  // as scan() takes it
  auto truth = read_ply_mesh(stem + "-truth.ply");
  auto mesh = saved_surface(stem, "");
  if (!truth.ok() || !mesh.ok())
    return std::fprintf(stderr, "%s\n", (truth.ok() ? mesh.status() : truth.status()).message().c_str()), 1;
  BodyMeasureOptions mo;
  mo.floor_y = floor;
  auto a = measure_body(*mesh, mo);
  if (!a.ok()) return std::fprintf(stderr, "scan set: %s\n", a.status().message().c_str()), 1;
  std::optional<BodyMeasurements> b;
  const bool has_second = std::ifstream(stem + (g_resurface ? "-cloud2.ply" : "-scan2.ply")).good();
  if (has_second) {
    auto mesh2 = saved_surface(stem, "2");
    if (!mesh2.ok()) return std::fprintf(stderr, "second scan: %s\n", mesh2.status().message().c_str()), 1;
    auto m = measure_body(*mesh2, mo);
    if (!m.ok()) return std::fprintf(stderr, "second scan set: %s\n", m.status().message().c_str()), 1;
    b = std::move(*m);
  }
  nlohmann::json record = {{"rig", rig}, {"body", body_name(body)}, {"saved", dir}};
  add_posture(record);
  return finish(record, report(*truth, *mesh, *a, floor, b ? &*b : nullptr, sway, record));
}

// How far each rule of the automatic set moves when the skin moves a little: the
// body's true mesh with a smooth random field added along its normals (two scales,
// 40 and 10 mm, each `rms_mm` RMS: a scan's surface errs so, not vertex by vertex),
// measured `n` times. Prints, per measurement, the RMS and the largest difference
// from the clean body's value, largest first; the rules that move most are those a
// second scan moves most.
int noise_study(const std::string& body, int n, double rms_mm, const std::string& noisy_out) {
  auto mesh = read_ply_mesh(body);
  if (!mesh.ok()) return std::fprintf(stderr, "%s\n", mesh.status().message().c_str()), 1;
  auto clean = measure_body(*mesh);
  if (!clean.ok()) return std::fprintf(stderr, "clean: %s\n", clean.status().message().c_str()), 1;
  std::map<std::string, std::vector<double>> diffs;
  std::map<std::string, std::vector<Eigen::Vector3d>> moves;
  for (int s = 1; s <= n; ++s) {
    const TriangleMesh noisy = with_smooth_skin_noise(*mesh, rms_mm, s);
    if (!noisy_out.empty()) {
      const std::string path = noisy_out + "/noisy" + std::to_string(s) + ".ply";
      if (Status w = write_ply(path, noisy); !w.ok())
        std::fprintf(stderr, "%s: %s\n", path.c_str(), w.message().c_str());
    }
    auto m = measure_body(noisy);
    if (!m.ok()) {
      std::printf("seed %d: %s\n", s, m.status().message().c_str());
      continue;
    }
    for (const BodyMeasurement& c : clean->measurements)
      if (const BodyMeasurement* x = m->find(c.name)) diffs[c.name].push_back(x->value_mm - c.value_mm);
    for (const BodyLandmark& c : clean->landmarks)
      if (const BodyLandmark* x = m->landmark(c.name)) moves[c.name].push_back(x->position - c.position);
  }
  std::vector<std::pair<double, std::string>> order;
  for (const auto& [name, d] : diffs) {
    double mx = 0;
    for (double x : d) mx = std::max(mx, std::abs(x));
    order.emplace_back(mx, name);
  }
  std::sort(order.rbegin(), order.rend());
  std::printf("\n== %s: %d fields of %.2f mm RMS at 40 mm and at 10 mm\n%-24s %8s %8s %8s %8s\n", body.c_str(), n,
              rms_mm, "measurement", "value", "mean", "rms", "largest");
  for (const auto& [mx, name] : order) {
    const std::vector<double>& d = diffs[name];
    double ss = 0, sum = 0;
    for (double x : d) ss += x * x, sum += x;
    std::printf("%-24s %8.1f %+8.2f %8.2f %8.2f\n", name.c_str(), clean->find(name)->value_mm, sum / d.size(),
                std::sqrt(ss / d.size()), mx);
  }
  std::printf("\n%-26s %8s %8s %8s %8s\n", "landmark", "rms x", "rms y", "rms z", "largest");
  for (const auto& [name, d] : moves) {
    Eigen::Vector3d ss = Eigen::Vector3d::Zero();
    double mx = 0;
    for (const Eigen::Vector3d& x : d) ss += x.cwiseProduct(x), mx = std::max(mx, x.norm());
    ss = (ss / d.size()).cwiseSqrt();
    std::printf("%-26s %8.2f %8.2f %8.2f %8.2f\n", name.c_str(), ss.x(), ss.y(), ss.z(), mx);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> rigs, bodies;
  bool repeat = false;
  std::string saved;
  double sway = 3;
  int every = 1, noise_fields = 0;
  double noise_rms = 0.25;
  std::string noisy_out;
  CommandLine cl("measure_benchmark",
                 "usage: measure_benchmark [--rig R]... [--body B]... [--repeat] [--sway MM] [--every N] "
                 "[--fairing membrane|thin] [--save DIR | --saved DIR [--resurface]] [--seed N] [--min-weight W] "
                 "[--voxel MM] [--posture ARMS,FEET,TURN] [--json OUT]\n"
                 "       measure_benchmark --noise-study N [--noise-rms MM] [--noisy-out DIR] --body B...\n");
  cl.option("--rig", &rigs);
  cl.option("--body", &bodies);
  cl.flag("--repeat", &repeat);
  cl.option("--sway", &sway);
  cl.option("--every", integer_between(1, 1000000, [&every](long long n) { every = static_cast<int>(n); }));
  cl.option("--save", &g_save);
  cl.option("--saved", &saved);
  cl.flag("--resurface", &g_resurface);
  cl.option("--noise-study",
            integer_between(1, 1000000, [&noise_fields](long long n) { noise_fields = static_cast<int>(n); }));
  cl.option("--noise-rms", &noise_rms);
  cl.option("--noisy-out", &noisy_out);
  cl.option("--seed", &g_seed);
  cl.option("--json", &g_json_out);
  cl.option("--min-weight", &g_surface.min_relative_weight);
  cl.option("--voxel", &g_surface.voxel_size);
  cl.option("--posture", parse_posture);
  cl.option("--fairing", [](const std::string& f) -> std::string {
    if (f != "membrane" && f != "thin") return "is membrane or thin, not '" + f + "'";
    g_surface.hole_fairing = f == "membrane" ? HoleFairing::kMembrane : HoleFairing::kThinPlate;
    return "";
  });
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  g_run = bench::run_record(argc, argv);
  if (noise_fields > 0) {
    if (bodies.empty()) return std::fprintf(stderr, "measure_benchmark: --noise-study needs --body B.ply\n"), 2;
    int rc = 0;
    for (const std::string& b : bodies) rc |= noise_study(b, noise_fields, noise_rms, noisy_out);
    return rc;
  }
  if (rigs.empty()) rigs = {"thesis"};
  if (bodies.empty()) bodies = {""};
  int rc = 0;
  if (!saved.empty() && bodies == std::vector<std::string>{""})
    return std::fprintf(stderr, "measure_benchmark: --saved needs the bodies' names (--body B.ply)\n"), 2;
  if (!g_save.empty()) {  // before the scans, not after them
    std::error_code ec;
    std::filesystem::create_directories(g_save, ec);
    if (ec) return std::fprintf(stderr, "measure_benchmark: --save %s: %s\n", g_save.c_str(), ec.message().c_str()), 2;
  }
  for (const std::string& r : rigs)
    for (const std::string& b : bodies)
      rc |= saved.empty() ? run(r, b, repeat, sway, every) : remeasure(saved, r, b, sway);
  return rc;
}
