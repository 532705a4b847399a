#include "recon/surface/marching_cubes.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <map>
#include <mutex>
#include <numeric>

namespace bodyscan {

namespace {

int corner_bit(int corner, int axis) { return (corner >> axis) & 1; }

// Cube edge number between two corners that differ in exactly one axis.
int edge_between(int c0, int c1) {
  const int diff = c0 ^ c1;
  const int a = diff == 1 ? 0 : diff == 2 ? 1 : 2;
  const int base = c0 & ~diff;
  return 4 * a + corner_bit(base, (a + 1) % 3) + 2 * corner_bit(base, (a + 2) % 3);
}

// The two cube faces an edge lies on, as bits of a 6-bit set (face 2a + side).
int edge_faces(int e) {
  const int a = e / 4, b = (a + 1) % 3, c = (a + 2) % 3;
  return (1 << (2 * b + (e & 1))) | (1 << (2 * c + ((e >> 1) & 1)));
}

// True when three cube edges all lie on one face of the cube.
bool edges_share_face(int e0, int e1, int e2) { return (edge_faces(e0) & edge_faces(e1) & edge_faces(e2)) != 0; }

using CaseTable = std::array<std::vector<std::array<uint8_t, 3>>, 256>;

CaseTable build_table() {
  CaseTable table;
  for (int mask = 0; mask < 256; ++mask) {
    std::map<int, int> next;  // segment start edge -> end edge
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int side = 0; side < 2; ++side) {
        // Counter-clockwise about +e_a in the (b, c) plane; reversed for the -e_a face.
        std::array<std::array<int, 2>, 4> bc = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
        if (side == 0) std::swap(bc[1], bc[3]);
        std::array<int, 4> corners;
        for (int i = 0; i < 4; ++i) {
          corners[i] = (side << a) | (bc[i][0] << b) | (bc[i][1] << c);
        }
        auto inside = [&](int i) { return (mask >> corners[i & 3]) & 1; };
        for (int i = 0; i < 4; ++i) {
          if (inside(i) || !inside(i + 1)) continue;  // not an entry (out -> in)
          const int entry = edge_between(corners[i], corners[(i + 1) & 3]);
          int j = i + 1;
          while (inside(j)) ++j;  // the next exit (in -> out)
          const int exit = edge_between(corners[(j - 1) & 3], corners[j & 3]);
          assert(!next.count(entry));
          next[entry] = exit;
        }
      }
    }
    while (!next.empty()) {
      std::vector<int> loop;
      int e = next.begin()->first;
      while (next.count(e)) {
        loop.push_back(e);
        const int f = next[e];
        next.erase(e);
        e = f;
      }
      assert(e == loop.front());
      // Fan from the first corner that makes no triangle lie in a cube face: such
      // a triangle would be matched by the neighbouring cell's identical one with
      // the opposite winding, and their edges would be used four times.
      const size_t m = loop.size();
      size_t apex = 0;
      for (size_t start = 0; start < m; ++start) {
        bool flat = false;
        for (size_t i = 1; i + 1 < m && !flat; ++i) {
          flat = edges_share_face(loop[start], loop[(start + i) % m], loop[(start + i + 1) % m]);
        }
        if (!flat) {
          apex = start;
          break;
        }
      }
      for (size_t i = 1; i + 1 < m; ++i) {
        table[mask].push_back({static_cast<uint8_t>(loop[apex]), static_cast<uint8_t>(loop[(apex + i) % m]),
                               static_cast<uint8_t>(loop[(apex + i + 1) % m])});
      }
    }
  }
  return table;
}

// A brick's nodes plus the one-node apron from its +x/+y/+z neighbours, so every
// cell whose first corner is in the brick sees all eight corners.
struct Gathered {
  int n = 0;  // B + 1
  std::vector<float> f, w;
  float& fv(int x, int y, int z) { return f[x + n * (y + n * z)]; }
  float& wv(int x, int y, int z) { return w[x + n * (y + n * z)]; }
};

