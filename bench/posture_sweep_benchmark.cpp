// The posture check before a scan (pipeline/posture_sweep.hpp), judged on the
// simulated rig: for each posture the subject is posed in, the posture the quick
// sweep reads against the one the full automatic set reads on the posed true mesh,
// whether the two agree on every check the sweep makes (arms, feet, turn), and how
// long the sweep takes.
//
//   posture_sweep_benchmark [--rig thesis|tiered|R.json] [--body X.ply] [--every N]
//                           [--json OUT.json] [ARMS,FEET,TURN ...]
//
// Default postures: the scanning posture, turned and not, and the ways customers
// stand outside it (arms low, feet close, turned past 30 degrees). The time of a
// real rig's sweep is the frames each camera takes at the description's frame rate
// (the simulator renders slower than a camera records). --json also writes each
// posture's figures (bench/json_figures.hpp) for bench/tables.py.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/json_figures.hpp"
#include "core/command_line.hpp"
#include "hw/sim/sim_rig.hpp"
#include "pipeline/posture_sweep.hpp"
#include "pipeline/rig_backend.hpp"
#include "recon/measure/body_measurements.hpp"

namespace {
using namespace bodyscan;

struct Case {
  double arms = 0, feet = 0, turn = 0;
};

std::string angle(const std::optional<double>& a) {
  char b[32];
  if (!a) return "-";
  std::snprintf(b, sizeof b, "%.1f", *a);
  return b;
}

nlohmann::json value(const std::optional<double>& a) { return a ? nlohmann::json(*a) : nlohmann::json(); }

nlohmann::json posture_json(const BodyPosture& p) {
  return {{"arm_left_deg", value(p.arm_abduction_deg[0])},
          {"arm_right_deg", value(p.arm_abduction_deg[1])},
          {"ankles_mm", value(p.ankle_distance_mm)},
          {"turn_deg", value(p.turn_deg)}};
}

// "read / truth" per part: arms left and right (deg), ankles (mm), turn (deg).
std::string pair(const std::optional<double>& sweep, const std::optional<double>& truth) {
  return angle(sweep) + " / " + angle(truth);
}

int run(const std::string& rig_name, const std::string& body, int every, const std::vector<Case>& cases,
        nlohmann::json& records) {
  std::printf("rig %s, body %s, every %d laser steps\n\n", rig_name.c_str(),
              body.empty() ? "(the rig's)" : body.c_str(), every);
  std::printf(
      "| posed: arms, ankles, turn | sweep / truth: arm left (deg) | arm right (deg) | ankles (mm) | turn (deg) "
      "| checks agree | frames per camera | at the frame rate (s) | processing (s) |\n");
  std::printf("|---|---|---|---|---|---|---:|---:|---:|\n");
  std::optional<pipeline::RigCalibration> calibration;
  int disagreements = 0;
  for (const Case& c : cases) {
    pipeline::SimulatedSubject s;
    s.body = body;
    s.posture.arm_abduction_deg = {c.arms, c.arms};
    s.posture.ankle_distance_mm = c.feet;
    s.turn_deg = c.turn;
    StatusOr<std::unique_ptr<hw::sim::SimulatedRig>> sim = pipeline::open_simulated_rig(rig_name, s);
    if (!sim.ok()) return std::fprintf(stderr, "%s\n", sim.status().message().c_str()), 1;
    const hw::RigDescription& desc = (*sim)->description();
    const pipeline::Rig rig = pipeline::rig_handle(**sim);
    if (!calibration) {  // the rig, not the subject: calibrated once
      StatusOr<pipeline::RigCalibration> cal = pipeline::calibrate_rig(rig);
      if (!cal.ok()) return std::fprintf(stderr, "%s\n", cal.status().message().c_str()), 1;
      calibration = std::move(*cal);
    }
    pipeline::PostureSweepOptions o;
    o.every = every;
    StatusOr<pipeline::PostureSweep> sweep = pipeline::sweep_posture(rig, *calibration, o);
    BodyMeasureOptions mo;
    mo.floor_y = -0.5 * desc.frame.tube;
    StatusOr<BodyMeasurements> truth = measure_body((*sim)->scene().subject(), mo);
    std::printf("| %g, %g, %+g | ", c.arms, c.feet, c.turn);
    nlohmann::json record = {{"rig", desc.name},
                             {"body", body.empty() ? desc.simulation.subject : body},
                             {"every", every},
                             {"posed", {{"arms_deg", c.arms}, {"ankles_mm", c.feet}, {"turn_deg", c.turn}}}};
    if (!sweep.ok() || !truth.ok()) {
      const std::string error = (!sweep.ok() ? sweep.status() : truth.status()).message();
      std::printf("%s |\n", error.c_str());
      record["error"] = error;
      records.push_back(std::move(record));
      ++disagreements;
      continue;
    }
    const BodyPosture &p = sweep->posture, &t = truth->posture;
    // The parts whose check the sweep and the truth decide differently.
    std::string differ;
    size_t checked = 0;
    for (const PostureCheck& tc : truth->posture_checks) checked += tc.part == "head" ? 0 : 1;
    for (const PostureCheck& sc : sweep->checks) {
      bool same = false;
      for (const PostureCheck& tc : truth->posture_checks) same = same || (tc.part == sc.part && tc.ok == sc.ok);
      if (!same)
        differ += (differ.empty() ? "" : ", ") + sc.part + (sc.ok ? " (sweep ok)" : " (sweep: " + sc.message + ")");
    }
    const bool agree = differ.empty() && sweep->checks.size() == checked;
    disagreements += agree ? 0 : 1;
    const double per_camera = static_cast<double>(sweep->frames) / static_cast<double>(desc.cameras.size());
    std::printf("%s | %s | %s | %s | %s | %.0f | %.1f | %.2f |\n",
                pair(p.arm_abduction_deg[0], t.arm_abduction_deg[0]).c_str(),
                pair(p.arm_abduction_deg[1], t.arm_abduction_deg[1]).c_str(),
                pair(p.ankle_distance_mm, t.ankle_distance_mm).c_str(), pair(p.turn_deg, t.turn_deg).c_str(),
                agree ? "yes" : ("no: " + differ).c_str(), per_camera, per_camera / desc.simulation.frame_rate_hz,
                sweep->processing_seconds);
    std::fflush(stdout);
    record["sweep"] = posture_json(p);
    record["truth"] = posture_json(t);
    record["agree"] = agree;
    record["differ"] = differ;
    record["frames_per_camera"] = per_camera;
    record["camera_seconds"] = per_camera / desc.simulation.frame_rate_hz;
    record["processing_seconds"] = sweep->processing_seconds;
    records.push_back(std::move(record));
  }
  std::printf("\n%d of %zu postures where the sweep's checks and the truth's disagree\n", disagreements, cases.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string rig = "thesis", body, json_out;
  int every = bodyscan::pipeline::kPostureSweepEvery;
  std::vector<Case> cases;
  std::vector<std::string> case_args;
  CommandLine cl(
      "posture_sweep_benchmark",
      "usage: posture_sweep_benchmark [--rig R] [--body X.ply] [--every N] [--json OUT] [ARMS,FEET,TURN ...]\n");
  cl.option("--rig", &rig);
  cl.option("--body", &body);
  cl.option("--every", integer_between(1, 1000000, [&every](long long n) { every = static_cast<int>(n); }));
  cl.option("--json", &json_out);
  cl.rest("ARMS,FEET,TURN ...", &case_args);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const nlohmann::json run_info = bodyscan::bench::run_record(argc, argv);  // the tree as the run starts
  for (const std::string& a : case_args) {
    const auto v = parse_number_list(a, 3);
    if (!v) return cl.fail("a case is ARMS,FEET,TURN, not '" + a + "'");
    cases.push_back(Case{(*v)[0], (*v)[1], (*v)[2]});
  }
  if (cases.empty())
    cases = {{42, 380, 0}, {40, 350, 20}, {45, 420, -25}, {20, 300, 0}, {30, 250, 10}, {42, 150, 0}, {42, 380, 40}};
  nlohmann::json records = nlohmann::json::array();
  const int rc = run(rig, body, every, cases, records);
  if (rc == 0 && !json_out.empty() && !bodyscan::bench::write_figures(json_out, run_info, records)) return 1;
  return rc;
}
