// The direct path the `inspect` goals are measured against (issue 15): a binary STL read with one
// fread, exact vertex merge (open addressing on the float bits), an edge check (every directed edge
// once, its reverse present: closed and consistently oriented) and the mass integrals (volume,
// centroid, inertia about it), single-threaded, no library. Prints one line.
//   direct_stl_reader FILE.stl
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {
std::uint64_t mix(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  return h;
}
struct Table {  // open addressing, at most half full; slot -1 = empty
  std::vector<std::int64_t> slot;
  std::size_t mask;
  explicit Table(std::size_t n) {
    std::size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    slot.assign(cap, -1);
    mask = cap - 1;
  }
};
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  std::FILE* f = std::fopen(argv[1], "rb");
  if (!f) return 1;
  std::fseek(f, 0, SEEK_END);
  const long size = std::ftell(f);
  std::fseek(f, 0, SEEK_SET);
  std::vector<unsigned char> buf(static_cast<std::size_t>(size));
  if (std::fread(buf.data(), 1, buf.size(), f) != buf.size()) return 1;
  std::fclose(f);
  std::uint32_t nf = 0;
  std::memcpy(&nf, buf.data() + 80, 4);
  if (84 + 50ull * nf != static_cast<unsigned long long>(size)) return 1;

  // Vertex merge: key = the 12 bytes of a corner's three floats.
  std::vector<float> xyz;  // merged vertices
  std::vector<std::uint32_t> tri(3ull * nf);
  Table vt(nf / 2 + 16);
  for (std::size_t c = 0; c < 3ull * nf; ++c) {
    const unsigned char* p = buf.data() + 84 + 50 * (c / 3) + 12 + 12 * (c % 3);
    std::uint32_t b[3];
    std::memcpy(b, p, 12);
    std::size_t i = mix((std::uint64_t(b[0]) << 32 | b[1]) ^ mix(b[2])) & vt.mask;
    for (;; i = (i + 1) & vt.mask) {
      if (vt.slot[i] < 0) {
        vt.slot[i] = static_cast<std::int64_t>(xyz.size() / 3);
        xyz.insert(xyz.end(), reinterpret_cast<const float*>(p), reinterpret_cast<const float*>(p) + 3);
        break;
      }
      if (std::memcmp(&xyz[3 * vt.slot[i]], p, 12) == 0) break;
    }
    tri[c] = static_cast<std::uint32_t>(vt.slot[i]);
  }
  const std::size_t nv = xyz.size() / 3;

  // Edge check: the directed edges a -> b listed per vertex a (counting sort); each must appear once
  // and its reverse b -> a must exist (closed and consistently oriented).
  std::vector<std::uint32_t> start(nv + 2, 0), to(3ull * nf);
  for (std::size_t c = 0; c < 3ull * nf; ++c) ++start[tri[c] + 2];
  for (std::size_t v = 0; v < nv; ++v) start[v + 2] += start[v + 1];
  for (std::size_t c = 0; c < 3ull * nf; ++c) to[start[tri[c] + 1]++] = tri[c - c % 3 + (c + 1) % 3];
  std::size_t repeated = 0, unmatched = 0;
  for (std::size_t a = 0; a < nv; ++a)
    for (std::uint32_t i = start[a]; i < start[a + 1]; ++i) {
      const std::uint32_t b = to[i];
      for (std::uint32_t j = i + 1; j < start[a + 1]; ++j) repeated += to[j] == b;
      bool back = false;
      for (std::uint32_t j = start[b]; j < start[b + 1]; ++j) back = back || to[j] == a;
      unmatched += !back;
    }

  // Mass integrals about the first vertex (recentred), unit density.
  const double o[3] = {xyz[0], xyz[1], xyz[2]};
  double vol = 0, m1[3] = {0, 0, 0}, m2[6] = {0, 0, 0, 0, 0, 0};
  for (std::size_t t = 0; t < nf; ++t) {
    double v[3][3];
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) v[k][j] = xyz[3 * tri[3 * t + k] + j] - o[j];
    const double d = v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1]) - v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0]) +
                     v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
    vol += d / 6;
    int q = 0;
    for (int i = 0; i < 3; ++i) {
      const double s = v[0][i] + v[1][i] + v[2][i];
      m1[i] += d / 24 * s;
      for (int j = i; j < 3; ++j, ++q)
        m2[q] += d / 120 * (v[0][i] * v[0][j] + v[1][i] * v[1][j] + v[2][i] * v[2][j] + s * (v[0][j] + v[1][j] + v[2][j]));
    }
  }
  const double g[3] = {m1[0] / vol, m1[1] / vol, m1[2] / vol};
  const double cxx = m2[0] - vol * g[0] * g[0], cyy = m2[3] - vol * g[1] * g[1], czz = m2[5] - vol * g[2] * g[2];
  std::printf("triangles %u vertices %zu closed_oriented %d volume %.9g centroid %.9g %.9g %.9g Ixx %.9g Iyy %.9g Izz %.9g\n",
              nf, nv, repeated == 0 && unmatched == 0, vol, g[0] + o[0], g[1] + o[1], g[2] + o[2], cyy + czz,
              cxx + czz, cxx + cyy);
  return repeated == 0 && unmatched == 0 ? 0 : 1;
}
