// How the automatic measurements follow the body rather than the way it stands
// (docs/benchmarks.md, "Posture and placement"). Each MakeHuman body is measured
// in its rest A-pose, then turned and moved (a rigid motion: nothing may change),
// and posed by skinning (hw/sim/pose_body.hpp): arms lowered or raised, feet
// closer or farther apart. Vertex i is the same anatomical point in every posture,
// so each landmark is held against the vertex it marked in the rest pose, and each
// value against the rest pose's where the posture did not move its skin.
//
//   posture_benchmark [--body BODY.ply]... [--arms DEG,...] [--feet MM,...]
//                     [--turns DEG,...] [--shift MM] [--json OUT.json] [--detail]
//
// Defaults: the six shared bodies (../shared/data/bodies) if present, else the two
// shipped demo bodies; arms 15,20,25,30,35,45; feet 150,250,350,450; turns
// -30,-20,-10,10,20,30 with a 300 mm shift. --detail prints every value that moved
// by more than half its allowance.
#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "hw/sim/pose_body.hpp"
#include "recon/io/ply.hpp"
#include "recon/measure/body_frame.hpp"
#include "recon/measure/body_measurements.hpp"
#include "recon/measure/body_posture.hpp"

using namespace bodyscan;

namespace {

std::string family(const BodyMeasurement& m) {
  if (m.kind == "girth") return iso20685_allowance_mm(m) > 4 ? "torso girths" : "limb and neck girths";
  if (m.kind == "height") return "heights";
  return "lengths";
}
const char* kFamilies[] = {"heights", "torso girths", "limb and neck girths", "lengths"};

// Landmarks whose place skinning does not define: the armpits sit in the crease,
// where skinning itself is not anatomical (shared/data/skeleton/README.md).
bool anatomical(const std::string& landmark) { return landmark.rfind("armpit", 0) != 0; }

size_t nearest_vertex(const TriangleMesh& m, const Eigen::Vector3d& p) {
  size_t best = 0;
  double best_d = INFINITY;
  for (size_t i = 0; i < m.vertices.size(); ++i)
    if (const double d = (m.vertices[i].cast<double>() - p).squaredNorm(); d < best_d) best_d = d, best = i;
  return best;
}

// A rest body measured once, with each landmark's vertex and each measurement's
// vertices (those nearest its path and loop).
struct Reference {
  std::string name;
  TriangleMesh mesh;
  BodyMeasurements measured;
  std::map<std::string, size_t> landmark_vertex;
  std::map<std::string, Eigen::Vector3d> landmark_offset;  // landmark - its vertex, at rest
  std::map<std::string, std::vector<size_t>> measurement_vertices;
};

struct Row {
  std::string variant;
  std::map<std::string, std::pair<double, std::string>> largest;  // family -> (|change|, measurement)
  double landmark_max = 0, landmark_median = 0;
  std::string landmark_worst;
  size_t unmoved = 0, unmoved_within_half = 0;
  double arm_length_error = 0;  // outer arm length's change less the anatomical points' own, largest
  std::vector<std::string> detail;
};

Row compare(const Reference& ref, const std::string& variant, const TriangleMesh& mesh, const BodyMeasurements& got,
            const Eigen::Isometry3d& motion, bool posed, bool detail) {
  Row row;
  row.variant = variant;
  // How far each vertex moved other than by the rigid motion (the posture's own).
  std::vector<double> moved(mesh.vertices.size());
  Eigen::Vector3d lift = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d expect = motion * ref.mesh.vertices[i].cast<double>();
    moved[i] = (mesh.vertices[i].cast<double>() - expect).norm();
  }
  // Skinning the legs lifts the whole body; girths and lengths do not see a lift.
  {
    std::vector<double> dy;
    for (size_t i = 0; i < mesh.vertices.size(); ++i)
      dy.push_back(mesh.vertices[i].y() - (motion * ref.mesh.vertices[i].cast<double>()).y());
    std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
    lift.y() = dy[dy.size() / 2];
  }
  for (const BodyMeasurement& m : ref.measured.measurements) {
    const BodyMeasurement* g = got.find(m.name);
    if (!g) {
      row.detail.push_back(m.name + " not taken");
      continue;
    }
    const double change = g->value_mm - m.value_mm;
    const std::string fam = family(m);
    if (std::abs(change) > row.largest[fam].first) row.largest[fam] = {std::abs(change), m.name};
    // Did the posture move this value's skin? (A height also sees the lift.)
    double skin = 0;
    for (size_t v : ref.measurement_vertices.at(m.name)) {
      const Eigen::Vector3d expect = motion * ref.mesh.vertices[v].cast<double>() + (m.kind == "height" ? 0 : 1) * lift;
      skin = std::max(skin, (mesh.vertices[v].cast<double>() - expect).norm());
    }
    if (skin < 0.5) {
      ++row.unmoved;
      if (std::abs(change) <= 0.5 * iso20685_allowance_mm(m)) ++row.unmoved_within_half;
    }
    if (detail && std::abs(change) > 0.5 * iso20685_allowance_mm(m)) {
      char b[160];
      std::snprintf(b, sizeof b, "%s %+.1f (allowance %.0f; skin moved %.1f mm)", m.name.c_str(), change,
                    iso20685_allowance_mm(m), skin);
      row.detail.push_back(b);
    }
    if (posed && m.name.rfind("outer_arm_length", 0) == 0) {
      const std::string side = m.name.substr(std::string("outer_arm_length_").size());
      double rest = 0, now = 0;
      const std::vector<std::string> via = {"shoulder_point_" + side, "elbow_point_" + side, "wrist_point_" + side};
      for (size_t k = 0; k + 1 < via.size(); ++k) {
        const size_t a = ref.landmark_vertex.at(via[k]), b = ref.landmark_vertex.at(via[k + 1]);
        rest += (ref.mesh.vertices[a] - ref.mesh.vertices[b]).norm();
        now += (mesh.vertices[a] - mesh.vertices[b]).norm();
      }
      row.arm_length_error = std::max(row.arm_length_error, std::abs(change - (now - rest)));
    }
  }
  std::vector<double> d;
  for (const BodyLandmark& l : ref.measured.landmarks) {
    if (!anatomical(l.name)) continue;
    const BodyLandmark* g = got.landmark(l.name);
    if (!g) continue;
    const size_t v = ref.landmark_vertex.at(l.name);
    const Eigen::Vector3d expect = mesh.vertices[v].cast<double>() + motion.linear() * ref.landmark_offset.at(l.name);
    const double dist = (g->position - expect).norm();
    d.push_back(dist);
    if (detail && dist > 5) {
      char b[160];
      std::snprintf(b, sizeof b, "landmark %s %.1f mm from its vertex", l.name.c_str(), dist);
      row.detail.push_back(b);
    }
    if (dist > row.landmark_max) row.landmark_max = dist, row.landmark_worst = l.name;
  }
  if (!d.empty()) {
    std::sort(d.begin(), d.end());
    row.landmark_median = d[d.size() / 2];
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> bodies;
  std::vector<double> arms = {15, 20, 25, 30, 35, 45}, feet = {150, 250, 350, 450}, turns = {-30, -20, -10, 10, 20, 30};
  double shift = 300;
  std::string json_out;
  bool detail = false;
  auto number_list = [](std::vector<double>* out) {
    return [out](const std::string& v) -> std::string {
      auto x = parse_number_list(v);
      if (!x) return "expects comma-separated numbers, got '" + v + "'";
      *out = std::move(*x);
      return "";
    };
  };
  CommandLine cl("posture_benchmark",
                 "usage: posture_benchmark [--body B.ply]... [--arms DEG,...] [--feet MM,...] [--turns DEG,...] "
                 "[--shift MM] [--json OUT] [--detail]\n");
  cl.option("--body", &bodies);
  cl.option("--arms", number_list(&arms));
  cl.option("--feet", number_list(&feet));
  cl.option("--turns", number_list(&turns));
  cl.option("--shift", &shift);
  cl.option("--json", &json_out);
  cl.flag("--detail", &detail);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bench::run_record(argc, argv);  // the tree as the run starts
  const std::string shared = BODYSCAN_SOURCE_DIR "/../shared/data/bodies";
  if (bodies.empty()) {
    if (std::filesystem::exists(shared + "/male_average.ply")) {
      for (const char* b :
           {"male_average", "male_heavy", "male_muscular", "female_average", "female_heavy", "female_slim_tall"})
        bodies.push_back(shared + "/" + b + ".ply");
    } else {
      for (const char* b : {"male_average", "female_average"})
        bodies.push_back(std::string(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/") + b + ".ply");
    }
  }
  auto poser = hw::sim::BodyPoser::shipped();
  if (!poser.ok()) {
    std::fprintf(stderr, "posture_benchmark: %s\n", poser.status().message().c_str());
    return 1;
  }
  nlohmann::json all = nlohmann::json::array();
  std::printf(
      "| body | variant | heights | torso girths | limb and neck girths | lengths | unmoved skin: within half the "
      "allowance | outer arm length vs its points | landmarks to their vertices: median / largest | arms found - true "
      "(left / right) | ankles found - true | turn found |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|\n");
  for (const std::string& path : bodies) {
    auto mesh = read_ply_mesh(path);
    if (!mesh.ok()) {
      std::fprintf(stderr, "posture_benchmark: %s\n", mesh.status().message().c_str());
      return 1;
    }
    Reference ref;
    ref.name = std::filesystem::path(path).stem().string();
    ref.mesh = *mesh;
    auto measured = measure_body(ref.mesh);
    if (!measured.ok()) {
      std::fprintf(stderr, "posture_benchmark: %s: %s\n", path.c_str(), measured.status().message().c_str());
      return 1;
    }
    ref.measured = *measured;
    for (const BodyLandmark& l : ref.measured.landmarks) {
      const size_t v = nearest_vertex(ref.mesh, l.position);
      ref.landmark_vertex[l.name] = v;
      ref.landmark_offset[l.name] = l.position - ref.mesh.vertices[v].cast<double>();
    }
    for (const BodyMeasurement& m : ref.measured.measurements) {
      std::vector<size_t>& vs = ref.measurement_vertices[m.name];
      const auto& pts = m.kind == "height" ? std::vector<Eigen::Vector3d>{m.path.back()} : m.path;
      for (const Eigen::Vector3d& p : pts) vs.push_back(nearest_vertex(ref.mesh, p));
      for (const Eigen::Vector3d& p : m.loop) vs.push_back(nearest_vertex(ref.mesh, p));
      // And the landmarks it is read from (a height's level can come from others).
      for (const std::string& l : m.landmarks) vs.push_back(ref.landmark_vertex.at(l));
    }
    struct Variant {
      std::string name;
      TriangleMesh mesh;
      Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
      bool posed = false;
      hw::sim::PostureJoints joints;  // the skeleton's, for the posture found
    };
    auto rest_pose = (*poser)->pose(ref.mesh, {});
    if (!rest_pose.ok()) {
      std::fprintf(stderr, "posture_benchmark: %s: %s\n", ref.name.c_str(), rest_pose.status().message().c_str());
      return 1;
    }
    std::vector<Variant> variants;
    for (double t : turns) {
      Variant v;
      char b[64];
      std::snprintf(b, sizeof b, "turned %+.0f deg, moved %.0f mm", t, shift);
      v.name = b;
      const double dir = t * M_PI / 180;
      v.motion = Eigen::Translation3d(shift * std::cos(3 * dir), 0, shift * std::sin(3 * dir)) *
                 Eigen::AngleAxisd(dir, Eigen::Vector3d::UnitY());
      v.mesh = transformed(ref.mesh, v.motion);
      v.joints = rest_pose->rest;
      variants.push_back(std::move(v));
    }
    auto pose = [&](const std::string& name, const hw::SubjectPosture& p) {
      auto posed = (*poser)->pose(ref.mesh, p);
      if (!posed.ok()) {
        std::fprintf(stderr, "posture_benchmark: %s %s: %s\n", ref.name.c_str(), name.c_str(),
                     posed.status().message().c_str());
        return;
      }
      variants.push_back({name, std::move(posed->mesh), Eigen::Isometry3d::Identity(), true, posed->posed});
    };
    for (double a : arms) {
      hw::SubjectPosture p;
      p.arm_abduction_deg = {a, a};
      pose("arms " + std::to_string(static_cast<int>(a)) + " deg", p);
    }
    for (double f : feet) {
      hw::SubjectPosture p;
      p.ankle_distance_mm = f;
      pose("ankles " + std::to_string(static_cast<int>(f)) + " mm apart", p);
    }
    {
      hw::SubjectPosture p;
      p.arm_abduction_deg = {18.0, 30.0};
      p.ankle_distance_mm = 220;
      pose("arms 18/30 deg, ankles 220 mm", p);
    }
    for (Variant& v : variants) {
      auto got = measure_body(v.mesh);
      if (!got.ok()) {
        std::printf("| %s | %s | not measured: %s ||||||||||\n", ref.name.c_str(), v.name.c_str(),
                    got.status().message().c_str());
        all.push_back({{"body", ref.name}, {"variant", v.name}, {"error", got.status().message()}});
        continue;
      }
      const Row r = compare(ref, v.name, v.mesh, *got, v.motion, v.posed, detail);
      std::printf("| %s | %s |", ref.name.c_str(), v.name.c_str());
      nlohmann::json j = {{"body", ref.name}, {"variant", v.name}};
      for (const char* f : kFamilies) {
        const auto it = r.largest.find(f);
        const double x = it == r.largest.end() ? 0 : it->second.first;
        std::printf(" %.1f |", x);
        j["largest_change_mm"][f] = {{"value", x}, {"measurement", it == r.largest.end() ? "" : it->second.second}};
      }
      std::printf(" %zu / %zu | %s | %.1f / %.1f (%s) |", r.unmoved_within_half, r.unmoved,
                  v.posed ? (std::to_string(r.arm_length_error).substr(0, 4) + " mm").c_str() : "-", r.landmark_median,
                  r.landmark_max, r.landmark_worst.c_str());
      const BodyPosture& found = got->posture;
      double arm_error[2] = {NAN, NAN};
      for (int k = 0; k < 2; ++k)
        if (found.arm_abduction_deg[k]) arm_error[k] = *found.arm_abduction_deg[k] - v.joints.arm_abduction_deg(k);
      const double ankle_error =
          found.ankle_distance_mm ? *found.ankle_distance_mm - v.joints.ankle_distance_mm() : NAN;
      std::printf(" %+.1f / %+.1f | %+.0f mm | %+.1f |\n", arm_error[0], arm_error[1], ankle_error, found.turn_deg);
      j["arm_abduction_error_deg"] = {arm_error[0], arm_error[1]};
      j["ankle_distance_error_mm"] = ankle_error;
      j["unmoved_values"] = r.unmoved;
      j["unmoved_within_half_allowance"] = r.unmoved_within_half;
      j["landmark_median_mm"] = r.landmark_median;
      j["landmark_max_mm"] = r.landmark_max;
      j["landmark_worst"] = r.landmark_worst;
      if (v.posed) j["outer_arm_length_error_mm"] = r.arm_length_error;
      j["turn_found_deg"] = got->frame.turn_deg;
      all.push_back(j);
      for (const std::string& d : r.detail) std::printf("|   | %s ||||||||||\n", d.c_str());
    }
    std::fflush(stdout);
  }
  if (!json_out.empty() && !bench::write_figures(json_out, run_info, all)) return 1;
  return 0;
}
