// Avatars for pattern-making tools (CLO3D, Browzwear, Optitex): the scan's closed
// surface decimated to the triangle budget those tools ask for, as a Wavefront OBJ
// or a plain glTF binary. The measurements stay on the full surface; the avatar is
// for draping, and says how far it strays from what was measured.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "storage/formats/mesh_files.hpp"

namespace bodyscan::pipeline {

enum class AvatarFormat { kObj, kGlb };

struct AvatarOptions {
  AvatarFormat format = AvatarFormat::kObj;
  size_t max_triangles = 70000;  // CLO3D's recommendation for an avatar
  // OBJ only: glTF is metres by definition.
  storage::ModelUnit unit = storage::ModelUnit::kMillimetre;
};

// The budgets accepted from staff: fewer triangles than this lose the body's
// shape; more than the scan has is the scan.
inline constexpr size_t kMinAvatarTriangles = 1000;
inline constexpr size_t kMaxAvatarTriangles = 5000000;

struct Avatar {
  std::string bytes;
  size_t triangles = 0;
  bool closed = false;          // every edge between exactly two triangles
  double max_deviation_mm = 0;  // from the full surface, both ways (simplify.hpp)
};

StatusOr<Avatar> make_avatar(const TriangleMesh& surface, const AvatarOptions& options);

// "mm" or "m": invalid_argument naming what is accepted otherwise.
StatusOr<storage::ModelUnit> parse_model_unit(std::string_view text);

}  // namespace bodyscan::pipeline
