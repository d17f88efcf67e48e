#include "impactdeck/geometry/mesh_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "text_mesh_readers.hpp"
#include "stl_binary.hpp"
#include "vertex_index.hpp"

namespace impactdeck::geometry {
namespace fs = std::filesystem;

namespace {

bool is_identity(const aiMatrix4x4& m) { return m.IsIdentity(); }

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

LoadedMesh load_mesh(const fs::path& file, LengthUnit unit) {
  const std::string where = file.string();
  // A regular file (a FIFO or a device is refused before it is opened) that fits in memory.
  const std::uintmax_t bytes = detail::check_part_file(file);
  if (bytes == 0) throw InputError(where, "file", "is empty (0 bytes): no triangles");
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".stl" && ext != ".obj" && ext != ".ply" && ext != ".off") {
    throw InputError(where, "file", "unsupported format '" + ext + "' (expected .stl, .obj, .ply or .off)");
  }
  if (ext == ".stl") {
    // Opened once: the first 84 bytes tell binary from ASCII, and the same stream reads on. A
    // binary STL is read directly (float32 records, no assimp, no per-triangle allocation); an
    // ASCII one by the own reader. A read that comes up short goes to the general route below,
    // which says why.
    // Opened without blocking and checked on the descriptor: a FIFO swapped in after
    // check_part_file cannot hang the run (the general route below says why it is refused).
    std::unique_ptr<std::FILE, FileCloser> f;
    if (const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC); fd >= 0) {
      struct stat st {};
      if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) f.reset(::fdopen(fd, "rb"));
      if (!f) ::close(fd);
    }
    std::string head(static_cast<std::size_t>(std::min<std::uintmax_t>(84, bytes)), '\0');
    if (f && std::fread(head.data(), 1, head.size(), f.get()) == head.size()) {
      if (!detail::is_ascii_stl(head, bytes)) {
        if (auto binary = detail::read_binary_stl(f.get(), head, where, unit, bytes)) {
          detail::finish_loaded(*binary, where);
          return std::move(*binary);
        }
      } else {
        std::string text = std::move(head);
        const std::size_t done = text.size();
        text.resize(static_cast<std::size_t>(bytes));
        if (std::fread(text.data() + done, 1, text.size() - done, f.get()) == text.size() - done)
          return std::move(*detail::read_own_text(std::move(text), file, ext, unit));
      }
    }
  }
  // OFF, OBJ, PLY and ASCII STL: own readers in double precision (text_mesh_readers.hpp); assimp
  // (float32) sees only a binary STL the direct reader below declines (size and count disagree).
  if (auto own = detail::read_own_format(file, ext, unit, bytes)) return std::move(*own);

  LoadedMesh out;
  out.format = ext.substr(1);
  Assimp::Importer importer;
  // Lines and points are kept by assimp and skipped below (with a warning). No vertex joining by
  // assimp: it would keep STL's per-face normals apart; we merge exact positions ourselves.
  const aiScene* scene = importer.ReadFile(where, aiProcess_ValidateDataStructure);
  if (!scene) {
    std::string msg = importer.GetErrorString();
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    throw InputError(where, "parse", "cannot read the file (assimp: " + msg + ")");
  }
  // Count polygons before assimp triangulates them (ear clipping, concave faces included).
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    for (unsigned f = 0; f < scene->mMeshes[m]->mNumFaces; ++f)
      if (scene->mMeshes[m]->mFaces[f].mNumIndices > 3) ++out.polygons_triangulated;
  if (out.polygons_triangulated > 0) {
    scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
    if (!scene) {
      throw InputError(where, "parse", std::string("cannot triangulate its polygons (assimp: ") +
                                           importer.GetErrorString() + ")");
    }
  }

  std::size_t total_vertices = 0, total_faces = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    total_vertices += scene->mMeshes[m]->mNumVertices;
    total_faces += scene->mMeshes[m]->mNumFaces;
  }
  // STL: 3 records per triangle, about 6 per distinct vertex; the table grows if needed.
  detail::VertexIndex index(total_vertices / 4 + 16);
  out.mesh.triangles.reserve(total_faces);
  const double to_m = metres_per(unit);
  std::size_t face_counter = 0;  // faces in file order over all meshes (for messages)

  // Walk the node tree so that node transforms (rare in these formats) are honoured.
  struct Item { const aiNode* node; aiMatrix4x4 transform; };
  std::vector<Item> stack;
  if (scene->mRootNode) stack.push_back({scene->mRootNode, scene->mRootNode->mTransformation});
  std::vector<bool> mesh_seen(scene->mNumMeshes, false);
  std::vector<std::pair<unsigned, aiMatrix4x4>> mesh_order;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < it.node->mNumMeshes; ++i) {
      const unsigned mi = it.node->mMeshes[i];
      if (mi < scene->mNumMeshes) mesh_order.emplace_back(mi, it.transform);
    }
    for (unsigned c = 0; c < it.node->mNumChildren; ++c) {
      const aiNode* child = it.node->mChildren[c];
      stack.push_back({child, it.transform * child->mTransformation});
    }
  }
  if (mesh_order.empty())
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) mesh_order.emplace_back(m, aiMatrix4x4());
  std::sort(mesh_order.begin(), mesh_order.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });

  for (const auto& entry : mesh_order) {
    // Named copies, not a structured binding: lambdas below use them (clang 14 refuses to capture
    // bindings before C++20).
    const auto mi = entry.first;
    const auto& xf = entry.second;
    const aiMesh* mesh = scene->mMeshes[mi];
    const bool transform = !is_identity(xf);
    std::vector<int> local(mesh->mNumVertices, -1);
    out.file_vertices += mesh->mNumVertices;
    auto vertex_id = [&](unsigned v) {
      if (local[v] >= 0) return local[v];
      aiVector3D p = mesh->mVertices[v];
      if (transform) p = xf * p;
      // Double from the first conversion on: the float is converted exactly, then scaled.
      Eigen::Vector3d x(static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z));
      if (!x.allFinite()) {
        throw InputError(where, "vertex " + std::to_string(v) + " of mesh " + std::to_string(mi),
                         "coordinate is not a finite number");
      }
      x *= to_m;
      bool inserted = false;
      const int id = index.find_or_add(x, out.mesh.vertices_m, inserted);
      if (!inserted) ++out.merged_vertices;
      local[v] = id;
      return id;
    };
    for (unsigned f = 0; f < mesh->mNumFaces; ++f, ++face_counter) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 1) { ++out.points_ignored; continue; }
      if (face.mNumIndices == 2) { ++out.lines_ignored; continue; }
      if (face.mNumIndices != 3) {
        throw InputError(where, "face " + std::to_string(face_counter),
                         "has " + std::to_string(face.mNumIndices) + " corners after triangulation");
      }
      std::array<int, 3> t{};
      for (int k = 0; k < 3; ++k) {
        const unsigned v = face.mIndices[k];
        if (v >= mesh->mNumVertices) {
          throw InputError(where, "face " + std::to_string(face_counter),
                           "vertex index " + std::to_string(v) + " out of range (" +
                               std::to_string(mesh->mNumVertices) + " vertices)");
        }
        t[k] = vertex_id(v);
      }
      out.mesh.triangles.push_back(t);
    }
  }
  // Vertices of skipped points/lines never get an id (vertex_id runs for triangle corners only),
  // and ids are given in order of first use: every vertex is a triangle corner, no remap needed.
  detail::finish_loaded(out, where);
  return out;
}