void gather(const ImplicitField& field, const std::array<long, 8>& nb, Gathered& g) {
  const int bs = field.brick_size();
  g.n = bs + 1;
  g.f.assign(static_cast<size_t>(g.n) * g.n * g.n, 0.f);
  g.w.assign(g.f.size(), 0.f);
  for (int z = 0; z <= bs; ++z) {
    for (int y = 0; y <= bs; ++y) {
      for (int x = 0; x <= bs; ++x) {
        const int which = (x == bs) | ((y == bs) << 1) | ((z == bs) << 2);
        const long src = nb[which];
        if (src < 0) continue;
        const int lx = x & (bs - 1), ly = y & (bs - 1), lz = z & (bs - 1);
        const size_t idx = static_cast<size_t>(lx + bs * (ly + bs * lz));
        g.fv(x, y, z) = field.values(static_cast<size_t>(src))[idx];
        g.wv(x, y, z) = field.weights(static_cast<size_t>(src))[idx];
      }
    }
  }
}

std::array<long, 8> neighbours(const ImplicitField& field, size_t b) {
  const Eigen::Vector3i c = field.brick_coord(b);
  std::array<long, 8> nb;
  for (int i = 0; i < 8; ++i) {
    nb[i] = i == 0 ? static_cast<long>(b) : field.find_brick(c + Eigen::Vector3i(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  }
  return nb;
}

}  // namespace

const std::vector<std::array<uint8_t, 3>>& marching_cubes_case(uint8_t inside_mask) {
  static const CaseTable table = build_table();
  return table[inside_mask];
}

StatusOr<TriangleMesh> extract_isosurface(const ImplicitField& field, const MarchingCubesOptions& options) {
  const size_t nb = field.num_bricks();
  const int bs = field.brick_size();
  const float min_w = std::max(options.min_weight, std::numeric_limits<float>::min());
  const float h = field.voxel_size();
  auto defined = [&](float w) { return w >= min_w; };
  auto inside = [](float f) { return f > 0.f; };

  // Pass 1: vertices on the edges each brick owns. Iterating z, y, x, axis keeps
  // each brick's edge ids sorted, so pass 2 can binary-search them.
  std::vector<std::vector<Vec3f>> verts(nb);
  std::vector<std::vector<uint32_t>> edge_ids(nb);
  std::mutex progress_mutex;
  double last_fraction = 0.0;
  std::atomic<size_t> done{0};
  std::atomic<bool> stop{false};
  // Both passes count into `done`, so the fraction runs 0..1 over the two.
  auto tick = [&](size_t count) {
    const size_t d = done.fetch_add(count) + count;
    if (!options.progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    // Under the lock, so that reports never go backwards.
    last_fraction = std::max(last_fraction, std::min(1.0, static_cast<double>(d) / (2.0 * static_cast<double>(nb))));
    if (!options.progress("mesh", last_fraction)) stop = true;
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nb, 8), [&](const tbb::blocked_range<size_t>& r) {
    if (stop) return;
    Gathered g;
    for (size_t b = r.begin(); b != r.end(); ++b) {
      gather(field, neighbours(field, b), g);
      const Vec3d o = field.node_position(field.brick_coord(b) * bs);
      for (int z = 0; z < bs; ++z) {
        for (int y = 0; y < bs; ++y) {
          for (int x = 0; x < bs; ++x) {
            const float w0 = g.wv(x, y, z);
            if (!defined(w0)) continue;
            const float f0 = g.fv(x, y, z);
            for (int a = 0; a < 3; ++a) {
              const int x1 = x + (a == 0), y1 = y + (a == 1), z1 = z + (a == 2);
              if (!defined(g.wv(x1, y1, z1))) continue;
              const float f1 = g.fv(x1, y1, z1);
              if (inside(f0) == inside(f1)) continue;
              // Clamped so that no vertex sits exactly on a node, which would make
              // zero-area triangles.
              const float t = std::clamp(f0 / (f0 - f1), 1e-3f, 1.f - 1e-3f);
              Vec3d p = o + static_cast<double>(h) * Vec3d(x, y, z);
              p[a] += static_cast<double>(h) * t;
              verts[b].push_back(p.cast<float>());
              edge_ids[b].push_back(static_cast<uint32_t>(((z * bs + y) * bs + x) * 3 + a));
            }
          }
        }
      }
    }
    tick(r.size());
  });
  if (stop) return cancelled("reconstruction cancelled");

  std::vector<uint32_t> offset(nb + 1, 0);
  for (size_t b = 0; b < nb; ++b) offset[b + 1] = offset[b] + static_cast<uint32_t>(verts[b].size());

  // Pass 2: triangles of the cells whose first corner lies in the brick.
  std::vector<std::vector<Triangle>> tris(nb);
  std::atomic<bool> broken{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nb, 8), [&](const tbb::blocked_range<size_t>& r) {
    if (stop) return;
    Gathered g;
    for (size_t b = r.begin(); b != r.end(); ++b) {
      const std::array<long, 8> nbr = neighbours(field, b);
      gather(field, nbr, g);
      auto vertex_of = [&](int x, int y, int z, int a) -> long {
        const int which = (x >= bs) | ((y >= bs) << 1) | ((z >= bs) << 2);
        const long owner = nbr[which];
        if (owner < 0) return -1;
        const int lx = x & (bs - 1), ly = y & (bs - 1), lz = z & (bs - 1);
        const uint32_t id = static_cast<uint32_t>(((lz * bs + ly) * bs + lx) * 3 + a);
        const auto& ids = edge_ids[static_cast<size_t>(owner)];
        auto it = std::lower_bound(ids.begin(), ids.end(), id);
        if (it == ids.end() || *it != id) return -1;
        return static_cast<long>(offset[static_cast<size_t>(owner)] + (it - ids.begin()));
      };
      for (int z = 0; z < bs; ++z) {
        for (int y = 0; y < bs; ++y) {
          for (int x = 0; x < bs; ++x) {
            uint8_t mask = 0;
            bool all_defined = true;
            for (int v = 0; v < 8 && all_defined; ++v) {
              const int cx = x + (v & 1), cy = y + ((v >> 1) & 1), cz = z + ((v >> 2) & 1);
              all_defined = defined(g.wv(cx, cy, cz));
              if (inside(g.fv(cx, cy, cz))) mask |= static_cast<uint8_t>(1u << v);
            }
            if (!all_defined || mask == 0 || mask == 255) continue;
            for (const auto& tri : marching_cubes_case(mask)) {
              Triangle t;
              for (int k = 0; k < 3; ++k) {
                const int e = tri[k];
                const int a = e / 4, bb = (a + 1) % 3, cc = (a + 2) % 3;
                Eigen::Vector3i start(x, y, z);
                start[bb] += e & 1;
                start[cc] += (e >> 1) & 1;
                const long vi = vertex_of(start.x(), start.y(), start.z(), a);
                if (vi < 0) {
                  broken = true;
                  continue;
                }
                t[k] = static_cast<uint32_t>(vi);
              }
              tris[b].push_back(t);
            }
          }
        }
      }
    }
    tick(r.size());
  });
  if (stop) return cancelled("reconstruction cancelled");
  if (broken) return internal_error("marching cubes: a cell referenced an edge without a vertex");

  // Assemble, dropping vertices on edges whose cells were not fully defined.
  TriangleMesh mesh;
  size_t nt = 0;
  for (const auto& t : tris) nt += t.size();
  mesh.triangles.reserve(nt);
  for (auto& t : tris) {
    mesh.triangles.insert(mesh.triangles.end(), t.begin(), t.end());
    std::vector<Triangle>().swap(t);
  }
  std::vector<uint32_t> remap(offset[nb], UINT32_MAX);
  for (const Triangle& t : mesh.triangles)
    for (uint32_t v : t) remap[v] = 0;
  uint32_t next = 0;
  mesh.vertices.reserve(offset[nb]);
  for (size_t b = 0; b < nb; ++b) {
    for (size_t i = 0; i < verts[b].size(); ++i) {
      uint32_t& m = remap[offset[b] + i];
      if (m == UINT32_MAX) continue;
      m = next++;
      mesh.vertices.push_back(verts[b][i]);
    }
  }
  for (Triangle& t : mesh.triangles)
    for (uint32_t& v : t) v = remap[v];
  return mesh;
}

}  // namespace bodyscan
