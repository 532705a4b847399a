// JSON request bodies: parsed as every route parses them (depth-bounded), and a
// measurement request evaluated on a body-sized closed surface, the route that
// does the most with what a client sends.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/json_text.hpp"
#include "pipeline/evaluate_measurement.hpp"

namespace {

// A closed cylinder 1,700 mm tall, 150 mm in radius, Y up: girths, lengths and
// surface paths all have something to cut.
bodyscan::TriangleMesh cylinder() {
  constexpr int kAround = 48, kLevels = 18;
  bodyscan::TriangleMesh m;
  for (int l = 0; l < kLevels; ++l)
    for (int a = 0; a < kAround; ++a) {
      const double t = 2 * M_PI * a / kAround;
      m.vertices.emplace_back(static_cast<float>(150 * std::cos(t)), 1700.0f * l / (kLevels - 1),
                              static_cast<float>(150 * std::sin(t)));
    }
  const auto bottom = static_cast<uint32_t>(m.vertices.size());
  m.vertices.emplace_back(0.0f, 0.0f, 0.0f);
  m.vertices.emplace_back(0.0f, 1700.0f, 0.0f);
  auto at = [](int l, int a) { return static_cast<uint32_t>(l * kAround + (a % kAround)); };
  for (int l = 0; l + 1 < kLevels; ++l)
    for (int a = 0; a < kAround; ++a) {
      m.triangles.push_back({at(l, a), at(l + 1, a), at(l, a + 1)});
      m.triangles.push_back({at(l, a + 1), at(l + 1, a), at(l + 1, a + 1)});
    }
  for (int a = 0; a < kAround; ++a) {
    m.triangles.push_back({bottom, at(0, a), at(0, a + 1)});
    m.triangles.push_back({bottom + 1, at(kLevels - 1, a + 1), at(kLevels - 1, a)});
  }
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bodyscan::TriangleMesh body = cylinder();
  const nlohmann::json j = bodyscan::parse_json(std::string_view(reinterpret_cast<const char*>(data), size));
  if (j.is_discarded()) return 0;
  if (j.is_object()) {
    for (const char* key : {"kind", "name", "label", "role", "username"}) (void)bodyscan::string_field(j, key);
    (void)bodyscan::pipeline::evaluate_measurement(body, j);
  }
  (void)j.dump();  // what the server does with the request it saves
  return 0;
}
