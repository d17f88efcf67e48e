#include "impactdeck/geometry/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "stl_binary.hpp"
#include "vertex_index.hpp"

namespace impactdeck::geometry {
namespace fs = std::filesystem;

namespace {

bool is_identity(const aiMatrix4x4& m) { return m.IsIdentity(); }

// An OFF header declaring more vertices and faces than the file can hold (each needs at least two
// bytes: a digit and a separator) is refused before assimp reserves memory for them: assimp's
// `models/invalid/OutOfMemory.off` (353535235358 vertices in 309 bytes) otherwise runs for minutes.
std::string count_text(long double n) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(0) << n;
  return o.str();
}

void check_off_header(const fs::path& file, const std::string& where, std::uintmax_t bytes) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  int line_no = 0, seen = 0;
  while (seen < 2 && std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream ls(line);
    std::string first;
    if (!(ls >> first)) continue;
    if (seen == 0) {
      ++seen;
      if (first.size() >= 3 && first.compare(first.size() - 3, 3, "OFF") == 0) {
        if (!(ls >> first)) continue;  // counts on the next line
      }
    }
    ++seen;
    long double nv = 0, nf = 0;
    std::string rest;
    std::getline(ls, rest);
    std::istringstream cs(first + " " + rest);
    if (!(cs >> nv >> nf)) return;  // malformed counts: assimp reports them
    if (nv < 0 || nf < 0 || 2.0L * (nv + nf) > static_cast<long double>(bytes)) {
      throw InputError(where, "line " + std::to_string(line_no),
                       "the OFF header declares " + count_text(nv) + " vertices and " +
                           count_text(nf) + " faces, more than a file of " +
                           std::to_string(bytes) + " bytes can hold");
    }
    return;
  }
}

// A PLY header is checked before assimp reads the body: assimp 5.2.5 reads past its buffer (a
// SEGV, found by fuzz_mesh) on a binary PLY whose property has an unknown type ("fl}oat"), and
// trusts element counts as the OFF reader does. Refused here: a first line other than "ply", an
// unknown format, a property type PLY does not define, a header with no end_header, and
// counts whose minimal size (binary: the scalar properties plus the count of each list; ASCII:
// two characters per value) exceeds what follows the header.
std::size_t ply_type_size(const std::string& t) {
  static const std::pair<const char*, std::size_t> kTypes[] = {
      {"char", 1},  {"uchar", 1},  {"int8", 1},   {"uint8", 1},  {"short", 2},   {"ushort", 2},
      {"int16", 2}, {"uint16", 2}, {"int", 4},    {"uint", 4},   {"int32", 4},   {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  for (const auto& [name, size] : kTypes)
    if (t == name) return size;
  return 0;
}

void check_ply_header(const fs::path& file, const std::string& where, std::uintmax_t bytes) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  int line_no = 0;
  bool binary = false;
  long double minimal = 0, element_count = 0, element_size = 0;
  auto fail = [&](const std::string& reason) { throw InputError(where, "line " + std::to_string(line_no), reason); };
  auto close_element = [&] { minimal += element_count * element_size; };
  std::uintmax_t header_bytes = 0;
  while (std::getline(in, line)) {
    ++line_no;
    header_bytes += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (line_no == 1) {
      if (word != "ply") fail("not a PLY file (the first line must be 'ply')");
      continue;
    }
    if (word.empty() || word == "comment" || word == "obj_info") continue;
    if (word == "format") {
      std::string kind;
      ls >> kind;
      if (kind == "ascii") binary = false;
      else if (kind == "binary_little_endian" || kind == "binary_big_endian") binary = true;
      else fail("unknown PLY format '" + kind + "'");
    } else if (word == "element") {
      close_element();
      std::string name;
      element_count = -1;
      if (!(ls >> name >> element_count) || element_count < 0) fail("an element needs a name and a count >= 0");
      element_size = 0;
    } else if (word == "property") {
      std::string type;
      ls >> type;
      if (type == "list") {
        std::string count_type, item_type;
        ls >> count_type >> item_type;
        const std::size_t c = ply_type_size(count_type);
        if (c == 0 || count_type.find("float") != std::string::npos || count_type == "double" ||
            ply_type_size(item_type) == 0) {
          fail("property list '" + count_type + " " + item_type + "': not PLY types (an integer count, then any type)");
        }
        element_size += binary ? static_cast<long double>(c) : 2.0L;
      } else {
        const std::size_t z = ply_type_size(type);
        if (z == 0) fail("property type '" + type + "' is not a PLY type");
        element_size += binary ? static_cast<long double>(z) : 2.0L;
      }
    } else if (word == "end_header") {
      close_element();
      const long double body = static_cast<long double>(bytes) - static_cast<long double>(header_bytes);
      if (minimal > body) {
        fail("the PLY header declares elements needing at least " + count_text(minimal) + " bytes, but " +
             count_text(std::max<long double>(body, 0)) + " follow the header");
      }
      return;
    }  // any other line is free text, as assimp (and Blender's exporter) take it
    if (line_no > 10000) break;
  }
  fail("no end_header: the PLY header is incomplete");
}

}  // namespace

LoadedMesh load_mesh(const fs::path& file, LengthUnit unit) {
  const std::string where = file.string();
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(where, "file", "does not exist");
  if (fs::is_directory(file, ec)) throw InputError(where, "file", "is a directory, not a part file");
  {
    std::ifstream probe(file, std::ios::binary);
    if (!probe) throw InputError(where, "file", "cannot be opened (unreadable)");
  }
  if (fs::file_size(file, ec) == 0) throw InputError(where, "file", "is empty (0 bytes): no triangles");
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".stl" && ext != ".obj" && ext != ".ply" && ext != ".off") {
    throw InputError(where, "file", "unsupported format '" + ext + "' (expected .stl, .obj, .ply or .off)");
  }

  if (ext == ".stl")
    if (auto binary = detail::read_binary_stl(file, where, unit, fs::file_size(file, ec))) return std::move(*binary);
  if (ext == ".off") check_off_header(file, where, fs::file_size(file, ec));
  if (ext == ".ply") check_ply_header(file, where, fs::file_size(file, ec));

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
  if (out.lines_ignored + out.points_ignored > 0) {
    out.warnings.push_back(where + ": ignored " + std::to_string(out.lines_ignored) + " line(s) and " +
                           std::to_string(out.points_ignored) +
                           " point(s): only triangles and polygons describe a surface");
  }
  if (out.mesh.triangles.empty()) {
    std::string detail;
    if (out.lines_ignored + out.points_ignored > 0) {
      detail = " (only " + std::to_string(out.points_ignored) + " point(s) and " +
               std::to_string(out.lines_ignored) + " line(s))";
    }
    throw InputError(where, "faces", "the file contains no triangles" + detail);
  }
  return out;
}

namespace {
void put_f32(std::ostream& o, float x) {
  char b[4];
  std::memcpy(b, &x, 4);
  o.write(b, 4);
}
}  // namespace

void write_stl_binary(const fs::path& file, const TriangleMesh& mesh, LengthUnit unit,
                      const std::string& header) {
  const double s = 1.0 / metres_per(unit);
  write_file_atomically(file, [&](std::ostream& o) {
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
  });
}

void write_stl_ascii(const fs::path& file, const TriangleMesh& mesh, LengthUnit unit,
                     const std::string& name) {
  const double s = 1.0 / metres_per(unit);
  write_file_atomically(file, [&](std::ostream& o) {
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
  });
}

}  // namespace impactdeck::geometry
