// JSON text from outside the process (HTTP bodies, rig descriptions, archive
// records and files) parsed with its nesting bounded. nlohmann's values copy
// recursively, so a document nested a few hundred thousand deep (under a
// megabyte) overflows the stack wherever one is copied; no document of ours nests
// deeper than a dozen levels. Header-only: the layers that read JSON link
// nlohmann_json.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <string_view>

namespace bodyscan {

inline constexpr int kMaxJsonDepth = 64;

// The document, or a discarded value (is_discarded()) where the text is not JSON
// or nests objects and arrays more than max_depth deep.
inline nlohmann::json parse_json(std::string_view text, int max_depth = kMaxJsonDepth) {
  struct TooDeep {};
  using Event = nlohmann::json::parse_event_t;
  try {
    return nlohmann::json::parse(
        text,
        [max_depth](int depth, Event event, nlohmann::json&) {
          if ((event == Event::object_start || event == Event::array_start) && depth >= max_depth) throw TooDeep{};
          return true;
        },
        /*allow_exceptions=*/false);
  } catch (const TooDeep&) {
    return nlohmann::json(nlohmann::json::value_t::discarded);
  }
}

// A string member of `object`: its value, `fallback` when absent or null, nullopt
// when present with another type (a client's mistake to answer with 400, where
// nlohmann's value() would throw).
inline std::optional<std::string> string_field(const nlohmann::json& object, const char* key,
                                               std::string fallback = {}) {
  const auto it = object.find(key);
  if (it == object.end() || it->is_null()) return fallback;
  if (!it->is_string()) return std::nullopt;
  return it->get<std::string>();
}

}  // namespace bodyscan
