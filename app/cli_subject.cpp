#include "app/cli_subject.hpp"

#include <cmath>
#include <optional>
#include <vector>

namespace bodyscan::cli {

const char* const kSubjectOptionsHelp =
    "  --body BODY.ply  the simulated subject (mm, Y up; default: the rig's)\n"
    "  --arms DEG[,DEG] its upper arms DEG from the vertical (left,right), posed\n"
    "                   by skinning a MakeHuman body (the demo bodies are)\n"
    "  --feet MM        its ankle joints MM apart, posed the same way\n"
    "  --turn DEG       turned DEG about the vertical (+: the face toward +X)\n"
    "  --at X,Z         standing with its centre at X,Z on the floor (mm)\n";

namespace {

// Comma-separated finite numbers, `min_count` to `max_count` of them.
std::optional<std::vector<double>> numbers(const std::string& text, size_t min_count, size_t max_count) {
  auto v = parse_number_list(text);
  if (!v || v->size() < min_count || v->size() > max_count) return std::nullopt;
  return v;
}

}  // namespace

void add_subject_options(CommandLine* cl, pipeline::SimulatedSubject* subject) {
  cl->option("--body", &subject->body);
  cl->option("--arms", [subject](const std::string& value) -> std::string {
    const auto v = numbers(value, 1, 2);
    if (!v || (*v)[0] < 0 || (*v)[0] > 80 || v->back() < 0 || v->back() > 80)
      return "expects degrees from the vertical, 0-80, as DEG or LEFT,RIGHT; got '" + value + "'";
    subject->posture.arm_abduction_deg = {(*v)[0], v->back()};
    return "";
  });
  cl->option("--feet", [subject](const std::string& value) -> std::string {
    const auto v = numbers(value, 1, 1);
    if (!v || (*v)[0] < 100 || (*v)[0] > 700) return "expects the ankles' distance in mm, 100-700; got '" + value + "'";
    subject->posture.ankle_distance_mm = (*v)[0];
    return "";
  });
  cl->option("--turn", [subject](const std::string& value) -> std::string {
    const auto v = numbers(value, 1, 1);
    if (!v || std::abs((*v)[0]) > 180) return "expects degrees, -180 to 180; got '" + value + "'";
    subject->turn_deg = (*v)[0];
    return "";
  });
  cl->option("--at", [subject](const std::string& value) -> std::string {
    const auto v = numbers(value, 2, 2);
    if (!v) return "expects X,Z in mm; got '" + value + "'";
    subject->position_mm = Eigen::Vector2d((*v)[0], (*v)[1]);
    return "";
  });
}

}  // namespace bodyscan::cli
