#include "storage/formats/mesh_files.hpp"

#include <cstdint>
#include <cstring>

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

std::string encode_obj(const TriangleMesh& mesh) {
  std::string out = "# bodyscan mesh, millimetres, Y up\n";
  out.reserve(mesh.num_vertices() * 40 + mesh.num_triangles() * 30);
  for (const Vec3f& v : mesh.vertices) {
    out += "v ";
    append_number(&out, v.x()), out += ' ';
    append_number(&out, v.y()), out += ' ';
    append_number(&out, v.z()), out += '\n';
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
