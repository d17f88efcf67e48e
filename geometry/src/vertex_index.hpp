#pragma once
// Private to geometry/src: the exact-position vertex merge shared by the mesh readers.
#include <cstdint>
#include <cstring>
#include <vector>

#include <Eigen/Dense>

namespace impactdeck::geometry::detail {

// Exact-position vertex merge: a flat open-addressing table of vertex ids (linear probing, at
// most half full), keyed by the bits of the coordinates: no node allocated per vertex and no
// pointer chasing, unlike std::unordered_map. Ids are given in order of first use, as before.
inline std::uint64_t position_hash(const Eigen::Vector3d& v) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (int i = 0; i < 3; ++i) {
    const double x = v[i] + 0.0;  // -0 and +0 are the same point
    std::uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    h = (h ^ bits) * 0xff51afd7ed558ccdull;
    h ^= h >> 32;
  }
  h *= 0xc4ceb9fe1a85ec53ull;
  return h ^ (h >> 29);
}
class VertexIndex {
 public:
  explicit VertexIndex(std::size_t expected) {
    std::size_t cap = 16;
    while (cap < 2 * expected) cap *= 2;
    slots_.assign(cap, -1);
    mask_ = cap - 1;
  }
  // Id of the vertex at x in `vertices`, appending it when new; `inserted` says which.
  int find_or_add(const Eigen::Vector3d& x, std::vector<Eigen::Vector3d>& vertices, bool& inserted) {
    return find_or_add(x, position_hash(x), vertices, inserted);
  }
  // The same with x's position_hash computed beforehand (a reader that prefetches, below).
  int find_or_add(const Eigen::Vector3d& x, std::uint64_t hash, std::vector<Eigen::Vector3d>& vertices,
                  bool& inserted) {
    if (2 * (vertices.size() + 1) > slots_.size()) grow(vertices);
    std::size_t i = hash & mask_;
    while (slots_[i] >= 0) {
      if (vertices[slots_[i]] == x) {
        inserted = false;
        return slots_[i];
      }
      i = (i + 1) & mask_;
    }
    slots_[i] = static_cast<int>(vertices.size());
    vertices.push_back(x);
    inserted = true;
    return slots_[i];
  }

  // Hints for a lookup a few corners ahead (a large mesh's table and vertices are far larger than
  // the caches, and each lookup would otherwise wait for memory twice): the slot of `hash`, and
  // once that is in cache, the vertex it holds. Only hints: the lookup does not depend on them.
  void prefetch_slot(std::uint64_t hash) const {
#if defined(__GNUC__)
    __builtin_prefetch(&slots_[hash & mask_]);
#else
    (void)hash;
#endif
  }
  void prefetch_vertex(std::uint64_t hash, const std::vector<Eigen::Vector3d>& vertices) const {
#if defined(__GNUC__)
    const int id = slots_[hash & mask_];
    if (id >= 0) __builtin_prefetch(&vertices[static_cast<std::size_t>(id)]);
#else
    (void)hash, (void)vertices;
#endif
  }

 private:
  void grow(const std::vector<Eigen::Vector3d>& vertices) {
    slots_.assign(2 * slots_.size(), -1);
    mask_ = slots_.size() - 1;
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      std::size_t i = position_hash(vertices[v]) & mask_;
      while (slots_[i] >= 0) i = (i + 1) & mask_;
      slots_[i] = static_cast<int>(v);
    }
  }
  std::vector<int> slots_;
  std::size_t mask_ = 0;
};

}  // namespace impactdeck::geometry::detail
