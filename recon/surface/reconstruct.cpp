#include "recon/surface/reconstruct.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/median.hpp"
#include "recon/geometry/fill_holes.hpp"
#include "recon/geometry/mesh_components.hpp"
#include "recon/spatial/knn_index.hpp"
#include "recon/spatial/morton.hpp"
#include "recon/surface/adapt_kernels.hpp"
#include "recon/surface/estimate_curvature.hpp"
#include "recon/surface/estimate_noise.hpp"
#include "recon/surface/estimate_normals.hpp"
#include "recon/surface/implicit_field.hpp"
#include "recon/surface/marching_cubes.hpp"
#include "recon/surface/orient_normals.hpp"

namespace bodyscan {

const char* to_string(NormalSource s) {
  switch (s) {
    case NormalSource::kAuto: return "auto";
    case NormalSource::kInput: return "input";
    case NormalSource::kCameras: return "cameras";
    case NormalSource::kMst: return "mst";
  }
  return "?";
}

bool parse_normal_source(const std::string& text, NormalSource* out) {
  for (NormalSource s : {NormalSource::kAuto, NormalSource::kInput, NormalSource::kCameras, NormalSource::kMst}) {
    if (text == to_string(s)) {
      *out = s;
      return true;
    }
  }
  return false;
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

StatusOr<ReconstructResult> reconstruct_surface(const PointCloud& input, const ReconstructOptions& options) {
  if (!input.is_consistent()) {
    return invalid_argument("point cloud attributes do not have one entry per point");
  }
  // Points with zero confidence do not take part at all, not even as neighbours.
  // The rest are put in Morton order (what each stage needs of them), so that
  // every later pass over the points walks space coherently.
  PointCloud ordered;
  std::vector<uint32_t> input_index;  // ordered point -> input point
  {
    const bool filter = options.use_confidence && input.has_confidence();
    std::vector<uint32_t> used;
    used.reserve(input.size());
    for (size_t i = 0; i < input.size(); ++i) {
      if (filter && !(input.confidence[i] > 0.f)) continue;
      if (!input.positions[i].allFinite()) return invalid_argument("the cloud has a non-finite coordinate");
      used.push_back(static_cast<uint32_t>(i));
    }
    std::vector<Vec3f> used_positions(used.size());
    for (size_t j = 0; j < used.size(); ++j) used_positions[j] = input.positions[used[j]];
    std::vector<uint32_t>& order = input_index;
    order = morton_order(used_positions);
    for (uint32_t& i : order) i = used[i];
    ordered.camera_centres = input.camera_centres;
    ordered.positions.resize(order.size());
    if (input.has_normals()) ordered.normals.resize(order.size());
    if (filter) ordered.confidence.resize(order.size());
    if (!input.camera.empty()) ordered.camera.resize(order.size());
    for (size_t j = 0; j < order.size(); ++j) {
      const uint32_t i = order[j];
      ordered.positions[j] = input.positions[i];
      if (input.has_normals()) ordered.normals[j] = input.normals[i];
      if (filter) ordered.confidence[j] = input.confidence[i];
      if (!input.camera.empty()) ordered.camera[j] = input.camera[i];
    }
  }
  const PointCloud* cloud = &ordered;
  const std::vector<Vec3f>& pts = cloud->positions;
  if (pts.size() < 8) {
    return invalid_argument("a surface needs at least 8 points with positive confidence; got " +
                            std::to_string(pts.size()));
  }

  ReconstructResult result;
  ReconstructStats& st = result.stats;
  st.input_points = input.size();
  st.used_points = pts.size();

  NormalSource source = options.normal_source;
  if (source == NormalSource::kAuto) {
    source = cloud->has_normals()   ? NormalSource::kInput
             : cloud->has_cameras() ? NormalSource::kCameras
                                    : NormalSource::kMst;
  }
  if (source == NormalSource::kInput && !cloud->has_normals()) {
    return invalid_argument("normal source 'input' chosen but the cloud has no normals");
  }
  if (source == NormalSource::kCameras && !cloud->has_cameras()) {
    return invalid_argument("normal source 'cameras' chosen but the cloud has no camera ids and centres");
  }
  st.normals = source;

  // Neighbours. 20 columns serve every later stage (density 10, normals, curvature
  // and noise fits); wider neighbourhoods for noisy clouds are queried as needed.
  auto t0 = Clock::now();
  if (!report(options.progress, "neighbours", 0.0)) return cancelled("reconstruction cancelled");
  const KnnIndex index(pts);
  const size_t max_k = std::max<size_t>({options.density_k, 20});
  const NeighborGraph graph = knn_graph(index, pts, max_k);
  st.t_neighbours = seconds_since(t0);

  // Normals: a first PCA with 20 neighbours gives frames for the noise estimate; the
  // final k grows with the noise, since PCA averages noise over k points.
  t0 = Clock::now();
  if (!report(options.progress, "normals", 0.0)) return cancelled("reconstruction cancelled");
  LocalFrames frames = estimate_normals(pts, index, graph, {.k = 20});
  const NoiseEstimate noise = estimate_noise(pts, index, graph, frames);
  const std::vector<float> sigma_density = density_sigma(graph, options.density_k);
  std::vector<float> sigma_sample = sigma_density;
  st.median_density_sigma = median_in_place(sigma_sample);
  st.noise_sigma = noise.sigma;
  const float eta = st.median_density_sigma > 0.f ? noise.sigma / st.median_density_sigma : 0.f;
  // PCA averages the noise over k points; once the noise nears the spacing the
  // neighbourhood must grow with its square to keep the normals' tilt small.
  st.normal_k = options.normal_k ? options.normal_k
                : eta < 0.05f    ? 12
                                 : static_cast<size_t>(std::clamp(20.f * (eta / 0.3f) * (eta / 0.3f), 20.f, 200.f));
  if (st.normal_k != 20) frames = estimate_normals(pts, index, graph, {.k = st.normal_k});
  if (source == NormalSource::kInput) {
    for (size_t i = 0; i < pts.size(); ++i) {
      Vec3f n = cloud->normals[i];
      if (!(n.squaredNorm() > 0.f) || !n.allFinite()) {
        return invalid_argument("input normal " + std::to_string(input_index[i]) + " is zero or not finite");
      }
      n.normalize();
      Vec3f t1 = frames.tangent1[i] - frames.tangent1[i].dot(n) * n;
      if (t1.squaredNorm() < 1e-12f) t1 = n.unitOrthogonal();
      t1.normalize();
      frames.normals[i] = n;
      frames.tangent1[i] = t1;
      frames.tangent2[i] = n.cross(t1);
    }
  }
  st.t_normals = seconds_since(t0);

  t0 = Clock::now();
  if (!report(options.progress, "orientation", 0.0)) return cancelled("reconstruction cancelled");
  if (source == NormalSource::kCameras) {
    orient_normals_toward_cameras(*cloud, frames);
  } else if (source == NormalSource::kMst) {
    st.orientation_components = orient_normals_mst(pts, graph, frames).components;
  }
  st.t_orientation = seconds_since(t0);

  // Kernel sizes. Noise needs wider kernels to average over; the defaults follow
  // the relative noise eta = noise / density sigma (tuned on the thesis's sphere
  // table, see docs/benchmarks.md).
  t0 = Clock::now();
  if (!report(options.progress, "kernels", 0.0)) return cancelled("reconstruction cancelled");
  // Tangential width averages the noise along the surface until it reaches about
  // 1.5 density sigmas; beyond that the normal width does the averaging. Once the
  // noise rivals the spacing, a normal width below about three noise sigmas makes
  // the sum a mode finder, and on a curved surface, where more points lie on the
  // convex side, the mode sits outside (16384 points at s = 0.1: bias 0.075 at
  // sigma_n = 1 density sigma, 0.012 at 5).
  st.sigma_scale =
      options.sigma_scale > 0.f ? options.sigma_scale : std::clamp(1.0f + 1.5f * eta + 1.5f * eta * eta, 1.0f, 1.5f);
  st.normal_scale = options.normal_scale > 0.f ? options.normal_scale
                                               : std::clamp(std::max(0.6f + 0.9f * eta, 3.f * eta), 0.6f, 6.0f);
  st.sharpening = options.sharpening;
  CurvatureResult curvature;
  if (options.sharpening != 0.f) curvature = estimate_curvature(pts, graph, frames);
  AdaptKernelsOptions ko;
  ko.sigma_user = st.sigma_scale;
  ko.normal_scale = st.normal_scale;
  ko.sharpening = options.sharpening;
  ko.curvature_compensation = options.curvature_compensation;
  ko.noise_sigma = st.noise_sigma;
  // The voxel must resolve the thinnest kernel across the surface.
  st.voxel_size =
      options.voxel_size > 0.f ? options.voxel_size : 0.7f * st.median_density_sigma * std::min(1.f, st.normal_scale);
  ko.band = options.band_voxels > 0.f ? options.band_voxels * st.voxel_size + 3.f * st.noise_sigma : 0.f;
  std::vector<ShapeOperator> shape;
  if (options.curvature_compensation) {
    shape = estimate_shape_operators(pts, index, graph, frames, {.k = 20});
  }
  // The PCA normals belong to their neighbourhoods' means; at the edge of what the
  // cameras saw those lie a few millimetres back from the point, and a kernel
  // extrapolating across the unseen strip from that tilted plane stands proud of
  // the skin. Each normal is carried to its own point along the shape operator
  // (correct_normal_tilt), where the skin is convex: the crown and the wrists,
  // whose sparse stripes leave one-sided neighbourhoods, otherwise stand high
  // (docs/reconstruction.md). One pass only: refitting the shape operator to the
  // carried normals and carrying them again overshoots, since those normals turn
  // faster than the surface where the sampling is uneven.
  if (options.correct_normal_tilt && !shape.empty() && source != NormalSource::kInput) {
    frames = correct_normal_tilt(frames, shape);
    // At the edge itself the operator was fitted to PCA normals that all lean the
    // same way and so turn too slowly across it: there the kernels take the
    // operator fitted again to the carried normals. Only there: refitted
    // everywhere, it bends unevenly sampled limbs too far (wrists 0.9 mm small).
    // The edge is where the point lies more than edge_refit_offset density sigmas
    // from its neighbourhood's mean across the surface: a few per cent of a body
    // scan's points at the default, since inside a patch the offset is a fraction
    // of that (docs/reconstruction.md item 4).
    if (options.edge_refit_offset > 0.f && frames.offset.size() == pts.size()) {
      const std::vector<ShapeOperator> carried = estimate_shape_operators(pts, index, graph, frames, {.k = 20});
      for (size_t i = 0; i < pts.size(); ++i) {
        const Vec3f& d = frames.offset[i];
        if ((d - d.dot(frames.normals[i]) * frames.normals[i]).norm() > options.edge_refit_offset * sigma_density[i])
          shape[i] = carried[i];
      }
    }
  }
  // Isolated points (a floor sample, a speck of dust far from the body) would get
  // kernels as wide as the gap to their neighbours, and the field's grid with them.
  std::vector<float> confidence = options.use_confidence ? cloud->confidence : std::vector<float>{};
  if (options.isolated_spacing_ratio > 0.f && st.median_density_sigma > 0.f) {
    const float limit = options.isolated_spacing_ratio * st.median_density_sigma;
    for (size_t i = 0; i < pts.size(); ++i) {
      if (sigma_density[i] <= limit) continue;
      if (confidence.empty()) confidence.assign(pts.size(), 1.f);
      confidence[i] = 0.f;
      ++st.isolated_points;
    }
  }
  const std::vector<Kernel> kernels = adapt_kernels(
      pts, frames, sigma_density, options.sharpening != 0.f ? &curvature : nullptr, shape, confidence, ko);
  st.t_kernels = seconds_since(t0);

  t0 = Clock::now();
  ImplicitFieldOptions fo;
  fo.voxel_size = st.voxel_size;
  fo.epsilon = options.epsilon;
  fo.brick_size = options.brick_size;
  fo.progress = options.progress;
  {
    // The field is the largest thing held; it goes once its zero set is extracted.
    ASSIGN_OR_RETURN(ImplicitField field, build_implicit_field(kernels, fo));
    st.bricks = field.num_bricks();
    st.field_bytes = field.memory_bytes();
    st.t_field = seconds_since(t0);

    t0 = Clock::now();
    MarchingCubesOptions mo;
    st.min_weight = std::max(1e-6f, options.min_relative_weight * median_surface_weight(field, pts));
    mo.min_weight = st.min_weight;
    mo.progress = options.progress;
    ASSIGN_OR_RETURN(result.mesh, extract_isosurface(field, mo));
  }
  if (options.close_holes) {
    // The field reaches past its data at creases and thin gaps (its kernels' planes
    // run on beyond them) and stops where the weight runs out, leaving open flaps
    // a few kernel widths long; peel those back to the data, then close every loop.
    const float reach =
        options.hole_trim_distance > 0.f ? options.hole_trim_distance : st.median_density_sigma + 3.f * st.noise_sigma;
    const float reach2 = reach * reach;
    st.flap_triangles_trimmed = trim_boundary_flaps(result.mesh, [&](uint32_t v) {
      uint32_t nearest = 0;
      float d2 = 0.f;
      return index.knn(result.mesh.vertices[v], 1, &nearest, &d2) == 0 || d2 > reach2;
    });
    if (!options.leave_trimmed_holes_open) {
      HoleFillOptions fill;
      fill.max_hole_area = options.max_hole_area_fraction * surface_area(result.mesh);
      fill.fairing = options.hole_fairing;
      const HoleFillStats holes = fill_holes(result.mesh, fill);
      st.holes_filled = holes.holes_filled;
      st.hole_area = holes.area_added;
    }
  }
  // After the trimming, which may cut islands off a flap.
  if (options.min_component_fraction > 0.0) {
    st.components_removed = remove_small_components(result.mesh, options.min_component_fraction);
  }
  result.mesh.normals = compute_vertex_normals(result.mesh);
  st.t_mesh = seconds_since(t0);
  report(options.progress, "done", 1.0);
  return result;
}

}  // namespace bodyscan
