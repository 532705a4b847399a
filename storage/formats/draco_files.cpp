#include "storage/formats/draco_files.hpp"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/io/gltf_encoder.h>
#include <draco/mesh/mesh.h>
#include <draco/point_cloud/point_cloud.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <vector>

#include "core/json_text.hpp"
#include "recon/io/atomic_file.hpp"

namespace bodyscan::storage {

namespace {

constexpr float kToMetres = 0.001f;
constexpr int kMaxPositionBits = 26;

Status from_draco(const draco::Status& s, const std::string& what) {
  return internal_error(what + ": " + s.error_msg_string());
}

// The fewest bits whose quantisation step keeps every point within `max_error` of
// where it was: Draco spreads 2^bits - 1 steps over the largest side of the
// bounding box, and a point moves at most half a step along each axis.
int position_bits(const std::vector<Vec3f>& p, double max_error_mm) {
  Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Vec3f& v : p) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double extent = p.empty() ? 1.0 : std::max(1e-3, static_cast<double>((hi - lo).maxCoeff()));
  const double steps = std::sqrt(3.0) * extent / (2 * max_error_mm);
  return std::clamp(static_cast<int>(std::ceil(std::log2(steps + 1))), 1, kMaxPositionBits);
}

// The largest distance from a point of `a` to the nearest point of `b` and back
// (vertex sets in mm), looked up in a grid of `cell`-sized cubes: pairs farther
// apart than one cell count as infinitely far, which fails any check. A point's own
// cell is searched first; its neighbours only when the nearest found is farther
// than the cell's nearest wall.
double max_displacement(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b, double cell) {
  auto one_way = [cell](const std::vector<Vec3f>& from, const std::vector<Vec3f>& to) {
    if (from.empty()) return 0.0;
    if (to.empty()) return std::numeric_limits<double>::infinity();
    auto coord = [cell](float x) { return static_cast<int64_t>(std::floor(x / cell)); };
    auto key = [](int64_t x, int64_t y, int64_t z) {
      return ((x + (1 << 20)) << 42) | ((y + (1 << 20)) << 21) | (z + (1 << 20));
    };
    std::vector<std::pair<int64_t, uint32_t>> grid(to.size());
    for (size_t i = 0; i < to.size(); ++i)
      grid[i] = {key(coord(to[i].x()), coord(to[i].y()), coord(to[i].z())), static_cast<uint32_t>(i)};
    std::sort(grid.begin(), grid.end());
    auto search = [&](const Vec3f& p, int64_t k, double* best) {
      auto it = std::lower_bound(grid.begin(), grid.end(), std::make_pair(k, uint32_t{0}));
      for (; it != grid.end() && it->first == k; ++it)
        *best = std::min(*best, static_cast<double>((to[it->second] - p).norm()));
    };
    double worst = 0;
    for (const Vec3f& p : from) {
      const int64_t cx = coord(p.x()), cy = coord(p.y()), cz = coord(p.z());
      double best = std::numeric_limits<double>::infinity();
      search(p, key(cx, cy, cz), &best);
      double wall = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        const double lo = p[k] - static_cast<double>((k == 0 ? cx : k == 1 ? cy : cz)) * cell;
        wall = std::min({wall, lo, cell - lo});
      }
      if (best > wall)
        for (int dx = -1; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz)
              if (dx || dy || dz) search(p, key(cx + dx, cy + dy, cz + dz), &best);
      worst = std::max(worst, best);
    }
    return worst;
  };
  return std::max(one_way(a, b), one_way(b, a));
}

int add_attribute(draco::PointCloud* pc, draco::GeometryAttribute::Type type, const std::vector<Vec3f>& values,
                  float scale) {
  draco::GeometryAttribute ga;
  ga.Init(type, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
  const int id = pc->AddAttribute(ga, true, static_cast<uint32_t>(values.size()));
  draco::PointAttribute* att = pc->attribute(id);
  for (size_t i = 0; i < values.size(); ++i) {
    const Vec3f v = values[i] * scale;
    att->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)), v.data());
  }
  return id;
}

