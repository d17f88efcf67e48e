#include "stl_binary.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "impactdeck/common/error.hpp"
#include "vertex_index.hpp"

namespace impactdeck::geometry::detail {

namespace {
constexpr std::size_t kHeaderBytes = 84, kTriangleBytes = 50;
// Triangles per fread: ~0.8 MB, so the file is never held whole in memory.
constexpr std::size_t kChunkTriangles = 16384;
}  // namespace

std::optional<LoadedMesh> read_binary_stl(std::FILE* f, const std::string& head, const std::string& where,
                                          LengthUnit unit, std::uintmax_t bytes) {
  if (bytes < kHeaderBytes + kTriangleBytes || head.size() != kHeaderBytes) return std::nullopt;
  std::uint32_t count = 0;
  std::memcpy(&count, head.data() + 80, 4);
  if (count == 0 || kHeaderBytes + kTriangleBytes * static_cast<std::uintmax_t>(count) != bytes) return std::nullopt;

  LoadedMesh out;
  out.format = "stl";
  out.file_vertices = 3 * static_cast<std::size_t>(count);
  out.mesh.triangles.reserve(count);
  // A closed surface has about n/2 vertices; a soup grows the vector as needed.
  out.mesh.vertices_m.reserve(count / 2 + 16);
  // STL: 3 records per triangle, about 6 per distinct vertex (as load_mesh sizes it).
  VertexIndex index(out.file_vertices / 4 + 16);
  const double to_m = metres_per(unit);
  std::vector<unsigned char> buf(kChunkTriangles * kTriangleBytes);
  // A chunk's corners, converted and hashed first, so that the merge below can ask for the table
  // slots (and then the vertices) of corners kSlotAhead and kVertexAhead ahead of the one it looks
  // up: the lookups' memory waits overlap instead of following one another. The same ids, in the
  // same order, as one lookup after the other.
  constexpr std::size_t kSlotAhead = 32, kVertexAhead = 16;
  std::vector<Eigen::Vector3d> corner(3 * kChunkTriangles);
  std::vector<std::uint64_t> hash(3 * kChunkTriangles);
  for (std::size_t first = 0; first < count;) {
    const std::size_t n = std::min<std::size_t>(kChunkTriangles, count - first);
    if (std::fread(buf.data(), kTriangleBytes, n, f) != n) {
      throw InputError(where, "triangle " + std::to_string(first), "cannot read the file (it changed while being read?)");
    }
    const std::size_t corners = 3 * n;
    for (std::size_t c = 0; c < corners; ++c) {
      const unsigned char* rec = buf.data() + (c / 3) * kTriangleBytes + 12 + 12 * (c % 3);  // after the normal
      float p[3];
      std::memcpy(p, rec, sizeof p);
      Eigen::Vector3d x(static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]));
      if (!x.allFinite()) {
        // assimp numbers the vertices of a binary STL 3 f + k, in one mesh.
        throw InputError(where, "vertex " + std::to_string(3 * first + c) + " of mesh 0",
                         "coordinate is not a finite number");
      }
      corner[c] = x * to_m;
      hash[c] = position_hash(corner[c]);
    }
    for (std::size_t c = 0; c < std::min(corners, kSlotAhead); ++c) index.prefetch_slot(hash[c]);
    std::array<int, 3> tri{};
    for (std::size_t c = 0; c < corners; ++c) {
      if (c + kSlotAhead < corners) index.prefetch_slot(hash[c + kSlotAhead]);
      if (c + kVertexAhead < corners) index.prefetch_vertex(hash[c + kVertexAhead], out.mesh.vertices_m);
      bool inserted = false;
      tri[c % 3] = index.find_or_add(corner[c], hash[c], out.mesh.vertices_m, inserted);
      if (!inserted) ++out.merged_vertices;
      if (c % 3 == 2) out.mesh.triangles.push_back(tri);
    }
    first += n;
  }
  // A soup's vector grew by doubling: give back a large unused tail (a copy, so only when large).
  if (out.mesh.vertices_m.capacity() - out.mesh.vertices_m.size() > out.mesh.vertices_m.size() / 4)
    out.mesh.vertices_m.shrink_to_fit();
  return out;
}

}  // namespace impactdeck::geometry::detail