namespace {
// STL holds float32 coordinates: every one must be finite and, unless 0, a normal float (a part
// 1e39 or 1e-60 units across would be written as Inf or as zeros).
void check_float32(const fs::path& file, const TriangleMesh& mesh, double scale) {
  for (std::size_t v = 0; v < mesh.vertices_m.size(); ++v)
    for (int i = 0; i < 3; ++i) {
      const double x = mesh.vertices_m[v][i] * scale;
      const float f = static_cast<float>(x);
      if (x != 0.0 && (!std::isfinite(f) || std::abs(f) < std::numeric_limits<float>::min())) {
        std::ostringstream m;
        m << "vertex " << v << " has the coordinate " << x << ", which float32, the STL coordinate type, cannot "
          << "hold (finite and normal: 1.2e-38 to 3.4e+38 in magnitude, or 0); nothing was written";
        throw InputError(file.string(), "coordinates", m.str());
      }
    }
}

void put_f32(std::ostream& o, float x) {
  char b[4];
  std::memcpy(b, &x, 4);
  o.write(b, 4);
}
}  // namespace

void write_stl_binary(std::ostream& o, const std::string& name, const TriangleMesh& mesh, LengthUnit unit,
                      const std::string& header) {
  const double s = 1.0 / metres_per(unit);
  check_float32(name, mesh, s);
  char h[80] = {};
  std::string text = header;
  if (text.rfind("solid", 0) == 0) text = "binary " + text;  // readers sniff "solid" as ascii
  std::memcpy(h, text.data(), std::min<std::size_t>(text.size(), 80));
  o.write(h, 80);
  const std::uint32_t n = static_cast<std::uint32_t>(mesh.triangles.size());
  char nb[4];
  std::memcpy(nb, &n, 4);
  o.write(nb, 4);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d &a = mesh.vertices_m[t[0]], &b = mesh.vertices_m[t[1]], &c = mesh.vertices_m[t[2]];
    Eigen::Vector3d nrm = (b - a).cross(c - a);
    if (nrm.norm() > 0) nrm.normalize();
    for (int i = 0; i < 3; ++i) put_f32(o, static_cast<float>(nrm[i]));
    for (const auto* p : {&a, &b, &c})
      for (int i = 0; i < 3; ++i) put_f32(o, static_cast<float>((*p)[i] * s));
    o.write("\0\0", 2);
  }
}

