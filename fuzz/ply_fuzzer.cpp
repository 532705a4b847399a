// PLY files: parsed, and when they hold faces, made a mesh as a scan's surface
// would be. Any input ends in a Status, never a crash, a hang or an allocation
// its size cannot justify (recon/io/ply.hpp).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "recon/io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  auto parsed = bodyscan::parse_ply(bytes);
  if (parsed.ok() && !parsed->triangles.empty()) {
    // Every index the parser let through must address a vertex.
    const size_t n = parsed->cloud.positions.size();
    for (const auto& t : parsed->triangles)
      for (int k = 0; k < 3; ++k)
        if (static_cast<size_t>(t[k]) >= n) __builtin_trap();
  }
  return 0;
}