// Positions (and normals) of every point of a decoded Draco geometry, in mm.
std::vector<Vec3f> read_attribute(const draco::PointCloud& pc, draco::GeometryAttribute::Type type, float scale) {
  std::vector<Vec3f> out;
  const draco::PointAttribute* att = pc.GetNamedAttribute(type);
  if (!att) return out;
  out.resize(pc.num_points());
  for (draco::PointIndex i(0); i < pc.num_points(); ++i) {
    float v[3] = {0, 0, 0};
    att->ConvertValue<float, 3>(att->mapped_index(i), v);
    out[i.value()] = Vec3f(v[0], v[1], v[2]) * scale;
  }
  return out;
}

bool usable_normals(const std::vector<Vec3f>& normals, size_t n, const DracoOptions& o) {
  return o.normals && normals.size() == n && n > 0;
}

// What a check decodes: the positions (mm) and how many triangles (or points).
struct Decoded {
  std::vector<Vec3f> positions;
  size_t count = 0;
};

// The encoding loop every format shares: from the fewest position bits that can
// keep every vertex within the error allowed, encode, decode again, compare every
// vertex, and take one more bit until the decoded positions are within it.
// `count`: the triangles of a mesh, or the points of a cloud (`is_mesh` false).
template <typename Encode, typename Decode>
StatusOr<DracoEncoded> encode_checked(const std::string& what, const std::vector<Vec3f>& positions, size_t count,
                                      bool is_mesh, const DracoOptions& options, Encode&& encode, Decode&& decode) {
  if (!(options.max_error_mm > 0)) return invalid_argument(what + ": the largest error allowed must be positive");
  for (int bits = position_bits(positions, options.max_error_mm); bits <= kMaxPositionBits; ++bits) {
    DracoEncoded e;
    ASSIGN_OR_RETURN(e.bytes, encode(bits));
    e.position_bits = bits;
    auto back = decode(e.bytes);
    if (!back.ok()) return internal_error(what + ": the encoding does not decode: " + back.status().message());
    if (back->count != count)
      return internal_error(what + ": decoding gave " + std::to_string(back->count) + " elements, not " +
                            std::to_string(count));
    e.vertices = back->positions.size();
    e.triangles = is_mesh ? count : 0;
    e.max_error_mm = max_displacement(positions, back->positions, std::max(1.0, 2 * options.max_error_mm));
    if (e.max_error_mm <= options.max_error_mm) return e;
  }
  return internal_error(what + ": no quantisation keeps the vertices within " + std::to_string(options.max_error_mm) +
                        " mm");
}

// Positions (in metres) and triangles.
void to_draco_mesh(const TriangleMesh& mesh, draco::Mesh* out) {
  draco::Mesh& dm = *out;
  dm.set_num_points(static_cast<uint32_t>(mesh.num_vertices()));
  add_attribute(&dm, draco::GeometryAttribute::POSITION, mesh.vertices, kToMetres);
  dm.SetNumFaces(mesh.num_triangles());
  for (size_t f = 0; f < mesh.num_triangles(); ++f) {
    const Triangle& t = mesh.triangles[f];
    dm.SetFace(draco::FaceIndex(static_cast<uint32_t>(f)),
               {draco::PointIndex(t[0]), draco::PointIndex(t[1]), draco::PointIndex(t[2])});
  }
}

// Draco's own encoder: positions at `bits`, speed from the compression level.
void configure(const DracoOptions& options, int bits, draco::Encoder* encoder) {
  encoder->SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  const int speed = 10 - std::clamp(options.compression_level, 0, 10);
  encoder->SetSpeedOptions(speed, speed);
}

