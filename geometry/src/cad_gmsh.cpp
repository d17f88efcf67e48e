// CAD parts through Gmsh's OpenCASCADE kernel (cad_plugin.hpp). gmsh.h is used only in this file,
// which is built into the plugin libimpactdeck_gmsh_cad.so. The caller holds gmsh_mutex().
//
// Gmsh keeps one model per loaded part (named impactdeck_cad_N). Another Gmsh user in the process
// (the FEM mesher plugin) initializes and finalizes Gmsh for each mesh, which drops every model:
// each query first checks that its model is still there and reads the file again if not (the
// same file read the same way gives the same entity tags).
#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include "cad_occ.hpp"
#include "cad_plugin.hpp"
#include "impactdeck/common/child_process.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/guarded_step.hpp"
#include "impactdeck/common/version.hpp"
#include "gmsh_home_files.hpp"

namespace impactdeck::geometry {
namespace fs = std::filesystem;
using detail::CadLoaded;

namespace {

struct ModelState {
  fs::path file;
  double unit_m = 1;  // metres per model coordinate
  std::string name;
};

std::map<int, ModelState>& models() {
  static std::map<int, ModelState> m;
  return m;
}

std::string raw_last_gmsh_error() {
  std::string e;
  try {
    gmsh::logger::getLastError(e);
  } catch (...) {
  }
  return e;
}

// The error Gmsh logged for ensure_initialized's own probe of a finalized Gmsh ("Gmsh has not been
// initialized"): Gmsh 4.8 keeps it as its last error after initialize, so a later step's failure
// without a message of its own would be reported with it.
std::string& probe_error() {
  static std::string e;
  return e;
}

// Gmsh's last logged error, unless it is the probe's.
std::string last_gmsh_error() {
  const std::string e = raw_last_gmsh_error();
  return e == probe_error() ? std::string() : e;
}

// Runs a Gmsh step; whatever Gmsh throws becomes an InputError naming the file and step.
template <class F>
void gmsh_step(const fs::path& file, const std::string& step, F&& f) {
  run_as_input_error(file.string(), step, std::forward<F>(f), &last_gmsh_error);
}

void ensure_initialized() {
  bool alive = true;
  try {
    std::vector<std::string> names;
    gmsh::model::list(names);
    alive = !names.empty();
  } catch (...) {
    alive = false;
  }
  if (!alive) {
    initialize_gmsh_without_home_files();  // no FLTK preferences, no ~/.gmsh-tmp (gmsh_home_files.hpp)
    probe_error() = raw_last_gmsh_error();
  }
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.NumThreads", 1);
}

// OpenCASCADE's BREP reader writes its complaints ("Not a surface table") to std::cout, which is
// the tool's own output (`--json`): while a file is imported they go to a string instead, which
// the caller reports with the read's warnings or error.
class CoutCapture {
 public:
  CoutCapture() : saved_(std::cout.rdbuf(text_.rdbuf())) {}
  ~CoutCapture() { std::cout.rdbuf(saved_); }
  CoutCapture(const CoutCapture&) = delete;
  CoutCapture& operator=(const CoutCapture&) = delete;
  /// The captured lines joined by "; " ("" when none).
  std::string lines() const {
    std::istringstream in(text_.str());
    std::string line, all;
    while (std::getline(in, line)) {
      // Colour escapes (ESC [ ... m) dropped; the IGES reader's entity count is not a complaint.
      std::string plain;
      for (std::size_t i = 0; i < line.size(); ++i) {
        if (line[i] == '\x1b' && i + 1 < line.size() && line[i + 1] == '[') {
          while (i < line.size() && line[i] != 'm') ++i;
          continue;
        }
        plain += line[i];
      }
      if (plain.empty() || plain.rfind("Total number of loaded entities", 0) == 0) continue;
      all += (all.empty() ? "" : "; ") + plain;
    }
    return all;
  }

