#include "app/cli_subject.hpp"

#include <cmath>
#include <cstdlib>
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
  std::vector<double> out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    const double x = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(x)) return std::nullopt;
    out.push_back(x);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.size() < min_count || out.size() > max_count) return std::nullopt;
  return out;
}

}  // namespace

bool is_subject_option(const std::string& flag) {
  return flag == "--body" || flag == "--arms" || flag == "--feet" || flag == "--turn" || flag == "--at";
}

Status set_subject_option(const std::string& flag, const std::string& value, pipeline::SimulatedSubject* subject) {
  if (flag == "--body") {
    subject->body = value;
  } else if (flag == "--arms") {
    const auto v = numbers(value, 1, 2);
    if (!v || (*v)[0] < 0 || (*v)[0] > 80 || v->back() < 0 || v->back() > 80)
      return invalid_argument("--arms expects degrees from the vertical, 0-80, as DEG or LEFT,RIGHT; got '" + value +
                              "'");
    subject->posture.arm_abduction_deg = {(*v)[0], v->back()};
  } else if (flag == "--feet") {
    const auto v = numbers(value, 1, 1);
    if (!v || (*v)[0] < 100 || (*v)[0] > 700)
      return invalid_argument("--feet expects the ankles' distance in mm, 100-700; got '" + value + "'");
    subject->posture.ankle_distance_mm = (*v)[0];
  } else if (flag == "--turn") {
    const auto v = numbers(value, 1, 1);
    if (!v || std::abs((*v)[0]) > 180)
      return invalid_argument("--turn expects degrees, -180 to 180; got '" + value + "'");
    subject->turn_deg = (*v)[0];
  } else if (flag == "--at") {
    const auto v = numbers(value, 2, 2);
    if (!v) return invalid_argument("--at expects X,Z in mm; got '" + value + "'");
    subject->position_mm = Eigen::Vector2d((*v)[0], (*v)[1]);
  } else {
    return invalid_argument("not a subject option: " + flag);
  }
  return Status();
}

}  // namespace bodyscan::cli