// Positions, normals and triangles of a Draco mesh; `ids` maps glTF attribute
// names to the Draco attributes' unique ids (the extension's "attributes").
StatusOr<TriangleMesh> from_draco_mesh(const draco::Mesh& dm, const std::map<std::string, int>& ids) {
  auto find = [&](const char* name, draco::GeometryAttribute::Type type) -> const draco::PointAttribute* {
    const auto it = ids.find(name);
    return it != ids.end() ? dm.GetAttributeByUniqueId(static_cast<uint32_t>(it->second)) : dm.GetNamedAttribute(type);
  };
  auto read = [&](const draco::PointAttribute* att, float scale) {
    std::vector<Vec3f> out;
    if (!att || att->num_components() != 3) return out;
    out.resize(dm.num_points());
    for (draco::PointIndex i(0); i < dm.num_points(); ++i) {
      float v[3] = {0, 0, 0};
      att->ConvertValue<float, 3>(att->mapped_index(i), v);
      out[i.value()] = Vec3f(v[0], v[1], v[2]) * scale;
    }
    return out;
  };
  TriangleMesh mesh;
  mesh.vertices = read(find("POSITION", draco::GeometryAttribute::POSITION), 1000.f);
  if (mesh.vertices.empty()) return invalid_argument("glb: the mesh has no positions");
  mesh.normals = read(find("NORMAL", draco::GeometryAttribute::NORMAL), 1.f);
  mesh.triangles.reserve(dm.num_faces());
  for (draco::FaceIndex f(0); f < dm.num_faces(); ++f) {
    const draco::Mesh::Face& face = dm.face(f);
    mesh.triangles.push_back({face[0].value(), face[1].value(), face[2].value()});
  }
  return mesh;
}

// Accessor a's bytes (from its offset to its buffer view's end), its count and
// component type; the view checked to lie in the binary chunk.
struct AccessorBytes {
  std::string_view bytes;
  size_t count = 0;
  int component_type = 0;
  std::string type;
};
StatusOr<AccessorBytes> accessor_bytes(const nlohmann::json& j, size_t a, std::string_view bin) {
  const nlohmann::json& acc = j.at("accessors").at(a);
  const nlohmann::json& view = j.at("bufferViews").at(acc.at("bufferView").get<size_t>());
  if (view.value("byteStride", size_t{0}) != 0) return invalid_argument("interleaved accessors");
  const size_t at = view.value("byteOffset", size_t{0}) + acc.value("byteOffset", size_t{0});
  const size_t length = view.at("byteLength").get<size_t>();
  if (at > bin.size() || length > bin.size() - at) return invalid_argument("a buffer view runs past the binary chunk");
  return AccessorBytes{bin.substr(at, length), acc.at("count").get<size_t>(), acc.at("componentType").get<int>(),
                       acc.value("type", "")};
}

// A float VEC3 attribute, scaled; empty when the primitive has none.
StatusOr<std::vector<Vec3f>> plain_vec3(const nlohmann::json& j, const nlohmann::json& prim, const char* name,
                                        float scale, std::string_view bin) {
  std::vector<Vec3f> out;
  if (!prim.at("attributes").contains(name)) return out;
  ASSIGN_OR_RETURN(AccessorBytes a, accessor_bytes(j, prim["attributes"][name].get<size_t>(), bin));
  if (a.component_type != 5126 || a.type != "VEC3") return invalid_argument(std::string(name) + " is not float VEC3");
  if (a.count > a.bytes.size() / 12) return invalid_argument(std::string(name) + " runs past its buffer view");
  out.resize(a.count);
  for (size_t i = 0; i < a.count; ++i) {
    float f[3];
    std::memcpy(f, a.bytes.data() + 12 * i, 12);
    out[i] = scale * Vec3f(f[0], f[1], f[2]);
  }
  return out;
}

