// The most a rig layout can cover of a body, without rendering: the share of the
// body's area that some camera sees while a laser that camera works with (one on
// its side of the frame) lights it within its sweep, at an incidence and a
// triangulation angle the scan can use. For choosing where cameras and lasers go.
// It also reports how close the body comes to hiding a frame light from a camera
// (calibration needs all eight unobstructed; a half-hidden light moves its centroid):
// the smallest clearance, in mm around the light's centre, that every camera has.
//
//   rig_coverage [--rig thesis|square|tiered|FILE]... [--body BODY.ply] [--min-angle DEG]
//                [--max-view DEG] [--cross] [--json OUT.json]
//
// --max-view counts a camera only within DEG of the surface's normal (default 90:
// any camera in front of it; the scan drops views beyond the rig's max_view_deg).
// --json also writes each rig's figures (bench/json_figures.hpp) for bench/tables.py.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "bench/body_region.hpp"
#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "pipeline/rig_backend.hpp"
#include "recon/geometry/sample_surface.hpp"

using namespace bodyscan;

int main(int argc, char** argv) {
  std::vector<std::string> rigs;
  std::string body, json_out;
  double min_angle = 8, min_incidence = 0.1, max_view = 90;
  bool cross = false;
  CommandLine cl("rig_coverage",
                 "usage: rig_coverage [--rig R]... [--body BODY.ply] [--min-angle DEG] [--max-view DEG] [--cross] "
                 "[--json OUT]\n");
  cl.option("--rig", &rigs);
  cl.option("--body", &body);
  cl.option("--min-angle", &min_angle);
  cl.option("--max-view", &max_view);
  cl.flag("--cross", &cross);
  cl.option("--json", &json_out);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  if (rigs.empty()) rigs = hw::shipped_rig_names();  // all of them
  const nlohmann::json run = bench::run_record(argc, argv);
  nlohmann::json records = nlohmann::json::array();
  for (const std::string& name : rigs) {
    pipeline::SimulatedSubject subject;
    subject.body = body;
    auto sim = pipeline::open_simulated_rig(name, subject);
    if (!sim.ok()) return std::fprintf(stderr, "%s\n", sim.status().message().c_str()), 1;
    const hw::RigDescription& desc = (*sim)->description();
    const hw::sim::Scene& scene = (*sim)->scene();
    std::vector<hw::CameraModel> cams;
    for (const auto& c : desc.cameras) cams.push_back(c.model());
    const PointCloud s = sample_mesh_uniform(scene.subject(), 60000, 3, true);
    size_t covered = 0, seen = 0, lit = 0;
    // Where the tailor's measurements hang from an unseen surface (docs/measurements.md):
    // the crotch, the shoulders' tops, the forearms held out from the sides.
    float floor_y = 1e9f, top_y = -1e9f;
    for (const Vec3f& p : s.positions) floor_y = std::min(floor_y, p.y()), top_y = std::max(top_y, p.y());
    const float height = top_y - floor_y;
    const auto zone = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& n) -> int {
      const double h = (p.y() - floor_y) / height;
      if (h > 0.40 && h < 0.50 && std::abs(p.x()) < 100 && n.y() < -0.3) return 0;
      if (h > 0.78 && h < 0.86 && std::abs(p.x()) > 60 && n.y() > 0.5) return 1;
      if (h > 0.45 && h < 0.65 && std::abs(p.x()) > 300) return 2;
      return -1;
    };
    const char* zone_names[3] = {"crotch", "shoulder tops", "forearms"};
    size_t zone_total[3] = {0, 0, 0}, zone_covered[3] = {0, 0, 0};
    std::map<std::string, size_t> holes;
    for (size_t i = 0; i < s.size(); ++i) {
      const Eigen::Vector3d p = s.positions[i].cast<double>(), n = s.normals[i].cast<double>();
      const Eigen::Vector3d q = p + 0.2 * n;
      bool any_seen = false, any_lit = false, ok = false;
      for (size_t c = 0; c < cams.size() && !ok; ++c) {
        const Eigen::Vector3d to_cam = cams[c].centre() - p;
        if (n.dot(to_cam) <= std::cos(max_view * M_PI / 180) * to_cam.norm()) continue;
        const auto px = cams[c].project(p);
        if (!px || !cams[c].in_image(*px) || scene.occluded(q, to_cam.normalized(), to_cam.norm())) continue;
        any_seen = true;
        const bool front_camera = cams[c].centre().z() > 0;
        for (const hw::LaserDescription& l : desc.lasers) {
          if (!cross && (l.position.z() > 0) != front_camera)
            continue;  // the camera sees only its side's lasers on the poles
          const Eigen::Vector3d to_laser = l.position - p;
          const double incidence = n.dot(to_laser.normalized());
          if (incidence < min_incidence || scene.occluded(q, to_laser.normalized(), to_laser.norm())) continue;
          // Within the sweep: the plane through the point contains the axis; its angle from the aim.
          const Eigen::Vector3d axis = l.axis.normalized();
          Eigen::Vector3d d = p - l.position;
          d -= d.dot(axis) * axis;
          const double angle = std::atan2(l.aim.cross(d).dot(axis), l.aim.dot(d)) * 180 / M_PI;
          if (angle < l.min_step * l.step_angle_deg || angle > l.max_step * l.step_angle_deg) continue;
          any_lit = true;
          const Eigen::Vector3d plane_n = axis.cross(d.normalized());
          const double tri = std::asin(std::min(1.0, std::abs(plane_n.dot(to_cam.normalized())))) * 180 / M_PI;
          if (tri >= min_angle) ok = true;
        }
      }
      seen += any_seen;
      lit += any_lit;
      covered += ok;
      if (const int z = zone(p, n); z >= 0) zone_total[z]++, zone_covered[z] += ok;
      if (!ok) {
        holes[bench::body_region(p, n) + (any_seen ? (any_lit ? " (angle)" : " (unlit)") : " (unseen)")]++;
      }
    }
    // Light clearance: the largest radius (to 100 mm, in 5 mm steps) around each
    // light's centre, in the plane of its face, that the body hides from no camera.
    double clearance = 1e9;
    std::string tightest;
    for (size_t c = 0; c < cams.size(); ++c) {
      const Eigen::Vector3d o = cams[c].centre();
      for (const Eigen::Vector3d& light : hw::visible_lights(desc.frame, o.z() > 0)) {
        double clear = 0;
        for (double r = 5; r <= 100; r += 5) {
          bool hidden = false;
          for (int k = 0; k < 24 && !hidden; ++k) {
            const double a = 2 * M_PI * k / 24;
            const Eigen::Vector3d rim = light + r * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
            const Eigen::Vector3d to = rim - o;
            hidden = scene.intersect(o, to.normalized(), 1e-3, to.norm()).surface == hw::sim::Surface::kSubject;
          }
          if (hidden) break;
          clear = r;
        }
        if (clear < clearance) {
          clearance = clear;
          char buf[160];
          std::snprintf(buf, sizeof buf, "camera %s, light (%.0f, %.0f, %.0f)", desc.cameras[c].id.c_str(), light.x(),
                        light.y(), light.z());
          tightest = buf;
        }
      }
    }
    std::printf(
        "%s: covered %.1f %% of the body's area (seen by a camera %.1f %%); lights clear by %.0f mm (tightest: %s); "
        "missing:",
        desc.name.c_str(), 100.0 * covered / s.size(), 100.0 * seen / s.size(), clearance, tightest.c_str());
    std::vector<std::pair<size_t, std::string>> by;
    for (const auto& [k, v] : holes) by.emplace_back(v, k);
    std::sort(by.rbegin(), by.rend());
    for (size_t k = 0; k < std::min<size_t>(8, by.size()); ++k)
      std::printf("%s %s %.1f %%", k ? "," : "", by[k].second.c_str(), 100.0 * by[k].first / s.size());
    std::printf("\n  zones:");
    nlohmann::json zones;  // name: % covered
    for (int z = 0; z < 3; ++z) {
      const double percent = zone_total[z] ? 100.0 * zone_covered[z] / zone_total[z] : 0.0;
      zones[zone_names[z]] = percent;
      std::printf(" %s %.1f %% of %.0f cm2%s", zone_names[z], percent,
                  zone_total[z] * surface_area(scene.subject()) / s.size() / 100.0, z < 2 ? "," : "");
    }
    std::printf("\n");
    const std::string body_name = std::filesystem::path(body.empty() ? desc.simulation.subject : body).stem().string();
    records.push_back({{"rig", desc.name},
                       {"body", body_name},
                       {"max_view_deg", max_view},
                       {"min_angle_deg", min_angle},
                       {"covered_percent", 100.0 * covered / s.size()},
                       {"seen_percent", 100.0 * seen / s.size()},
                       {"light_clearance_mm", clearance},
                       {"zones_covered_percent", zones}});
  }
  if (!json_out.empty() && !bench::write_figures(json_out, run, records)) return 1;
  return 0;
}