 private:
  std::ostringstream text_;
  std::streambuf* saved_;
};

// Reads the file into a new model; returns what OpenCASCADE wrote to std::cout meanwhile.
std::string import_into(const ModelState& st) {
  detail::occ_init_translators();  // else Gmsh cannot set the IGES target unit (cad_occ.hpp)
  gmsh::model::add(st.name);
  gmsh::option::setString("Geometry.OCCTargetUnit", "MM");
  gmsh::logger::start();
  gmsh::vectorpair out;
  CoutCapture occt;
  try {
    gmsh::model::occ::importShapes(st.file.string(), out, true);
    gmsh::model::occ::synchronize();
  } catch (const std::exception&) {
    throw;
  } catch (const std::string&) {
    throw;
  } catch (...) {
    // OpenCASCADE's own exceptions (Standard_Failure) pass through Gmsh 4.8 unconverted, without a
    // message we can read: say what failed instead of "unknown error".
    throw InputError(st.file.string(), "read",
                     "OpenCASCADE stopped with an error of its own while building the shapes (for example a "
                     "solid without faces, whose bounding box is empty): the file is damaged or holds a shape "
                     "OpenCASCADE cannot rebuild");
  }
  return occt.lines();
}

// Makes the part's model current, reading the file again when Gmsh lost it.
void activate(int model) {
  const ModelState& st = models().at(model);
  ensure_initialized();
  std::vector<std::string> names;
  gmsh::model::list(names);
  if (std::find(names.begin(), names.end(), st.name) == names.end()) {
    import_into(st);
  }
  gmsh::model::setCurrent(st.name);
}

Eigen::Vector3d v3(const std::vector<double>& x, std::size_t i = 0) { return {x[i], x[i + 1], x[i + 2]}; }

double model_size(double& x0, double& y0, double& z0) {
  double x1, y1, z1;
  gmsh::model::getBoundingBox(-1, -1, x0, y0, z0, x1, y1, z1);
  return std::max({x1 - x0, y1 - y0, z1 - z0});
}

// Closest point of face `face` to q (model units): projection, then its parameters; false when
// the projection fails or leaves the face's parameter box.
bool project(int face, const Eigen::Vector3d& q, Eigen::Vector3d& p, double& u, double& v, double tol) {
  try {
    std::vector<double> cp, uv, uv2, back;
    gmsh::model::getClosestPoint(2, face, {q.x(), q.y(), q.z()}, cp, uv);
    if (cp.size() != 3) return false;
    gmsh::model::getParametrization(2, face, cp, uv2);
    if (uv2.size() != 2) return false;
    gmsh::model::getValue(2, face, uv2, back);
    p = v3(cp);
    if (!p.allFinite() || !((v3(back) - p).norm() <= tol)) return false;
    u = uv2[0];
    v = uv2[1];
    return true;
  } catch (...) {
    return false;
  }
}

Eigen::Vector3d normal_at(int face, double u, double v) {
  std::vector<double> n;
  gmsh::model::getNormal(face, {u, v}, n);
  return v3(n).normalized();
}

// OpenCASCADE's adaptive integration of the mass properties stops when the volume changes by less
// than this from one refinement to the next (cad_occ.hpp). The moments converge more slowly than
// the volume: asked for 1e-9, a cylinder's inertia stayed 5.6e-8 off; at 1e-12 it is within 3e-10
// (rounding). The fixed Gauss rule of Gmsh's occ::getMass is not exact on B-spline faces (9.9e-6
// off on CAP_50SGV_8_10.stp; issue 29 saw 2.2e-4 on another part).
constexpr double kMassRelativeAccuracy = 1e-12;
// OpenCASCADE's triangulation (the fallback): chordal deflection as a fraction of the part's size,
// angular deflection; a face is matched to Gmsh's within the deflection plus 1e-6 of the size.
constexpr double kOccDeflectionRelative = 1e-3;
constexpr double kOccAngleRad = 0.3;
double pad_limit(double size) { return kOccDeflectionRelative * size + 1e-6 * size; }

// The surface mesh the child process passes back: nodes, and each face's triangles as node tags.
struct TriangulationResult {
  std::vector<std::size_t> node_tags;
  std::vector<double> xyz;
  std::map<int, std::vector<std::size_t>> face_nodes;
  double deviation_bound = 0;  ///< from the B-rep, model units (0: unknown, Gmsh's)
};

// In the child process: Gmsh's 2D mesh of the current model (edges up to size_max, refined by
// curvature), serialised. Options need no restoring: the parent's Gmsh never sees them.
std::string mesh_faces(double size_max, int algorithm) {
  const std::vector<std::pair<std::string, double>> opts = {
      {"Mesh.MeshSizeMax", size_max},         {"Mesh.MeshSizeMin", 0.0},
      {"Mesh.MeshSizeFromCurvature", 12},     {"Mesh.MeshSizeFromPoints", 0},
      {"Mesh.MeshSizeExtendFromBoundary", 1}, {"Mesh.Algorithm", static_cast<double>(algorithm)}};
  for (const auto& [k, v] : opts) gmsh::option::setNumber(k, v);
  gmsh::model::mesh::generate(2);
  std::vector<std::size_t> tags;
  std::vector<double> xyz, par;
  gmsh::model::mesh::getNodes(tags, xyz, par, -1, -1, true, false);
  ByteWriter w;
  w.put<std::uint64_t>(tags.size());
  for (std::size_t i = 0; i < tags.size(); ++i) {
    w.put<std::uint64_t>(tags[i]);
    for (int k = 0; k < 3; ++k) w.put<double>(xyz[3 * i + k]);
  }
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  w.put<std::uint64_t>(faces.size());
  for (const auto& [d, f] : faces) {
    std::vector<std::size_t> etags, enodes;
    gmsh::model::mesh::getElementsByType(2, etags, enodes, f);
    w.put<std::int64_t>(f);
    w.put<std::uint64_t>(enodes.size());
    for (std::size_t n : enodes) w.put<std::uint64_t>(n);
  }
  return w.take();
}

TriangulationResult parse_triangulation(const std::string& bytes, const InputContext& where) {
  ByteReader r(bytes, where, "triangulation");
  TriangulationResult t;
  const std::size_t n = r.count(4 * 8);
  for (std::size_t i = 0; i < n; ++i) {
    t.node_tags.push_back(r.get<std::uint64_t>());
    for (int k = 0; k < 3; ++k) t.xyz.push_back(r.get<double>());
  }
  const std::size_t faces = r.count(2 * 8);
  for (std::size_t i = 0; i < faces; ++i) {
    const auto f = static_cast<int>(r.get<std::int64_t>());
    auto& nodes = t.face_nodes[f];
    const std::size_t m = r.count(8);
    for (std::size_t k = 0; k < m; ++k) nodes.push_back(r.get<std::uint64_t>());
  }
  return t;
}

// OpenCASCADE's triangulation (cad_occ.hpp) with each of its faces matched to the Gmsh face
// that holds the centroid of its largest triangle (nearest, by projection).
TriangulationResult occ_fallback(const fs::path& file, CadFormat format, double size) {
  const detail::OccTriangulation o = [&] {
    CoutCapture quiet;
    return detail::occ_triangulate(file, format, kOccDeflectionRelative * size, kOccAngleRad);
  }();
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  std::vector<std::array<double, 6>> boxes;
  for (const auto& [d, f] : faces) {
    std::array<double, 6> b{};
    gmsh::model::getBoundingBox(2, f, b[0], b[1], b[2], b[3], b[4], b[5]);
    boxes.push_back(b);
  }
  const double pad = pad_limit(size);
  std::vector<int> tag_of(o.face_probe.size(), -1);
  std::vector<bool> has_triangles(o.face_probe.size(), false);
  for (int f : o.triangle_face) has_triangles[static_cast<std::size_t>(f)] = true;
  for (std::size_t i = 0; i < o.face_probe.size(); ++i) {
    if (!has_triangles[i]) continue;  // every triangle collapsed (a degenerate face)
    const Eigen::Vector3d& q = o.face_probe[i];
    // The nearest face holding the probe (isInside); else the nearest projection at all (a probe
    // close to a trimming curve).
    double best = std::numeric_limits<double>::infinity(), best_any = best;
    int any = -1;
    for (std::size_t k = 0; k < faces.size(); ++k) {
      const auto& b = boxes[k];
      if (q.x() < b[0] - pad || q.y() < b[1] - pad || q.z() < b[2] - pad || q.x() > b[3] + pad ||
          q.y() > b[4] + pad || q.z() > b[5] + pad) {
        continue;
      }
      Eigen::Vector3d p;
      double u = 0, v = 0;
      if (!project(faces[k].second, q, p, u, v, 1e-7 * size)) continue;
      const double dist = (p - q).norm();
      if (dist < best_any) best_any = dist, any = faces[k].second;
      if (dist < best && gmsh::model::isInside(2, faces[k].second, {u, v})) best = dist, tag_of[i] = faces[k].second;
    }
    if (tag_of[i] < 0 && best_any <= pad) tag_of[i] = any;
    if (tag_of[i] < 0) {
      throw InputError(file.string(), "triangulation",
                       "OpenCASCADE's face " + std::to_string(i + 1) + " matches no face of Gmsh's model");
    }
  }
  TriangulationResult t;
  // BRepMesh keeps its facets within the chordal deflection of the faces (twice that, for its
  // approximate enforcement): the search's candidate margin.
  t.deviation_bound = 2 * kOccDeflectionRelative * size;
  for (std::size_t n = 0; n < o.nodes.size(); ++n) {
    t.node_tags.push_back(n + 1);
    for (int k = 0; k < 3; ++k) t.xyz.push_back(o.nodes[n][k]);
  }
  for (std::size_t e = 0; e < o.triangles.size(); ++e) {
    auto& nodes = t.face_nodes[tag_of[static_cast<std::size_t>(o.triangle_face[e])]];
    for (int k = 0; k < 3; ++k) nodes.push_back(static_cast<std::size_t>(o.triangles[e][k]) + 1);
  }
  return t;
}

// The search triangulation: Gmsh's 2D mesh (algorithm 6, Frontal-Delaunay) in a child process
// (run_in_child), stopped after deadline_s: Gmsh 4.8 throws from inside its OpenMP face meshing
// ("Impossible to mesh periodic surface", "Unable to recover the edge"), where no catch reaches,
// crashes, or runs for minutes (a thin torus). When it fails, OpenCASCADE's own triangulation
// (occ_fallback), with a warning saying why. (Gmsh's other 2D algorithms are no better on such
// parts: on netgen's frame.step 1 crashes and 5 hangs.)
TriangulationResult triangulate(const fs::path& file, CadFormat format, double size, double size_max,
                                double deadline_s, std::vector<std::string>& warnings) {
  const InputContext where{file.string(), ""};
  std::string failures;
  try {
    const std::string bytes = run_in_child(where, "triangulation", "Gmsh's surface mesher", deadline_s,
                                           [&] { return mesh_faces(size_max, 6); }, &last_gmsh_error);
    return parse_triangulation(bytes, where);
  } catch (const InputError& e) {
    failures = e.reason() + "; ";
  }
  try {
    TriangulationResult t = occ_fallback(file, format, size);
    warnings.push_back(file.string() + ": triangulation: " + failures +
                       "OpenCASCADE's triangulation (BRepMesh) used instead, as the search guide only");
    return t;
  } catch (const InputError& e) {
    throw where.error("triangulation", failures + "OpenCASCADE's triangulation: " + e.reason());
  }
}

void release(int model);
CadLoaded load_model(const fs::path& file, CadFormat format, double unit_m, double mesh_size_relative,
                     double deadline_s, int model);

// Reads a part into a new model; a failure drops the model again.
CadLoaded load(const fs::path& file, CadFormat format, double unit_m, double mesh_size_relative, double deadline_s) {
  static int next = 0;
  const int model = ++next;
  try {
    return load_model(file, format, unit_m, mesh_size_relative, deadline_s, model);
  } catch (...) {
    release(model);
    throw;
  }
}

CadLoaded load_model(const fs::path& file, CadFormat format, double unit_m, double mesh_size_relative,
                     double deadline_s, int model) {
  ModelState st{file, unit_m, "impactdeck_cad_" + std::to_string(model)};
  CadLoaded out;
  out.model = model;
  const std::string where = file.string();
  models()[out.model] = st;
  std::string occt_said;  // OpenCASCADE's own complaints while reading (usually none)
  gmsh_step(file, "read", [&] {
    ensure_initialized();
    occt_said = import_into(st);
  });
  const std::string occt_note = occt_said.empty() ? "" : " (OpenCASCADE while reading: " + occt_said + ")";
  gmsh::vectorpair vols, faces, edges;
  double x0 = 0, y0 = 0, z0 = 0, size = 0;
  gmsh_step(file, "mass properties", [&] {
    gmsh::model::getEntities(vols, 3);
    gmsh::model::getEntities(faces, 2);
    gmsh::model::getEntities(edges, 1);
    out.solids = static_cast<int>(vols.size());
    if (vols.empty()) {
      throw InputError(where, "solids", "the file holds no solid (" + std::to_string(faces.size()) +
                       " faces, none closing a volume): mass properties need a closed solid" + occt_note);
    }
    size = model_size(x0, y0, z0);
  });
  // Mass properties: OpenCASCADE's adaptive integration (cad_occ.hpp) of the file read by its own
  // reader, to kMassRelativeAccuracy; its error estimate is reported.
  {
    CoutCapture quiet;  // the readers' own chatter
    const detail::OccMass m = detail::occ_mass_properties(file, format, kMassRelativeAccuracy);
    if (m.solids != out.solids) {
      throw InputError(where, "mass properties", "Gmsh finds " + std::to_string(out.solids) + " solids, OpenCASCADE " +
                       std::to_string(m.solids));
    }
    const double L = unit_m;
    out.volume.volume_m3 = m.volume * L * L * L;
    out.volume.centroid_m = m.centre * L;
    out.volume.inertia_per_density_m5 = m.inertia * std::pow(L, 5);
    out.volume.area_m2 = m.area * L * L;
    out.mass_relative_error_estimate = m.relative_error;
  }
  if (!occt_said.empty()) out.warnings.push_back(where + ": OpenCASCADE while reading: " + occt_said);
  if (out.solids > 1) {
    out.warnings.push_back(where + ": " + std::to_string(out.solids) +
                           " solids taken as one body (mass properties summed; overlaps would count twice)");
  }

  // Triangulation: Gmsh's 2D mesh of the faces, in a child process (triangulate_in_child).
  const TriangulationResult tri = triangulate(file, format, size, mesh_size_relative * size, deadline_s, out.warnings);
  out.triangulation_deviation_m = tri.deviation_bound * unit_m;
  gmsh_step(file, "triangulation", [&] {
    std::map<std::size_t, int> index;
    for (std::size_t i = 0; i < tri.node_tags.size(); ++i) {
      index[tri.node_tags[i]] = static_cast<int>(out.nodes_m.size());
      out.nodes_m.push_back(v3(tri.xyz, 3 * i) * unit_m);
    }
    const double tol = 1e-7 * size;
    for (const auto& [d, f] : faces) {
      out.faces.push_back(f);
      std::vector<double> lo, hi;
      gmsh::model::getParametrizationBounds(2, f, lo, hi);
      out.face_bounds.push_back({lo[0], hi[0], lo[1], hi[1]});
      const auto found = tri.face_nodes.find(f);
      static const std::vector<std::size_t> none;
      const std::vector<std::size_t>& enodes = found == tri.face_nodes.end() ? none : found->second;
      const std::size_t first = out.triangles.size();
      double best_area = -1;
      std::size_t best = first;
      for (std::size_t e = 0; e + 2 < enodes.size(); e += 3) {
        const auto node = [&](std::size_t k) {
          const auto it = index.find(enodes[e + k]);
          if (it == index.end()) throw InputError(where, "triangulation", "a triangle names an unknown node");
          return it->second;
        };
        std::array<int, 3> t{node(0), node(1), node(2)};
        out.triangles.push_back(t);
        out.triangle_face.push_back(f);
        const double a = (out.nodes_m[t[1]] - out.nodes_m[t[0]]).cross(out.nodes_m[t[2]] - out.nodes_m[t[0]]).norm();
        if (a > best_area) best_area = a, best = out.triangles.size() - 1;
      }
      if (out.triangles.size() == first) continue;
      // Orientation of the face's triangles against the face's outward normal at the largest one.
      const auto& t = out.triangles[best];
      const Eigen::Vector3d c = (out.nodes_m[t[0]] + out.nodes_m[t[1]] + out.nodes_m[t[2]]) / (3.0 * unit_m);
      Eigen::Vector3d p;
      double u = 0, v = 0;
      if (!project(f, c, p, u, v, tol)) {
        throw InputError(where, "face " + std::to_string(f), "cannot orient its triangulation (projection failed)");
      }
      const Eigen::Vector3d tn =
          (out.nodes_m[t[1]] - out.nodes_m[t[0]]).cross(out.nodes_m[t[2]] - out.nodes_m[t[0]]);
      if (tn.dot(normal_at(f, u, v)) < 0) {
        for (std::size_t k = first; k < out.triangles.size(); ++k) std::swap(out.triangles[k][1], out.triangles[k][2]);
      }
    }
  });
  if (out.triangles.empty()) throw InputError(where, "triangulation", "Gmsh produced no surface triangles");

  // B-rep edges: adjacent faces and the largest angle between their normals along the edge.
  gmsh_step(file, "edges", [&] {
    for (const auto& [d, e] : edges) {
      CadLoaded::Edge ed;
      ed.tag = e;
      std::vector<int> up, down;
      gmsh::model::getAdjacencies(1, e, up, down);
      ed.faces = up;
      std::vector<double> lo, hi;
      gmsh::model::getParametrizationBounds(1, e, lo, hi);
      constexpr int kSamples = 16;
      for (int i = 0; i <= kSamples; ++i) {
        const double t = lo[0] + (hi[0] - lo[0]) * i / kSamples;
        std::vector<double> x;
        gmsh::model::getValue(1, e, {t}, x);
        ed.polyline_m.push_back(v3(x) * unit_m);
        if (up.size() == 2 && up[0] != up[1]) {
          std::vector<double> uv0, uv1;
          try {
            gmsh::model::reparametrizeOnSurface(1, e, {t}, up[0], uv0, 0);
            gmsh::model::reparametrizeOnSurface(1, e, {t}, up[1], uv1, 0);
            const double c = std::clamp(normal_at(up[0], uv0[0], uv0[1]).dot(normal_at(up[1], uv1[0], uv1[1])), -1.0, 1.0);
            ed.dihedral_deg = std::max(ed.dihedral_deg, std::acos(c) * 180.0 / 3.14159265358979323846);
          } catch (...) {
            ed.dihedral_deg = 180;  // cannot tell: count it as sharp
          }
        }
      }
      if (up.size() > 2) ed.dihedral_deg = 180;  // non-manifold edge
      out.edges.push_back(std::move(ed));
    }
  });
  return out;
}

bool project_on_face(int model, int face, const Eigen::Vector3d& q_m, detail::CadFacePoint& out) {
  try {
    activate(model);
    const double L = models().at(model).unit_m;
    double x0, y0, z0;
    const double size = model_size(x0, y0, z0);
    Eigen::Vector3d p;
    double u = 0, v = 0;
    if (!project(face, q_m / L, p, u, v, 1e-7 * size)) return false;
    out.point_m = p * L;
    out.u = u;
    out.v = v;
    out.normal = normal_at(face, u, v);
    out.inside = gmsh::model::isInside(2, face, {u, v}) != 0;
    return out.normal.allFinite();
  } catch (...) {
    return false;
  }
}

bool face_frame(int model, int face, double u, double v, detail::CadFaceFrame& out) {
  try {
    activate(model);
    const double L = models().at(model).unit_m;
    std::vector<double> x, d1, d2, k1, k2, dir1, dir2;
    gmsh::model::getValue(2, face, {u, v}, x);
    gmsh::model::getDerivative(2, face, {u, v}, d1);
    gmsh::model::getSecondDerivative(2, face, {u, v}, d2);
    gmsh::model::getPrincipalCurvatures(face, {u, v}, k1, k2, dir1, dir2);
    if (x.size() != 3 || d1.size() != 6 || d2.size() != 9 || k1.empty() || k2.empty()) return false;
    out.point_m = v3(x) * L;
    out.normal = normal_at(face, u, v);
    out.xu = v3(d1, 0) * L;
    out.xv = v3(d1, 3) * L;
    out.xuu = v3(d2, 0) * L;
    out.xvv = v3(d2, 3) * L;
    out.xuv = v3(d2, 6) * L;
    out.k1_gmsh = k1[0] / L;
    out.k2_gmsh = k2[0] / L;
    return true;
  } catch (...) {
    return false;
  }
}

bool project_on_edge(int model, int edge, const Eigen::Vector3d& q_m, detail::CadEdgePoint& out) {
  try {
    activate(model);
    const double L = models().at(model).unit_m;
    const Eigen::Vector3d q = q_m / L;
    std::vector<double> lo, hi, cp, t, a, b;
    gmsh::model::getParametrizationBounds(1, edge, lo, hi);
    gmsh::model::getValue(1, edge, {lo[0]}, a);
    gmsh::model::getValue(1, edge, {hi[0]}, b);
    // The nearer end, unless the projection falls inside the edge's range and is nearer still.
    Eigen::Vector3d best = (v3(a) - q).norm() <= (v3(b) - q).norm() ? v3(a) : v3(b);
    double best_t = (v3(a) - q).norm() <= (v3(b) - q).norm() ? lo[0] : hi[0];
    try {
      gmsh::model::getClosestPoint(1, edge, {q.x(), q.y(), q.z()}, cp, t);
      gmsh::model::getParametrization(1, edge, cp, t);
      if (cp.size() == 3 && t.size() == 1 && t[0] >= lo[0] && t[0] <= hi[0] && (v3(cp) - q).norm() < (best - q).norm()) {
        best = v3(cp);
        best_t = t[0];
      }
    } catch (...) {
    }
    out.point_m = best * L;
    out.t = best_t;
    return out.point_m.allFinite();
  } catch (...) {
    return false;
  }
}

void release(int model) {
  auto it = models().find(model);
  if (it == models().end()) return;
  try {
    std::vector<std::string> names;
    gmsh::model::list(names);
    if (std::find(names.begin(), names.end(), it->second.name) != names.end()) {
      gmsh::model::setCurrent(it->second.name);
      gmsh::model::remove();
    }
  } catch (...) {
  }
  models().erase(it);
}

}  // namespace
}  // namespace impactdeck::geometry

// The plugin's entry point (cad_plugin.hpp); everything else in this library is hidden.
extern "C" __attribute__((visibility("default"))) const void* impactdeck_gmsh_cad_v1() {
  using namespace impactdeck::geometry;
  static const detail::GmshCadV1 table{impactdeck::kVersion, sizeof(detail::CadLoaded), sizeof(detail::CadFaceFrame),
                                       &load, &project_on_face, &face_frame, &project_on_edge, &release};
  return &table;
}