// The primitive's indices (unsigned byte, short or int), or 0..vertices-1 without.
StatusOr<std::vector<uint32_t>> plain_indices(const nlohmann::json& j, const nlohmann::json& prim, size_t vertices,
                                              std::string_view bin) {
  std::vector<uint32_t> out;
  if (!prim.contains("indices")) {
    out.resize(vertices);
    for (size_t i = 0; i < vertices; ++i) out[i] = static_cast<uint32_t>(i);
    return out;
  }
  ASSIGN_OR_RETURN(AccessorBytes a, accessor_bytes(j, prim["indices"].get<size_t>(), bin));
  const size_t width = a.component_type == 5121 ? 1 : a.component_type == 5123 ? 2 : a.component_type == 5125 ? 4 : 0;
  if (width == 0) return invalid_argument("indices of component type " + std::to_string(a.component_type));
  if (a.count > a.bytes.size() / width) return invalid_argument("the indices run past their buffer view");
  out.resize(a.count);
  for (size_t i = 0; i < a.count; ++i) {
    uint32_t v = 0;
    std::memcpy(&v, a.bytes.data() + width * i, width);
    out[i] = v;
  }
  return out;
}

// A primitive with plain accessors: float VEC3 POSITION (m) and NORMAL, and a
// triangle list.
StatusOr<TriangleMesh> read_plain_primitive(const nlohmann::json& j, const nlohmann::json& prim, std::string_view bin) {
  TriangleMesh mesh;
  ASSIGN_OR_RETURN(mesh.vertices, plain_vec3(j, prim, "POSITION", 1000.f, bin));
  ASSIGN_OR_RETURN(mesh.normals, plain_vec3(j, prim, "NORMAL", 1.f, bin));
  ASSIGN_OR_RETURN(std::vector<uint32_t> indices, plain_indices(j, prim, mesh.vertices.size(), bin));
  if (prim.value("mode", 4) != 4 || indices.size() % 3 != 0) return invalid_argument("not a triangle list");
  for (size_t i = 0; i < indices.size(); i += 3) mesh.triangles.push_back({indices[i], indices[i + 1], indices[i + 2]});
  if (!mesh.is_consistent()) return invalid_argument("an index is out of range");
  return mesh;
}

}  // namespace

StatusOr<TriangleMesh> decode_glb(std::string_view bytes) {
  // The container (glTF 2.0 §4.4): a 12-byte header, a JSON chunk, a BIN chunk.
  auto bad = [](const std::string& why) {
    return invalid_argument("glb: not a glTF binary this reader understands (" + why + ")");
  };
  auto u32 = [&](size_t at) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20 || u32(0) != 0x46546C67u) return bad("no glTF header");
  if (u32(4) != 2) return bad("glTF version " + std::to_string(u32(4)) + ", not 2");
  if (u32(8) > bytes.size()) return bad("the file is cut short");
  const uint32_t json_len = u32(12);
  if (u32(16) != 0x4E4F534Au || 20ull + json_len > bytes.size()) return bad("no JSON chunk");
  const nlohmann::json j = parse_json(bytes.substr(20, json_len));
  if (j.is_discarded()) return bad("its JSON chunk does not parse");
  const size_t bin_at = 20 + ((json_len + 3) & ~3u);
  if (bin_at + 8 > bytes.size() || u32(bin_at + 4) != 0x004E4942u) return bad("no BIN chunk");
  const std::string_view bin = bytes.substr(bin_at + 8, std::min<size_t>(u32(bin_at), bytes.size() - bin_at - 8));
  try {
    const nlohmann::json& prim = j.at("meshes").at(0).at("primitives").at(0);
    if (!prim.contains("extensions") || !prim["extensions"].contains("KHR_draco_mesh_compression")) {
      auto plain = read_plain_primitive(j, prim, bin);
      if (!plain.ok()) return bad(plain.status().message());
      return plain;
    }
    const nlohmann::json& ext = prim["extensions"]["KHR_draco_mesh_compression"];
    const nlohmann::json& view = j.at("bufferViews").at(ext.at("bufferView").get<size_t>());
    const size_t offset = view.value("byteOffset", size_t{0}), length = view.at("byteLength").get<size_t>();
    if (offset + length > bin.size()) return bad("a buffer view runs past the binary chunk");
    draco::DecoderBuffer buffer;
    buffer.Init(bin.data() + offset, length);
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) return bad("Draco: " + decoded.status().error_msg_string());
    std::map<std::string, int> ids;
    for (const auto& [name, id] : ext.at("attributes").items()) ids[name] = id.get<int>();
    return from_draco_mesh(*decoded.value(), ids);
  } catch (const nlohmann::json::exception& e) {
    return bad(std::string("a field is missing: ") + e.what());
  }
}

