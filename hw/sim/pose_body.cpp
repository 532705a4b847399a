#include "hw/sim/pose_body.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>

namespace bodyscan::hw::sim {

namespace {

// The subdivided hm08 body: vertices 0..kHm08-1 are the hm08 body vertices, then
// one edge point per hm08 edge, then one face point per hm08 quad.
constexpr size_t kHm08 = 13380;
constexpr size_t kBodyVertices = 53514;
constexpr size_t kBodyTriangles = 107024;
// MakeHuman drops a vertex's normalised weights at or below this.
constexpr double kDroppedWeight = 1e-4;
// A body-only joint computed from a body file's vertices (which the subdivision
// moved to their vertex points) lies within 4 mm of joints.json's on the right body.
constexpr double kJointMatchMm = 6;

StatusOr<nlohmann::json> read_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) return io_error("cannot read " + path);
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return invalid_argument(path + " is not valid JSON");
  return j;
}

double deg(double rad) { return rad * 180.0 / M_PI; }
double rad(double deg) { return deg * M_PI / 180.0; }

// Angle of v from the downward vertical, degrees.
double from_down(const Eigen::Vector3d& v) { return deg(std::acos(std::clamp(-v.y() / v.norm(), -1.0, 1.0))); }

// The x in [lo, hi] where f reaches `target`, f falling to its one minimum in that
// range and rising after it: on the rising side, to `tol`; nothing when out of reach.
std::optional<double> solve_rising(const std::function<double(double)>& f, double lo, double hi, double target,
                                   double tol) {
  double a = lo, b = hi;  // golden-section search for the minimum
  const double r = (std::sqrt(5.0) - 1) / 2;
  while (b - a > tol) {
    const double c = b - r * (b - a), d = a + r * (b - a);
    (f(c) < f(d) ? b : a) = f(c) < f(d) ? d : c;
  }
  lo = 0.5 * (a + b);
  if (f(lo) > target || f(hi) < target) return std::nullopt;
  while (hi - lo > tol) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

const char* kSide[2] = {"L", "R"};

}  // namespace

double PostureJoints::arm_abduction_deg(int side) const { return from_down(elbow[side] - shoulder[side]); }

StatusOr<BodyPoser> BodyPoser::load(const std::string& dir) {
  ASSIGN_OR_RETURN(nlohmann::json skel, read_json(dir + "/default.mhskel"));
  ASSIGN_OR_RETURN(nlohmann::json weights, read_json(dir + "/default_weights.mhw"));
  ASSIGN_OR_RETURN(nlohmann::json joints, read_json(dir + "/joints.json"));
  BodyPoser p;
  try {
    for (const auto& [name, b] : skel.at("bones").items()) {
      p.bone_index_[name] = static_cast<int>(p.bones_.size());
      p.bones_.push_back({name, b.at("head").get<std::string>(), -1});
    }
    for (const auto& [name, b] : skel.at("bones").items()) {
      if (b.at("parent").is_null()) continue;
      const auto it = p.bone_index_.find(b.at("parent").get<std::string>());
      if (it == p.bone_index_.end()) return invalid_argument("default.mhskel: bone " + name + " has an unknown parent");
      p.bones_[p.bone_index_[name]].parent = it->second;
    }
    for (const auto& [name, v] : skel.at("joints").items()) p.joint_vertices_[name] = v.get<std::vector<int>>();
    std::vector<std::vector<std::pair<int, double>>> raw(kHm08);
    for (const auto& [bone, list] : weights.at("weights").items()) {
      const auto it = p.bone_index_.find(bone);
      if (it == p.bone_index_.end()) continue;
      for (const auto& vw : list) {
        const int v = vw.at(0).get<int>();
        if (v >= 0 && static_cast<size_t>(v) < kHm08) raw[v].emplace_back(it->second, vw.at(1).get<double>());
      }
    }
    p.hm08_weights_.resize(kHm08);
    for (size_t v = 0; v < kHm08; ++v) {
      double sum = 0;
      for (const auto& [b, w] : raw[v]) sum += w;
      if (!(sum > 0))
        return invalid_argument("default_weights.mhw: hm08 vertex " + std::to_string(v) + " has no weight");
      for (const auto& [b, w] : raw[v])
        if (w / sum > kDroppedWeight) p.hm08_weights_[v].emplace_back(b, static_cast<float>(w / sum));
    }
    for (const auto& [body, entry] : joints.at("bodies").items())
      for (const auto& [name, xyz] : entry.at("joints").items())
        p.rest_joints_[body][name] = {xyz.at(0).get<double>(), xyz.at(1).get<double>(), xyz.at(2).get<double>()};
  } catch (const nlohmann::json::exception& e) {
    return invalid_argument("the skeleton in " + dir + " is malformed: " + e.what());
  }
  if (p.rest_joints_.empty()) return invalid_argument(dir + "/joints.json lists no bodies");
  return p;
}