void write_stl_ascii(std::ostream& o, const std::string& file, const TriangleMesh& mesh, LengthUnit unit,
                     const std::string& name) {
  const double s = 1.0 / metres_per(unit);
  check_float32(file, mesh, s);
  o << std::setprecision(9) << "solid " << name << "\n";
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d &a = mesh.vertices_m[t[0]], &b = mesh.vertices_m[t[1]], &c = mesh.vertices_m[t[2]];
    Eigen::Vector3d nrm = (b - a).cross(c - a);
    if (nrm.norm() > 0) nrm.normalize();
    o << "  facet normal " << nrm.x() + 0.0 << " " << nrm.y() + 0.0 << " " << nrm.z() + 0.0 << "\n    outer loop\n";
    for (const auto* p : {&a, &b, &c})
      // The float32 values a binary STL would hold, printed with 9 digits (float round trip).
      o << "      vertex " << static_cast<float>((*p)[0] * s) + 0.0f << " " << static_cast<float>((*p)[1] * s) + 0.0f
        << " " << static_cast<float>((*p)[2] * s) + 0.0f << "\n";
    o << "    endloop\n  endfacet\n";
  }
  o << "endsolid " << name << "\n";
}

void write_stl_binary(const fs::path& file, const TriangleMesh& mesh, LengthUnit unit, const std::string& header) {
  check_float32(file, mesh, 1.0 / metres_per(unit));  // before the file is created
  write_file_atomically(file, [&](std::ostream& o) { write_stl_binary(o, file.string(), mesh, unit, header); });
}

void write_stl_ascii(const fs::path& file, const TriangleMesh& mesh, LengthUnit unit, const std::string& name) {
  check_float32(file, mesh, 1.0 / metres_per(unit));
  write_file_atomically(file, [&](std::ostream& o) { write_stl_ascii(o, file.string(), mesh, unit, name); });
}

}  // namespace impactdeck::geometry
