#include "stl_binary.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "impactdeck/common/error.hpp"
#include "vertex_index.hpp"

namespace impactdeck::geometry::detail {

namespace {
constexpr std::size_t kHeaderBytes = 84, kTriangleBytes = 50;
// Triangles per fread: ~0.8 MB, so the file is never held whole in memory.
constexpr std::size_t kChunkTriangles = 16384;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
}  // namespace

std::optional<LoadedMesh> read_binary_stl(const std::filesystem::path& file, const std::string& where,
                                          LengthUnit unit, std::uintmax_t bytes) {
  if (bytes < kHeaderBytes + kTriangleBytes) return std::nullopt;
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(file.c_str(), "rb"));
  if (!f) return std::nullopt;  // the general route reports why
  unsigned char head[kHeaderBytes];
  if (std::fread(head, 1, kHeaderBytes, f.get()) != kHeaderBytes) return std::nullopt;
  std::uint32_t count = 0;
  std::memcpy(&count, head + 80, 4);
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
  for (std::size_t first = 0; first < count;) {
    const std::size_t n = std::min<std::size_t>(kChunkTriangles, count - first);
    if (std::fread(buf.data(), kTriangleBytes, n, f.get()) != n) {
      throw InputError(where, "triangle " + std::to_string(first), "cannot read the file (it changed while being read?)");
    }
    for (std::size_t t = 0; t < n; ++t) {
      const unsigned char* rec = buf.data() + t * kTriangleBytes + 12;  // after the normal
      std::array<int, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        float p[3];
        std::memcpy(p, rec + 12 * k, sizeof p);
        Eigen::Vector3d x(static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]));
        if (!x.allFinite()) {
          // assimp numbers the vertices of a binary STL 3 f + k, in one mesh.
          throw InputError(where, "vertex " + std::to_string(3 * (first + t) + k) + " of mesh 0",
                           "coordinate is not a finite number");
        }
        x *= to_m;
        bool inserted = false;
        tri[k] = index.find_or_add(x, out.mesh.vertices_m, inserted);
        if (!inserted) ++out.merged_vertices;
      }
      out.mesh.triangles.push_back(tri);
    }
    first += n;
  }
  // A soup's vector grew by doubling: give back a large unused tail (a copy, so only when large).
  if (out.mesh.vertices_m.capacity() - out.mesh.vertices_m.size() > out.mesh.vertices_m.size() / 4)
    out.mesh.vertices_m.shrink_to_fit();
  return out;
}

}  // namespace impactdeck::geometry::detail
