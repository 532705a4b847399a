#include "storage/formats/mesh_files.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "recon/io/atomic_file.hpp"

namespace bodyscan::storage {

namespace {

void append_float(std::string* out, float f) {
  char b[4];
  std::memcpy(b, &f, 4);  // x86-64 and ARM64 are little-endian, as STL wants
  out->append(b, 4);
}

// Shortest text that reads back to the same float.
void append_number(std::string* out, float f) {
  char b[32];
  const int n = std::snprintf(b, sizeof b, "%.9g", static_cast<double>(f));
  out->append(b, static_cast<size_t>(n));
}

}  // namespace

std::string encode_obj(const TriangleMesh& mesh, ModelUnit unit) {
  const float scale = unit == ModelUnit::kMetre ? 0.001f : 1.0f;
  std::string out =
      unit == ModelUnit::kMetre ? "# bodyscan mesh, metres, Y up\n" : "# bodyscan mesh, millimetres, Y up\n";
  out.reserve(mesh.num_vertices() * 40 + mesh.num_triangles() * 30);
  for (const Vec3f& v : mesh.vertices) {
    out += "v ";
    append_number(&out, scale * v.x()), out += ' ';
    append_number(&out, scale * v.y()), out += ' ';
    append_number(&out, scale * v.z()), out += '\n';
  }
  const bool normals = mesh.normals.size() == mesh.vertices.size() && !mesh.normals.empty();
  if (normals)
    for (const Vec3f& n : mesh.normals) {
      out += "vn ";
      append_number(&out, n.x()), out += ' ';
      append_number(&out, n.y()), out += ' ';
      append_number(&out, n.z()), out += '\n';
    }
  for (const Triangle& t : mesh.triangles) {
    out += 'f';
    for (uint32_t i : t) {
      const std::string k = std::to_string(i + 1);
      out += ' ', out += k;
      if (normals) out += "//", out += k;
    }
    out += '\n';
  }
  return out;
}

StatusOr<std::string> encode_plain_glb(const TriangleMesh& mesh) {
  if (mesh.empty()) return invalid_argument("glb: the mesh has no triangles");
  if (!mesh.is_consistent()) return invalid_argument("glb: the mesh's indices or attributes are inconsistent");
  // glTF asks for unit normals: where a vertex has none (its triangles all
  // degenerate), the file carries none and the reader computes them.
  const bool normals =
      !mesh.normals.empty() && std::all_of(mesh.normals.begin(), mesh.normals.end(),
                                           [](const Vec3f& n) { return std::abs(n.squaredNorm() - 1.f) < 1e-3f; });
  // The binary chunk: positions (m), normals, indices; each 4-byte aligned.
  std::string bin;
  bin.reserve(mesh.num_vertices() * (normals ? 24 : 12) + mesh.num_triangles() * 12);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Vec3f& v : mesh.vertices) {
    const Eigen::Vector3f m = 0.001f * v;
    lo = lo.cwiseMin(m), hi = hi.cwiseMax(m);
    for (int k = 0; k < 3; ++k) append_float(&bin, m[k]);
  }
  const size_t positions_bytes = bin.size();
  if (normals)
    for (const Vec3f& n : mesh.normals) {
      const Vec3f unit = n.normalized();
      for (int k = 0; k < 3; ++k) append_float(&bin, unit[k]);
    }
  const size_t normals_bytes = bin.size() - positions_bytes;
  for (const Triangle& t : mesh.triangles)
    for (uint32_t i : t) {
      char b[4];
      std::memcpy(b, &i, 4);
      bin.append(b, 4);
    }
  const size_t indices_bytes = bin.size() - positions_bytes - normals_bytes;

  constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;
  nlohmann::json attributes = {{"POSITION", 0}};
  nlohmann::json accessors = nlohmann::json::array();
  nlohmann::json views = nlohmann::json::array();
  views.push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", positions_bytes}, {"target", kArrayBuffer}});
  accessors.push_back({{"bufferView", 0},
                       {"componentType", kFloat},
                       {"count", mesh.num_vertices()},
                       {"type", "VEC3"},
                       {"min", {lo.x(), lo.y(), lo.z()}},
                       {"max", {hi.x(), hi.y(), hi.z()}}});
  if (normals) {
    attributes["NORMAL"] = 1;
    views.push_back(
        {{"buffer", 0}, {"byteOffset", positions_bytes}, {"byteLength", normals_bytes}, {"target", kArrayBuffer}});
    accessors.push_back(
        {{"bufferView", 1}, {"componentType", kFloat}, {"count", mesh.num_vertices()}, {"type", "VEC3"}});
  }
  views.push_back({{"buffer", 0},
                   {"byteOffset", positions_bytes + normals_bytes},
                   {"byteLength", indices_bytes},
                   {"target", kElementArrayBuffer}});
  accessors.push_back({{"bufferView", views.size() - 1},
                       {"componentType", kUnsignedInt},
                       {"count", 3 * mesh.num_triangles()},
                       {"type", "SCALAR"}});
  const nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}, {"generator", "bodyscan"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}, {"name", "body"}}}},
      {"meshes",
       {{{"name", "body"},
         {"primitives",
          {{{"attributes", attributes}, {"indices", accessors.size() - 1}, {"material", 0}, {"mode", 4}}}}}}},
      {"materials",
       {{{"name", "skin"},
         {"pbrMetallicRoughness",
          {{"baseColorFactor", {0.8, 0.8, 0.8, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.9}}}}}},
      {"accessors", accessors},
      {"bufferViews", views},
      {"buffers", {{{"byteLength", bin.size()}}}}};
  std::string json = gltf.dump();
  json.append((4 - json.size() % 4) % 4, ' ');  // chunks are 4-byte aligned; JSON pads with spaces
  // The container (glTF 2.0 §4.4): header, JSON chunk, BIN chunk.
  std::string out;
  const auto u32 = [&out](uint32_t v) {
    char b[4];
    std::memcpy(b, &v, 4);
    out.append(b, 4);
  };
  const size_t total = 12 + 8 + json.size() + 8 + bin.size();
  if (total > std::numeric_limits<uint32_t>::max()) return out_of_range("glb: the mesh is too large for one file");
  out.reserve(total);
  u32(0x46546C67u), u32(2), u32(static_cast<uint32_t>(total));
  u32(static_cast<uint32_t>(json.size())), u32(0x4E4F534Au), out += json;
  u32(static_cast<uint32_t>(bin.size())), u32(0x004E4942u), out += bin;
  return out;
}

std::string encode_stl(const TriangleMesh& mesh) {
  std::string out(80, ' ');
  const char title[] = "bodyscan mesh, millimetres, Y up";
  std::memcpy(out.data(), title, sizeof title - 1);
  const auto n = static_cast<uint32_t>(mesh.num_triangles());
  char count[4];
  std::memcpy(count, &n, 4);
  out.append(count, 4);
  out.reserve(84 + 50 * size_t{n});
  for (const Triangle& t : mesh.triangles) {
    const Vec3f& a = mesh.vertices[t[0]];
    const Vec3f& b = mesh.vertices[t[1]];
    const Vec3f& c = mesh.vertices[t[2]];
    Vec3f normal = (b - a).cross(c - a);
    const float len = normal.norm();
    normal = len > 0 ? Vec3f(normal / len) : Vec3f::Zero();
    for (int k = 0; k < 3; ++k) append_float(&out, normal[k]);
    for (const Vec3f* v : {&a, &b, &c})
      for (int k = 0; k < 3; ++k) append_float(&out, (*v)[k]);
    out.append(2, '\0');  // attribute byte count
  }
  return out;
}

Status write_obj(const std::string& path, const TriangleMesh& mesh) {
  if (!mesh.is_consistent()) return invalid_argument("obj: the mesh's indices or attributes are inconsistent");
  return write_file_atomically(path, encode_obj(mesh));
}

Status write_stl(const std::string& path, const TriangleMesh& mesh) {
  if (!mesh.is_consistent()) return invalid_argument("stl: the mesh's indices or attributes are inconsistent");
  return write_file_atomically(path, encode_stl(mesh));
}

}  // namespace bodyscan::storage