StatusOr<DracoEncoded> encode_glb(const TriangleMesh& mesh, const DracoOptions& options) {
  if (mesh.empty()) return invalid_argument("glb: the mesh has no triangles");
  if (!mesh.is_consistent()) return invalid_argument("glb: the mesh's indices or attributes are inconsistent");
  return encode_checked(
      "glb", mesh.vertices, mesh.num_triangles(), true, options,
      [&](int bits) -> StatusOr<std::string> {
        draco::Mesh dm;
        to_draco_mesh(mesh, &dm);
        if (usable_normals(mesh.normals, mesh.num_vertices(), options))
          add_attribute(&dm, draco::GeometryAttribute::NORMAL, mesh.normals, 1.f);
        draco::DracoCompressionOptions co;
        co.compression_level = options.compression_level;
        co.quantization_position.SetQuantizationBits(bits);
        co.quantization_bits_normal = options.normal_bits;
        dm.SetCompressionEnabled(true);
        dm.SetCompressionOptions(co);
        draco::GltfEncoder encoder;
        draco::EncoderBuffer out;
        const draco::Status st = encoder.EncodeToBuffer(dm, &out);
        if (!st.ok()) return from_draco(st, "glb: Draco could not encode the mesh");
        return std::string(out.data(), out.size());
      },
      [](std::string_view bytes) -> StatusOr<Decoded> {
        ASSIGN_OR_RETURN(TriangleMesh back, decode_glb(bytes));
        return Decoded{std::move(back.vertices), back.num_triangles()};
      });
}

StatusOr<PointCloud> decode_drc(std::string_view bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodePointCloudFromBuffer(&buffer);
  if (!decoded.ok())
    return invalid_argument("drc: not a Draco file this reader understands (" + decoded.status().error_msg_string() +
                            ")");
  PointCloud cloud;
  cloud.positions = read_attribute(*decoded.value(), draco::GeometryAttribute::POSITION, 1000.f);
  if (cloud.positions.empty() && decoded.value()->num_points() > 0)
    return invalid_argument("drc: the points have no positions");
  cloud.normals = read_attribute(*decoded.value(), draco::GeometryAttribute::NORMAL, 1.f);
  return cloud;
}

StatusOr<DracoEncoded> encode_drc(const PointCloud& cloud, const DracoOptions& options) {
  if (cloud.empty()) return invalid_argument("drc: the point cloud is empty");
  return encode_checked(
      "drc", cloud.positions, cloud.size(), false, options,
      [&](int bits) -> StatusOr<std::string> {
        draco::PointCloud pc;
        pc.set_num_points(static_cast<uint32_t>(cloud.size()));
        add_attribute(&pc, draco::GeometryAttribute::POSITION, cloud.positions, kToMetres);
        if (usable_normals(cloud.normals, cloud.size(), options))
          add_attribute(&pc, draco::GeometryAttribute::NORMAL, cloud.normals, 1.f);
        draco::Encoder encoder;
        configure(options, bits, &encoder);
        encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, options.normal_bits);
        draco::EncoderBuffer out;
        const draco::Status st = encoder.EncodePointCloudToBuffer(pc, &out);
        if (!st.ok()) return from_draco(st, "drc: Draco could not encode the points");
        return std::string(out.data(), out.size());
      },
      [](std::string_view bytes) -> StatusOr<Decoded> {
        ASSIGN_OR_RETURN(PointCloud back, decode_drc(bytes));
        const size_t n = back.size();
        return Decoded{std::move(back.positions), n};
      });
}

