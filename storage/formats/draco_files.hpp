// Compressed models for the browser: glTF 2.0 binary (.glb) with the
// KHR_draco_mesh_compression extension for meshes, and Draco's own .drc for point
// clouds (glTF's Draco extension carries triangles only). Both are in metres with Y
// up (the glTF convention; three.js's GLTFLoader and DRACOLoader read them as they
// are). The scan frame is millimetres: coordinates are scaled by 0.001 on the way
// out and by 1000 on the way back.
//
// Positions are quantised. The number of bits is chosen from the model's extent so
// that no coordinate moves more than `max_error_mm`, and every encoding is checked
// by decoding it again: the error reported is measured, not promised.
#pragma once

#include <string>
#include <string_view>

#include "core/status.hpp"
#include "recon/geometry/point_cloud.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::storage {

struct DracoOptions {
  double max_error_mm = 0.5;  // largest distance a vertex or point may move
  int compression_level = 7;  // Draco's speed/size trade-off, 0 (fast) .. 10 (small)
  // Carry vertex/point normals when the model has them. Off by default: on a body
  // scan they are 45 % of the GLB (8-bit octahedral), and a viewer computes them
  // from the triangles in a few tens of milliseconds (docs/benchmarks.md §8).
  bool normals = false;
  int normal_bits = 8;
};

struct DracoEncoded {
  std::string bytes;
  int position_bits = 0;
  double max_error_mm = 0;  // measured by decoding `bytes` again
  size_t vertices = 0, triangles = 0;
};

// A one-mesh, one-node glTF binary with a plain grey material.
StatusOr<DracoEncoded> encode_glb(const TriangleMesh& mesh, const DracoOptions& options = {});
// Reads what encode_glb wrote (and other Draco-compressed or plain single-mesh
// GLBs) back into millimetres.
StatusOr<TriangleMesh> decode_glb(std::string_view bytes);

// A Draco point cloud: positions, and normals when present.
StatusOr<DracoEncoded> encode_drc(const PointCloud& cloud, const DracoOptions& options = {});
StatusOr<PointCloud> decode_drc(std::string_view bytes);

// A mesh for keeping (the archive's copy, which measurements are taken on): Draco's
// own format, positions within `max_error_mm` (use a hundredth of a millimetre:
// far below the scan's noise), the per-vertex confidence (which parts hole filling
// invented) as an 8-bit generic attribute, no normals (they follow from the
// triangles). About a tenth of the binary PLY.
StatusOr<DracoEncoded> encode_mesh_drc(const TriangleMesh& mesh, const DracoOptions& options);
StatusOr<TriangleMesh> decode_mesh_drc(std::string_view bytes);

// Encoded, checked, and written whole or not at all.
StatusOr<DracoEncoded> write_glb(const std::string& path, const TriangleMesh& mesh, const DracoOptions& options = {});
StatusOr<DracoEncoded> write_drc(const std::string& path, const PointCloud& cloud, const DracoOptions& options = {});

}  // namespace bodyscan::storage