StatusOr<const BodyPoser*> BodyPoser::shipped() {
  static std::once_flag once;
  static StatusOr<BodyPoser> poser = internal_error("not loaded");
  std::call_once(once, [] { poser = load(std::string(BODYSCAN_DATA_DIR) + "/hw/sim/bodies/skeleton"); });
  if (!poser.ok()) return poser.status();
  return &*poser;
}

StatusOr<BodyPoser::Match> BodyPoser::recognise(const TriangleMesh& rest) const {
  if (rest.vertices.size() != kBodyVertices || rest.triangles.size() != kBodyTriangles)
    return invalid_argument("posing needs a MakeHuman body (53,514 vertices, 107,024 triangles); this mesh has " +
                            std::to_string(rest.vertices.size()) + " and " + std::to_string(rest.triangles.size()));
  // The joints made of body vertices only, computed from this mesh, against each
  // body's: the right body matches them all, up to where it stands.
  std::optional<Match> best;
  double best_err = std::numeric_limits<double>::infinity();
  for (const auto& [body, joints] : rest_joints_) {
    std::vector<Eigen::Vector3d> diffs;
    for (const auto& [name, idx] : joint_vertices_) {
      if (idx.empty() || !joints.count(name)) continue;
      if (std::any_of(idx.begin(), idx.end(), [](int v) { return v < 0 || static_cast<size_t>(v) >= kHm08; })) continue;
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int v : idx) c += rest.vertices[v].cast<double>();
      diffs.push_back(c / static_cast<double>(idx.size()) - joints.at(name));
    }
    if (diffs.empty()) continue;
    Eigen::Vector3d shift;
    for (int k = 0; k < 3; ++k) {
      std::vector<double> d;
      for (const auto& x : diffs) d.push_back(x[k]);
      std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
      shift[k] = d[d.size() / 2];
    }
    double worst = 0;
    for (const auto& x : diffs) worst = std::max(worst, (x - shift).norm());
    if (worst < best_err) best_err = worst, best = Match{body, shift};
  }
  if (!best || best_err > kJointMatchMm)
    return invalid_argument(
        "this mesh is not one of the MakeHuman bodies in its rest pose whose skeleton is shipped "
        "(joints.json); the nearest is " +
        std::to_string(best_err) + " mm off");
  return *best;
}

Eigen::Vector3d BodyPoser::joint(const Match& m, const std::string& name) const {
  return rest_joints_.at(m.body).at(name) + m.shift;
}