StatusOr<TriangleMesh> decode_mesh_drc(std::string_view bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    return invalid_argument("drc: not a Draco mesh this reader understands (" + decoded.status().error_msg_string() +
                            ")");
  const draco::Mesh& dm = *decoded.value();
  TriangleMesh mesh;
  mesh.vertices = read_attribute(dm, draco::GeometryAttribute::POSITION, 1000.f);
  if (mesh.vertices.empty()) return invalid_argument("drc: the mesh has no positions");
  if (const draco::PointAttribute* c = dm.GetNamedAttribute(draco::GeometryAttribute::GENERIC)) {
    mesh.confidence.resize(dm.num_points());
    for (draco::PointIndex i(0); i < dm.num_points(); ++i) {
      float v = 1;
      c->ConvertValue<float, 1>(c->mapped_index(i), &v);
      mesh.confidence[i.value()] = v;
    }
  }
  mesh.triangles.reserve(dm.num_faces());
  for (draco::FaceIndex f(0); f < dm.num_faces(); ++f) {
    const draco::Mesh::Face& face = dm.face(f);
    mesh.triangles.push_back({face[0].value(), face[1].value(), face[2].value()});
  }
  return mesh;
}

StatusOr<DracoEncoded> encode_mesh_drc(const TriangleMesh& mesh, const DracoOptions& options) {
  if (mesh.empty()) return invalid_argument("drc: the mesh has no triangles");
  if (!mesh.is_consistent()) return invalid_argument("drc: the mesh's indices or attributes are inconsistent");
  return encode_checked(
      "drc", mesh.vertices, mesh.num_triangles(), true, options,
      [&](int bits) -> StatusOr<std::string> {
        draco::Mesh dm;
        to_draco_mesh(mesh, &dm);
        if (!mesh.confidence.empty()) {
          draco::GeometryAttribute ga;
          ga.Init(draco::GeometryAttribute::GENERIC, nullptr, 1, draco::DT_FLOAT32, false, sizeof(float), 0);
          const int id = dm.AddAttribute(ga, true, static_cast<uint32_t>(mesh.num_vertices()));
          for (size_t i = 0; i < mesh.num_vertices(); ++i)
            dm.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)),
                                                &mesh.confidence[i]);
        }
        draco::Encoder encoder;
        configure(options, bits, &encoder);
        encoder.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, 8);
        draco::EncoderBuffer out;
        const draco::Status st = encoder.EncodeMeshToBuffer(dm, &out);
        if (!st.ok()) return from_draco(st, "drc: Draco could not encode the mesh");
        return std::string(out.data(), out.size());
      },
      [](std::string_view bytes) -> StatusOr<Decoded> {
        ASSIGN_OR_RETURN(TriangleMesh back, decode_mesh_drc(bytes));
        return Decoded{std::move(back.vertices), back.num_triangles()};
      });
}

StatusOr<DracoEncoded> write_glb(const std::string& path, const TriangleMesh& mesh, const DracoOptions& options) {
  ASSIGN_OR_RETURN(DracoEncoded e, encode_glb(mesh, options));
  RETURN_IF_ERROR(write_file_atomically(path, e.bytes));
  return e;
}

StatusOr<DracoEncoded> write_drc(const std::string& path, const PointCloud& cloud, const DracoOptions& options) {
  ASSIGN_OR_RETURN(DracoEncoded e, encode_drc(cloud, options));
  RETURN_IF_ERROR(write_file_atomically(path, e.bytes));
  return e;
}

}  // namespace bodyscan::storage
