// Points to a watertight surface: the whole thesis §3.2 pipeline.
//
//   k nearest neighbours -> PCA frames (eq. 3.12-3.13) -> orientation (cameras or
//   minimum spanning tree) -> kernel sizes from density and curvature (eq. 3.17-3.25)
//   -> implicit field on a sparse grid (eq. 3.14-3.15, 3.27) -> marching cubes
//   -> stray components removed -> flaps trimmed and holes filled (fill_holes.hpp).
//
// Every parameter left at 0 is chosen from the data: the thesis's density scaling
// makes the kernels follow the cloud's scale and spacing, and the noise estimate
// (estimate_noise.hpp) sets how much the kernels average, so the same call works on
// 128 points on a 1 m sphere and on a million points on a body.
#pragma once

#include <string>
#include <vector>

#include "core/progress.hpp"
#include "core/status.hpp"
#include "recon/geometry/fill_holes.hpp"
#include "recon/geometry/point_cloud.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

enum class NormalSource {
  kAuto,     // the cloud's normals if it has them, else its cameras, else the MST
  kInput,    // the cloud's own normals (orientation and direction kept)
  kCameras,  // PCA normals oriented toward the camera that saw each point
  kMst,      // PCA normals oriented by minimum-spanning-tree propagation
};

const char* to_string(NormalSource s);
// Parses "auto", "input", "cameras", "mst".
bool parse_normal_source(const std::string& text, NormalSource* out);

struct ReconstructOptions {
  float sigma_scale = 0.f;   // sigma_user, tangential kernel size / density (0 = auto)
  float normal_scale = 0.f;  // sigma_n / density (0 = auto)
  float sharpening = 0.f;    // s of eq. 3.24 (0 = none)
  // Bend kernels by the local mean curvature (removes the thesis kernel's
  // curvature bias; implicit_field.hpp). Off = the thesis's flat kernels.
  bool curvature_compensation = true;
  // With curvature_compensation: carry each PCA normal from its neighbourhood's mean
  // to the point itself along the shape operator (correct_normal_tilt); off = the
  // PCA normals as they are. Input normals are never touched.
  bool correct_normal_tilt = true;
  // With correct_normal_tilt: where a point lies more than this many density sigmas
  // from its PCA neighbourhood's mean across the surface (the edge of what the
  // cameras saw), its kernel is bent by the shape operator fitted again to the
  // carried normals. 0 = every kernel keeps the PCA normals' operator.
  float edge_refit_offset = 0.6f;
  float voxel_size = 0.f;  // grid spacing in the cloud's unit (0 = auto)
  float epsilon = 1e-2f;   // kernel cut-off tolerance, eq. 3.26
  size_t density_k = 10;   // neighbours of eq. 3.17
  size_t normal_k = 0;     // neighbours per PCA normal (0 = auto from the noise)
  NormalSource normal_source = NormalSource::kAuto;
  bool use_confidence = true;  // weight kernels by the cloud's per-point confidence
  // Points whose density sigma (eq. 3.17) exceeds this many times the median are
  // isolated strays and get no kernel (0 = keep every point).
  float isolated_spacing_ratio = 8.f;
  // Marching cubes needs this much Gaussian weight at a node, as a fraction of the
  // median weight on the surface (median_surface_weight): cuts the spurious zero
  // crossings in kernels' tails that noise creates.
  float min_relative_weight = 0.1f;
  // Components with fewer triangles than this fraction of the largest are dropped.
  double min_component_fraction = 0.01;
  // Close the surface (fill_holes.hpp): first trim boundary flaps farther than
  // hole_trim_distance from every point (0 = the median density sigma plus three
  // noise sigmas), then fill every hole up to max_hole_area_fraction. Off = the
  // field's zero set as is.
  bool close_holes = true;
  // With close_holes: stop after the trimming, holes left open (to study or time
  // the filling on exactly what it would get: bench/hole_fill_benchmark).
  bool leave_trimmed_holes_open = false;
  float hole_trim_distance = 0.f;
  // Openings whose fill would exceed this fraction of the surface's area are taken
  // as the surface's real edge and stay open (a scanned patch, a tube's ends); a
  // body's unseen soles or crown are 1-3 % of its skin.
  double max_hole_area_fraction = 0.05;
  // How filled patches are shaped (fill_holes.hpp): a membrane spans the opening,
  // a thin plate continues the surrounding curvature.
  HoleFairing hole_fairing = HoleFairing::kMembrane;
  int brick_size = 16;
  // Kernels reach this many voxels plus three noise sigmas along their normals
  // (Kernel::band); 0 = their full support.
  float band_voxels = 1.5f;
  ProgressFn progress;
};

struct ReconstructStats {
  size_t input_points = 0;
  size_t used_points = 0;                      // points with positive confidence
  size_t isolated_points = 0;                  // of those, dropped as isolated strays
  NormalSource normals = NormalSource::kAuto;  // what was used
  size_t orientation_components = 0;
  float median_density_sigma = 0.f;  // median of eq. 3.17, the cloud's unit
  float noise_sigma = 0.f;           // estimated per-axis noise, the cloud's unit
  float sigma_scale = 0.f, normal_scale = 0.f, sharpening = 0.f, voxel_size = 0.f;
  float min_weight = 0.f;
  size_t normal_k = 0;
  size_t bricks = 0;
  size_t field_bytes = 0;
  size_t components_removed = 0;
  size_t flap_triangles_trimmed = 0;
  size_t holes_filled = 0;
  double hole_area = 0.0;  // area of the fill, the cloud's unit squared
  // Wall-clock seconds per stage.
  double t_neighbours = 0, t_normals = 0, t_orientation = 0, t_kernels = 0, t_field = 0, t_mesh = 0;
  double total_seconds() const { return t_neighbours + t_normals + t_orientation + t_kernels + t_field + t_mesh; }
};

struct ReconstructResult {
  TriangleMesh mesh;  // outward-wound triangles, vertex normals from the triangles
  ReconstructStats stats;
};

StatusOr<ReconstructResult> reconstruct_surface(const PointCloud& cloud, const ReconstructOptions& options = {});

}  // namespace bodyscan
