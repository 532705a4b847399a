#include "pipeline/share_model.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>

namespace bodyscan::pipeline {

StatusOr<double> head_cut_height(const std::vector<storage::MeasurementRecord>& measurements) {
  for (const storage::MeasurementRecord& m : measurements) {
    if (m.name != "neck_girth" || m.source != "automatic") continue;
    double lowest = std::numeric_limits<double>::infinity();
    for (const char* key : {"loop", "path"}) {
      if (!m.geometry.contains(key) || !m.geometry[key].is_array()) continue;
      for (const auto& p : m.geometry[key])
        if (p.is_array() && p.size() == 3 && p[1].is_number()) lowest = std::min(lowest, p[1].get<double>());
    }
    if (lowest < std::numeric_limits<double>::infinity()) return lowest;
  }
  return not_found("the scan has no neck girth: its model cannot be shown without the head");
}

TriangleMesh below_height(const TriangleMesh& mesh, double cut_y) {
  TriangleMesh out;
  constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> index(mesh.vertices.size(), kUnused);
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const bool confidence = mesh.confidence.size() == mesh.vertices.size();
  for (const Triangle& t : mesh.triangles) {
    bool below = true;
    for (int k = 0; k < 3; ++k) below = below && mesh.vertices[t[k]].y() <= cut_y;
    if (!below) continue;
    Triangle kept;
    for (int k = 0; k < 3; ++k) {
      uint32_t& i = index[t[k]];
      if (i == kUnused) {
        i = static_cast<uint32_t>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[t[k]]);
        if (normals) out.normals.push_back(mesh.normals[t[k]]);
        if (confidence) out.confidence.push_back(mesh.confidence[t[k]]);
      }
      kept[k] = i;
    }
    out.triangles.push_back(kept);
  }
  return out;
}

}  // namespace bodyscan::pipeline
