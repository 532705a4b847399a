#include "pipeline/cad_avatar.hpp"

#include "recon/geometry/simplify.hpp"

namespace bodyscan::pipeline {

StatusOr<Avatar> make_avatar(const TriangleMesh& surface, const AvatarOptions& options) {
  if (options.max_triangles < kMinAvatarTriangles || options.max_triangles > kMaxAvatarTriangles)
    return invalid_argument("avatar: a budget of " + std::to_string(kMinAvatarTriangles) + " to " +
                            std::to_string(kMaxAvatarTriangles) + " triangles");
  SimplifyOptions so;
  so.max_triangles = options.max_triangles;
  ASSIGN_OR_RETURN(SimplifyResult s, simplify(surface, so));
  Avatar out;
  out.triangles = s.mesh.num_triangles();
  out.closed = analyze_topology(s.mesh).closed();
  out.max_deviation_mm = s.max_deviation_mm;
  if (options.format == AvatarFormat::kObj) {
    out.bytes = storage::encode_obj(s.mesh, options.unit);
  } else {
    ASSIGN_OR_RETURN(out.bytes, storage::encode_plain_glb(s.mesh));
  }
  return out;
}

StatusOr<storage::ModelUnit> parse_model_unit(std::string_view text) {
  if (text == "mm") return storage::ModelUnit::kMillimetre;
  if (text == "m") return storage::ModelUnit::kMetre;
  return invalid_argument("'unit' is 'mm' or 'm'");
}

}  // namespace bodyscan::pipeline