StatusOr<std::vector<std::vector<std::pair<int, float>>>> BodyPoser::vertex_weights(const TriangleMesh& rest) const {
  const size_t nv = rest.vertices.size();
  const size_t f0 = nv - rest.triangles.size() / 8;  // each hm08 quad became 8 triangles
  std::vector<std::vector<uint32_t>> ends(f0 - kHm08), edge_points(nv - f0);
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  edges.reserve(rest.triangles.size() * 3);
  for (const Triangle& t : rest.triangles)
    for (int e = 0; e < 3; ++e) edges.emplace_back(std::minmax(t[e], t[(e + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) {
    if (a < kHm08 && b >= kHm08 && b < f0) ends[b - kHm08].push_back(a);
    if (a >= kHm08 && a < f0 && b >= f0) edge_points[b - f0].push_back(a);
  }
  std::vector<std::vector<std::pair<int, float>>> w(nv);
  auto mean_of = [&](const std::vector<uint32_t>& corners) {
    std::map<int, double> sum;
    for (uint32_t c : corners)
      for (const auto& [b, x] : hm08_weights_[c]) sum[b] += x;
    double total = 0;
    for (const auto& [b, x] : sum) total += x;
    std::vector<std::pair<int, float>> out;
    for (const auto& [b, x] : sum) out.emplace_back(b, static_cast<float>(x / total));
    return out;
  };
  for (size_t v = 0; v < kHm08; ++v) w[v] = mean_of({static_cast<uint32_t>(v)});
  for (size_t e = 0; e < ends.size(); ++e) {
    if (ends[e].size() != 2) return invalid_argument("not a subdivided hm08 mesh: an edge point without two hm08 ends");
    w[kHm08 + e] = mean_of(ends[e]);
  }
  for (size_t f = 0; f < edge_points.size(); ++f) {
    if (edge_points[f].size() != 4)
      return invalid_argument("not a subdivided hm08 mesh: a face point without four edges");
    std::vector<uint32_t> corners;
    for (uint32_t e : edge_points[f]) corners.insert(corners.end(), ends[e - kHm08].begin(), ends[e - kHm08].end());
    w[f0 + f] = mean_of(corners);
  }
  return w;
}

StatusOr<TriangleMesh> BodyPoser::skin(
    const TriangleMesh& rest, const std::map<std::string, std::pair<Eigen::Vector3d, double>>& rotations) const {
  ASSIGN_OR_RETURN(const Match m, recognise(rest));
  return skin(rest, m, rotations);
}

StatusOr<TriangleMesh> BodyPoser::skin(
    const TriangleMesh& rest, const Match& m,
    const std::map<std::string, std::pair<Eigen::Vector3d, double>>& rotations) const {
  ASSIGN_OR_RETURN(const auto weights, vertex_weights(rest));
  std::vector<Eigen::Isometry3d> local(bones_.size(), Eigen::Isometry3d::Identity());
  for (const auto& [bone, rot] : rotations) {
    const auto it = bone_index_.find(bone);
    if (it == bone_index_.end()) return invalid_argument("no bone " + bone + " in the skeleton");
    const Eigen::Vector3d h = joint(m, bones_[it->second].head);
    const Eigen::Matrix3d r = Eigen::AngleAxisd(rad(rot.second), rot.first.normalized()).toRotationMatrix();
    local[it->second].linear() = r;
    local[it->second].translation() = h - r * h;
  }
  // A bone's global transform: its parent's times its own, root first.
  std::vector<std::optional<Eigen::Isometry3d>> global(bones_.size());
  std::function<const Eigen::Isometry3d&(int)> g = [&](int b) -> const Eigen::Isometry3d& {
    if (!global[b]) global[b] = bones_[b].parent < 0 ? local[b] : g(bones_[b].parent) * local[b];
    return *global[b];
  };
  std::vector<bool> moved(bones_.size());
  for (size_t b = 0; b < bones_.size(); ++b)
    moved[b] = !g(static_cast<int>(b)).isApprox(Eigen::Isometry3d::Identity(), 0);
  TriangleMesh out = rest;
  for (size_t v = 0; v < rest.vertices.size(); ++v) {
    // A vertex on unmoved bones only keeps its coordinates bit for bit.
    if (std::none_of(weights[v].begin(), weights[v].end(), [&](const auto& bw) { return moved[bw.first]; })) continue;
    const Eigen::Vector3d p = rest.vertices[v].cast<double>();
    Eigen::Vector3d q = Eigen::Vector3d::Zero();
    double total = 0;
    for (const auto& [b, x] : weights[v]) q += static_cast<double>(x) * (*global[b] * p), total += x;
    out.vertices[v] = (q / total).cast<float>();
  }
  out.normals.clear();
  return out;
}

StatusOr<PosedBody> BodyPoser::pose(const TriangleMesh& rest, const Posture& posture) const {
  ASSIGN_OR_RETURN(const Match m, recognise(rest));
  PosedBody out;
  out.body = m.body;
  for (int s = 0; s < 2; ++s) {
    const std::string x = kSide[s];
    out.rest.shoulder[s] = joint(m, "upperarm01." + x + "____head");
    out.rest.elbow[s] = joint(m, "lowerarm01." + x + "____head");
    out.rest.wrist[s] = joint(m, "wrist." + x + "____head");
    out.rest.hip[s] = joint(m, "upperleg01." + x + "____head");
    out.rest.ankle[s] = joint(m, "foot." + x + "____head");
  }
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  auto turned = [](const Eigen::Vector3d& p, const Eigen::Vector3d& about, double degrees) {
    return (Eigen::AngleAxisd(rad(degrees), Eigen::Vector3d::UnitZ()) * (p - about) + about).eval();
  };
  std::map<std::string, std::pair<Eigen::Vector3d, double>> rotations;
  for (int s = 0; s < 2; ++s) {
    if (!posture.arm_abduction_deg[s]) continue;
    const double want = *posture.arm_abduction_deg[s];
    if (!(want >= 0 && want <= 80)) return invalid_argument("an arm's abduction must be 0-80 degrees");
    // About +Z a positive turn raises the left arm (+X) and lowers the right.
    const double sign = s == 0 ? 1 : -1;
    const Eigen::Vector3d sh = out.rest.shoulder[s], el = out.rest.elbow[s];
    const std::optional<double> t =
        solve_rising([&](double deg) { return from_down(turned(el, sh, sign * deg) - sh); }, -60, 60, want, 1e-5);
    if (!t) return invalid_argument("an arm's abduction of " + std::to_string(want) + " degrees is out of reach");
    rotations["upperarm01." + std::string(kSide[s])] = {z, sign * *t};
    out.shoulder_rotation_deg[s] = sign * *t;
  }
  if (posture.ankle_distance_mm) {
    const double want = *posture.ankle_distance_mm;
    if (!(want >= 100 && want <= 700)) return invalid_argument("the ankles' distance must be 100-700 mm");
    // Spreading the legs by a turns the left leg (+X) by +a about +Z and the right
    // by -a: the ankles part as a grows (until then they cross).
    const auto apart = [&](double a) {
      return (turned(out.rest.ankle[0], out.rest.hip[0], a) - turned(out.rest.ankle[1], out.rest.hip[1], -a)).norm();
    };
    const std::optional<double> spread = solve_rising(apart, -30, 30, want, 1e-5);
    if (!spread) return invalid_argument("an ankle distance of " + std::to_string(want) + " mm is out of reach");
    out.hip_adduction_deg = -*spread;
    rotations["upperleg01.L"] = {z, *spread};
    rotations["upperleg01.R"] = {z, -*spread};
    // The feet turn back about the ankles: their soles stay flat.
    rotations["foot.L"] = {z, -*spread};
    rotations["foot.R"] = {z, *spread};
  }
  ASSIGN_OR_RETURN(out.mesh, skin(rest, m, rotations));
  // Standing on the floor again: the lowest point where the rest mesh's was.
  float rest_low = std::numeric_limits<float>::infinity(), posed_low = rest_low;
  for (const Vec3f& v : rest.vertices) rest_low = std::min(rest_low, v.y());
  for (const Vec3f& v : out.mesh.vertices) posed_low = std::min(posed_low, v.y());
  const Eigen::Vector3d lift(0, static_cast<double>(rest_low) - posed_low, 0);
  for (Vec3f& v : out.mesh.vertices) v += lift.cast<float>();
  for (int s = 0; s < 2; ++s) {
    const double arm = out.shoulder_rotation_deg[s];
    const double leg = s == 0 ? -out.hip_adduction_deg : out.hip_adduction_deg;
    out.posed.shoulder[s] = out.rest.shoulder[s] + lift;
    out.posed.elbow[s] = turned(out.rest.elbow[s], out.rest.shoulder[s], arm) + lift;
    out.posed.wrist[s] = turned(out.rest.wrist[s], out.rest.shoulder[s], arm) + lift;
    out.posed.hip[s] = out.rest.hip[s] + lift;
    out.posed.ankle[s] = turned(out.rest.ankle[s], out.rest.hip[s], leg) + lift;
  }
  return out;
}

}  // namespace bodyscan::hw::sim
