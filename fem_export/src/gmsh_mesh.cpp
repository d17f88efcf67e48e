// Gmsh meshing of the target body (see mesh.hpp). gmsh.h is used only in this file, which is
// built into the plugin libimpactdeck_gmsh_mesher.so (gmsh_plugin.hpp, gmsh_loader.cpp).
#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/guarded_step.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/fem_export/mesh.hpp"
#include "gmsh_plugin.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;

namespace {

constexpr double kMmPerM = 1000.0;
constexpr double kPi = 3.14159265358979323846;

// Gmsh is a process-wide singleton: one session at a time, finalized on every way out.
std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

class GmshSession {
 public:
  explicit GmshSession(const std::string& model) : lock_(gmsh_mutex()) {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.NumThreads", 1);  // deterministic meshes
    gmsh::logger::start();
    gmsh::model::add(model);
  }
  ~GmshSession() {
    try {
      gmsh::logger::stop();
      gmsh::finalize();
    } catch (...) {
    }
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

  /// Last error logged by Gmsh (empty if none).
  static std::string last_error() {
    std::string e;
    try {
      gmsh::logger::getLastError(e);
    } catch (...) {
    }
    return e;
  }

 private:
  std::lock_guard<std::mutex> lock_;
};

// Runs a Gmsh step; whatever Gmsh throws becomes an InputError naming the step and Gmsh's message.
template <class F>
void gmsh_step(const std::string& where, const std::string& step, F&& f) {
  run_as_input_error(where, "gmsh " + step, std::forward<F>(f), &GmshSession::last_error);
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// The mesh-size field: size h0 at the load point growing linearly to h at distance 4 h.
std::string size_formula(const Eigen::Vector3d& p_mm, double h0_mm, double h_mm) {
  std::ostringstream f;
  f.precision(17);
  f << h0_mm << " + (" << h_mm - h0_mm << ") * Min(1, Sqrt((x - (" << p_mm.x() << "))^2 + (y - ("
    << p_mm.y() << "))^2 + (z - (" << p_mm.z() << "))^2) / " << 4.0 * h_mm << ")";
  return f.str();
}

void set_common_options(double h_mm, int algorithm_3d) {
  gmsh::option::setNumber("Mesh.CharacteristicLengthMax", h_mm);
  gmsh::option::setNumber("Mesh.CharacteristicLengthFromPoints", 0);
  gmsh::option::setNumber("Mesh.CharacteristicLengthFromCurvature", 0);
  gmsh::option::setNumber("Mesh.CharacteristicLengthExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.Algorithm", 1);     // MeshAdapt: the dilated OCC sphere (DECKS.md)
  gmsh::option::setNumber("Mesh.Algorithm3D", algorithm_3d);
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  gmsh::option::setNumber("Mesh.Optimize", 1);
}

std::string geo_options(double h_mm, int algorithm_3d) {
  std::ostringstream g;
  g << "Mesh.CharacteristicLengthMax = " << fmt(h_mm) << ";\n"
    << "Mesh.CharacteristicLengthFromPoints = 0;\n"
    << "Mesh.CharacteristicLengthFromCurvature = 0;\n"
    << "Mesh.CharacteristicLengthExtendFromBoundary = 0;\n"
    << "Mesh.Algorithm = 1;    // MeshAdapt\n"
    << "Mesh.Algorithm3D = " << algorithm_3d << "; // 1 Delaunay, 10 HXT\n"
    << "Mesh.ElementOrder = 1;\n"
    << "Mesh.Optimize = 1;\n"
    << "General.NumThreads = 1;\n";
  return g.str();
}

int add_size_field(const Eigen::Vector3d& p_mm, double h0_mm, double h_mm) {
  const int f = gmsh::model::mesh::field::add("MathEval");
  gmsh::model::mesh::field::setString(f, "F", size_formula(p_mm, h0_mm, h_mm));
  gmsh::model::mesh::field::setAsBackgroundMesh(f);
  return f;
}

std::string probe_name(std::size_t i) { return "PROBE" + std::to_string(i + 1); }

// Size field around the load point, then the 3D mesh (both routes).
void generate_tets(const std::string& where, const MeshOptions& o, const Eigen::Vector3d& p_mm, double h0,
                   double h) {
  gmsh_step(where, "mesh", [&] {
    set_common_options(h, o.algorithm_3d);
    add_size_field(p_mm, h0, h);
    gmsh::model::mesh::generate(3);
  });
}

// Physical groups PROBEk of the embedded probe points (both routes).
void add_probe_groups(const std::vector<int>& probe_tags) {
  for (std::size_t i = 0; i < probe_tags.size(); ++i) {
    gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {probe_tags[i]}), probe_name(i));
  }
}

// Probe points embedded in volume 1 (numbered from 1000) and their physical groups PROBEk: the
// same in both .geo routes.
std::string geo_probe_points(const MeshOptions& o) {
  std::ostringstream g;
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    const Eigen::Vector3d pm = o.probes_m[i] * kMmPerM;
    g << "Point(" << 1000 + i << ") = {" << fmt(pm.x()) << ", " << fmt(pm.y()) << ", " << fmt(pm.z())
      << "};\nPoint{" << 1000 + i << "} In Volume{1};\n";
  }
  return g.str();
}

std::string geo_probe_groups(const MeshOptions& o) {
  std::ostringstream g;
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    g << "Physical Point(\"" << probe_name(i) << "\") = {" << 1000 + i << "};\n";
  }
  return g.str();
}

std::string geo_size_field(const Eigen::Vector3d& p_mm, double h0_mm, double h_mm) {
  return "Field[1] = MathEval;\nField[1].F = \"" + size_formula(p_mm, h0_mm, h_mm) +
         "\";\nBackground Field = 1;\n";
}

void check_options(const MeshOptions& o, const std::string& where) {
  if (!(o.mesh_size_m > 0.0) || !std::isfinite(o.mesh_size_m)) {
    throw InputError(where, "mesh_size", "must be > 0");
  }
  if (o.load_mesh_size_m < 0.0 || !std::isfinite(o.load_mesh_size_m)) {
    throw InputError(where, "load_mesh_size", "must be >= 0");
  }
  if (o.algorithm_3d != 1 && o.algorithm_3d != 10) throw InputError(where, "algorithm_3d", "must be 1 or 10");
  if (o.probes_m.size() > 99) throw InputError(where, "probes", "at most 99 probes");
}

double load_size(const MeshOptions& o) {
  const double h0 = o.load_mesh_size_m > 0 ? o.load_mesh_size_m : o.mesh_size_m / 3.0;
  return std::min(h0, o.mesh_size_m);
}

/// Reads the tetrahedra of the current model into a TetMesh (only nodes used by tetrahedra),
/// oriented positively; returns the map gmsh node tag -> index.
std::map<std::size_t, int> extract(TetMesh& m, const std::string& where) {
  std::vector<std::size_t> tags;
  std::vector<double> xyz, par;
  gmsh::model::mesh::getNodes(tags, xyz, par, -1, -1, true, false);
  std::map<std::size_t, std::size_t> pos;
  for (std::size_t i = 0; i < tags.size(); ++i) pos[tags[i]] = i;

  std::vector<std::size_t> etags, enodes;
  gmsh::model::mesh::getElementsByType(4, etags, enodes);  // 4 = 4-node tetrahedron
  if (etags.empty()) {
    throw InputError(where, "gmsh mesh", "Gmsh produced no tetrahedra (mesh size too large for "
                     "the body, or an open/self-intersecting surface)");
  }
  std::map<std::size_t, int> index;
  for (std::size_t e = 0; e < etags.size(); ++e) {
    std::array<int, 4> t{};
    for (int k = 0; k < 4; ++k) {
      const std::size_t tag = enodes[4 * e + k];
      auto it = index.find(tag);
      if (it == index.end()) {
        const std::size_t i = pos.at(tag);
        m.nodes_m.emplace_back(xyz[3 * i] / kMmPerM, xyz[3 * i + 1] / kMmPerM, xyz[3 * i + 2] / kMmPerM);
        it = index.emplace(tag, static_cast<int>(m.nodes_m.size() - 1)).first;
      }
      t[k] = it->second;
    }
    m.tets.push_back(t);
    if (tet_volume_m3(m, m.tets.size() - 1) < 0) std::swap(m.tets.back()[1], m.tets.back()[2]);
  }
  return index;
}

int node_of_point_entity(int point_tag, const std::map<std::size_t, int>& index, const std::string& where,
                         const std::string& what) {
  std::vector<std::size_t> tags;
  std::vector<double> xyz, par;
  gmsh::model::mesh::getNodes(tags, xyz, par, 0, point_tag, false, false);
  if (tags.empty() || !index.count(tags[0])) {
    throw InputError(where, "gmsh mesh", what + ": no mesh node on its geometry point");
  }
  return index.at(tags[0]);
}

void fill_quality(const TetMesh& m, MeshQuality& q) {
  q.node_count = m.nodes_m.size();
  q.tet_count = m.tets.size();
  q.min_quality = 1.0;
  double sum = 0;
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    const double g = tet_quality(m, e);
    q.min_quality = std::min(q.min_quality, g);
    sum += g;
  }
  q.mean_quality = sum / static_cast<double>(m.tets.size());
  q.fe_volume_m3 = m.volume_m3();
  q.volume_relative_difference = (q.fe_volume_m3 - q.part_volume_m3) / q.part_volume_m3;
}

void check_mesh(const MeshResult& r, const std::string& where) {
  if (!(r.quality.min_quality > 1e-6)) {
    std::ostringstream s;
    s << "degenerate tetrahedron (radius ratio " << r.quality.min_quality
      << "): the solver would fail; change mesh_size";
    throw InputError(where, "gmsh mesh", s.str());
  }
}

void write_msh(const fs::path& folder, const std::string& name, MeshResult& r) {
  r.msh41 = folder / (name + ".msh");
  r.msh22 = folder / (name + "_v22.msh");
  gmsh::option::setNumber("Mesh.SaveAll", 0);  // physical groups only: BODY, LOAD, PROBEk
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::write(r.msh41.string());
  gmsh::option::setNumber("Mesh.MshFileVersion", 2.2);
  gmsh::write(r.msh22.string());
}

// After meshing a body whose load point and probes are geometry points (ellipsoid and CAD routes):
// extract the tetrahedra, name LOAD and PROBEk, check the quality, write the .msh files.
void finish_point_mesh(const std::string& where, const MeshOptions& o, const fs::path& folder,
                       const std::string& name, int load_tag, const std::vector<int>& probe_tags,
                       const Eigen::Vector3d& p_mm, MeshResult& r) {
  gmsh_step(where, "mesh", [&] {
    const std::map<std::size_t, int> index = extract(r.mesh, where);
    const int ln = node_of_point_entity(load_tag, index, where, "LOAD");
    r.mesh.node_groups.emplace_back("LOAD", ln);
    r.quality.load_node_distance_m = (r.mesh.nodes_m[ln] * kMmPerM - p_mm).norm() / kMmPerM;
    for (std::size_t i = 0; i < probe_tags.size(); ++i) {
      const int pn = node_of_point_entity(probe_tags[i], index, where, probe_name(i));
      r.mesh.node_groups.emplace_back(probe_name(i), pn);
      r.quality.probe_node_distance_m.push_back((r.mesh.nodes_m[pn] - o.probes_m[i]).norm());
    }
  });
  fill_quality(r.mesh, r.quality);
  check_mesh(r, where);
  gmsh_step(where, "write", [&] { write_msh(folder, name, r); });
}


std::string geo_header(const std::string& what) {
  return "// impactdeck " + std::string(kVersion) + ": " + what +
         "\n// Units: mm. Reproduce the mesh with: gmsh -3 -format msh41 <this file>\n";
}

}  // namespace

MeshResult mesh_ellipsoid_with_gmsh(const Eigen::Vector3d& semi_axes_m, const Eigen::Vector3d& load_point_m,
                          const MeshOptions& o, const fs::path& folder, const std::string& name) {
  const std::string where = (folder / (name + ".geo")).string();
  check_options(o, where);
  if (!((semi_axes_m.array() > 0).all())) throw InputError(where, "semi_axes", "must be > 0");
  const Eigen::Vector3d ax = semi_axes_m * kMmPerM;
  const double size_mm = ax.maxCoeff();
  // Radial projection onto the surface through the unit sphere.
  const Eigen::Vector3d q = (load_point_m * kMmPerM).cwiseQuotient(ax);
  if (!(q.norm() > 1e-9)) throw InputError(where, "load point", "must not be the centre");
  const Eigen::Vector3d qhat = q.normalized();
  const Eigen::Vector3d p_mm = ax.cwiseProduct(qhat);
  if ((p_mm - load_point_m * kMmPerM).norm() > 0.01 * size_mm) {
    throw InputError(where, "load point", "more than 1 % of the size away from the surface");
  }
  const double h = o.mesh_size_m * kMmPerM, h0 = load_size(o) * kMmPerM;
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    if (o.probes_m[i].cwiseQuotient(semi_axes_m).squaredNorm() >= 1.0) {
      throw InputError(where, probe_name(i), "probe point is not inside the ellipsoid");
    }
  }
  // Rotation taking the north pole (0, 0, 1) onto qhat.
  const Eigen::Vector3d ez(0, 0, 1);
  double angle = std::acos(std::clamp(ez.dot(qhat), -1.0, 1.0));
  Eigen::Vector3d axis = ez.cross(qhat);
  if (axis.norm() < 1e-12) axis = Eigen::Vector3d(1, 0, 0);
  axis.normalize();

  MeshResult r;
  r.quality.part_volume_m3 = 4.0 / 3.0 * kPi * semi_axes_m.prod();
  GmshSession session(name);
  int load_tag = -1, vol = -1;
  std::vector<int> probe_tags;
  gmsh_step(where, "geometry", [&] {
    vol = gmsh::model::occ::addSphere(0, 0, 0, 1);
    if (angle > 1e-14) gmsh::model::occ::rotate({{3, vol}}, 0, 0, 0, axis.x(), axis.y(), axis.z(), angle);
    gmsh::model::occ::dilate({{3, vol}}, 0, 0, 0, ax.x(), ax.y(), ax.z());
    for (const auto& pr : o.probes_m) {
      const Eigen::Vector3d pm = pr * kMmPerM;
      probe_tags.push_back(gmsh::model::occ::addPoint(pm.x(), pm.y(), pm.z()));
    }
    gmsh::model::occ::synchronize();
    if (!probe_tags.empty()) gmsh::model::mesh::embed(0, probe_tags, 3, vol);
    gmsh::vectorpair pts;
    gmsh::model::getBoundary({{3, vol}}, pts, false, false, true);
    double best = 1e300;
    for (const auto& [d, t] : pts) {
      if (d != 0) continue;
      std::vector<double> c;
      gmsh::model::getValue(0, t, {}, c);
      const double dist = (Eigen::Vector3d(c[0], c[1], c[2]) - p_mm).norm();
      if (dist < best) best = dist, load_tag = t;
    }
    if (load_tag < 0 || best > 1e-6 * size_mm) {
      throw InputError(where, "gmsh geometry", "no sphere pole on the load point");
    }
    gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {vol}), "BODY");
    gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {load_tag}), "LOAD");
    add_probe_groups(probe_tags);
  });
  generate_tets(where, o, p_mm, h0, h);
  finish_point_mesh(where, o, folder, name, load_tag, probe_tags, p_mm, r);

  std::ostringstream g;
  g << geo_header("ellipsoid " + fmt(ax.x()) + " x " + fmt(ax.y()) + " x " + fmt(ax.z()) +
                  " mm (semi-axes), load point at a sphere pole");
  g << "SetFactory(\"OpenCASCADE\");\n" << geo_options(h, o.algorithm_3d);
  g << "Sphere(1) = {0, 0, 0, 1};\n";
  if (angle > 1e-14) {
    g << "Rotate {{" << fmt(axis.x()) << ", " << fmt(axis.y()) << ", " << fmt(axis.z())
      << "}, {0, 0, 0}, " << fmt(angle) << "} { Volume{1}; }\n";
  }
  g << "Dilate {{0, 0, 0}, {" << fmt(ax.x()) << ", " << fmt(ax.y()) << ", " << fmt(ax.z())
    << "}} { Volume{1}; }\n";
  const double e = 1e-6 * size_mm;
  g << "load() = Point In BoundingBox {" << fmt(p_mm.x() - e) << ", " << fmt(p_mm.y() - e) << ", "
    << fmt(p_mm.z() - e) << ", " << fmt(p_mm.x() + e) << ", " << fmt(p_mm.y() + e) << ", "
    << fmt(p_mm.z() + e) << "};\n";
  g << geo_probe_points(o);
  g << geo_size_field(p_mm, h0, h);
  g << "Physical Volume(\"BODY\") = {1};\nPhysical Point(\"LOAD\") = {load()};\n";
  g << geo_probe_groups(o);
  r.geo = folder / (name + ".geo");
  write_file_atomically(r.geo, g.str());
  return r;
}

MeshResult mesh_stl_with_gmsh(const fs::path& stl, double stl_unit_m, const Eigen::Vector3d& load_point_m,
                    const MeshOptions& o, const fs::path& folder, const std::string& name) {
  const std::string where = stl.string();
  check_options(o, where);
  if (!fs::is_regular_file(stl)) throw InputError(where, "file", "cannot be opened (missing or unreadable)");
  if (!(stl_unit_m > 0)) throw InputError(where, "unit", "must be > 0");
  const double scale = stl_unit_m * kMmPerM;  // STL unit -> mm
  const double h = o.mesh_size_m * kMmPerM, h0 = load_size(o) * kMmPerM;
  const Eigen::Vector3d p_mm = load_point_m * kMmPerM;
  const fs::path stl_copy = folder / (name + "_part.stl");

  MeshResult r;
  GmshSession session(name);
  // 1. Read the STL with Gmsh, rescale it to mm into one discrete surface, write the copy the
  //    .geo merges, and integrate the enclosed volume (divergence theorem).
  gmsh_step(where, "read STL", [&] {
    gmsh::merge(stl.string());
    std::vector<std::size_t> ntags;
    std::vector<double> xyz, par;
    gmsh::model::mesh::getNodes(ntags, xyz, par, 2, -1, true, false);
    std::vector<std::size_t> etags, enodes;
    gmsh::model::mesh::getElementsByType(2, etags, enodes);
    if (etags.empty()) throw InputError(where, "STL", "no triangles");
    std::map<std::size_t, Eigen::Vector3d> x;
    for (std::size_t i = 0; i < ntags.size(); ++i) {
      x[ntags[i]] = Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) * scale;
    }
    double v6 = 0;
    for (std::size_t e = 0; e < etags.size(); ++e) {
      v6 += x.at(enodes[3 * e]).dot(x.at(enodes[3 * e + 1]).cross(x.at(enodes[3 * e + 2])));
    }
    r.quality.part_volume_m3 = std::abs(v6) / 6.0 / std::pow(kMmPerM, 3);
    if (!(r.quality.part_volume_m3 > 0)) throw InputError(where, "STL", "encloses no volume");
    gmsh::clear();
    gmsh::model::add(name);
    const int s = gmsh::model::addDiscreteEntity(2);
    std::vector<double> coords;
    for (std::size_t t : ntags) {
      const Eigen::Vector3d& p = x.at(t);
      coords.insert(coords.end(), {p.x(), p.y(), p.z()});
    }
    gmsh::model::mesh::addNodes(2, s, ntags, coords);
    gmsh::model::mesh::addElementsByType(s, 2, {}, enodes);
    gmsh::model::mesh::removeDuplicateNodes();
    gmsh::write(stl_copy.string());
    gmsh::clear();
    gmsh::model::add(name);
    gmsh::merge(stl_copy.string());
  });
  // 2. Surfaces -> geometry -> volume.
  int vol = -1;
  std::vector<int> probe_tags;
  gmsh_step(where, "classify surfaces", [&] {
    gmsh::model::mesh::classifySurfaces(o.feature_angle_deg * kPi / 180.0, true, true, kPi);
    gmsh::model::mesh::createGeometry();
    gmsh::vectorpair surfs;
    gmsh::model::getEntities(surfs, 2);
    std::vector<int> st;
    for (const auto& [d, t] : surfs) st.push_back(t);
    const int loop = gmsh::model::geo::addSurfaceLoop(st);
    vol = gmsh::model::geo::addVolume({loop});
    for (const auto& pr : o.probes_m) {
      const Eigen::Vector3d pm = pr * kMmPerM;
      probe_tags.push_back(gmsh::model::geo::addPoint(pm.x(), pm.y(), pm.z()));
    }
    gmsh::model::geo::synchronize();
    if (!probe_tags.empty()) gmsh::model::mesh::embed(0, probe_tags, 3, vol);
    gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {vol}), "BODY");
    add_probe_groups(probe_tags);
  });
  generate_tets(where, o, p_mm, h0, h);
  std::map<std::size_t, int> index;
  std::size_t load_gmsh_tag = 0;
  gmsh_step(where, "mesh", [&] {
    index = extract(r.mesh, where);
    // LOAD: the surface node nearest to the load point.
    std::vector<std::size_t> tags;
    std::vector<double> xyz, par;
    gmsh::model::mesh::getNodes(tags, xyz, par, 2, -1, true, false);
    double best = 1e300;
    for (std::size_t i = 0; i < tags.size(); ++i) {
      if (!index.count(tags[i])) continue;
      const double d = (Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) - p_mm).norm();
      if (d < best) best = d, load_gmsh_tag = tags[i];
    }
    if (load_gmsh_tag == 0) throw InputError(where, "gmsh mesh", "no surface node for LOAD");
    const int ln = index.at(load_gmsh_tag);
    r.mesh.node_groups.emplace_back("LOAD", ln);
    r.quality.load_node_distance_m = best / kMmPerM;
    for (std::size_t i = 0; i < probe_tags.size(); ++i) {
      const int pn = node_of_point_entity(probe_tags[i], index, where, probe_name(i));
      r.mesh.node_groups.emplace_back(probe_name(i), pn);
      r.quality.probe_node_distance_m.push_back((r.mesh.nodes_m[pn] - o.probes_m[i]).norm());
    }
    // LOAD in the .msh files: a discrete point entity holding one point element on that node.
    const int pt = gmsh::model::addDiscreteEntity(0);
    gmsh::model::mesh::addElementsByType(pt, 15, {}, {load_gmsh_tag});
    gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {pt}), "LOAD");
  });
  fill_quality(r.mesh, r.quality);
  if (r.quality.load_node_distance_m > 2.0 * o.mesh_size_m) {
    throw InputError(where, "load point", "no surface node within 2 mesh sizes of the load point "
                     "(is the point on the part's surface?)");
  }
  check_mesh(r, where);
  gmsh_step(where, "write", [&] { write_msh(folder, name, r); });

  std::ostringstream g;
  g << geo_header("mesh part from " + stl.filename().string() + " (copied in mm as " +
                  stl_copy.filename().string() + ")");
  g << "// LOAD is the surface node nearest to (" << fmt(p_mm.x()) << ", " << fmt(p_mm.y()) << ", "
    << fmt(p_mm.z()) << ") mm, picked after meshing (impactdeck writes it into the .msh files).\n";
  g << geo_options(h, o.algorithm_3d);
  g << "Merge \"" << stl_copy.filename().string() << "\";\n"
    << "ClassifySurfaces{" << fmt(o.feature_angle_deg * kPi / 180.0) << ", 1, 1, " << fmt(kPi) << "};\n"
    << "CreateGeometry;\n"
    << "Surface Loop(1) = Surface{:};\nVolume(1) = {1};\n";
  g << geo_probe_points(o);
  g << geo_size_field(p_mm, h0, h);
  g << "Physical Volume(\"BODY\") = {1};\n";
  g << geo_probe_groups(o);
  r.geo = folder / (name + ".geo");
  write_file_atomically(r.geo, g.str());
  return r;
}

MeshResult mesh_cad_with_gmsh(const fs::path& cad, double cad_unit_m, const Eigen::Vector3d& load_point_m,
                              const MeshOptions& o, const fs::path& folder, const std::string& name) {
  const std::string where = cad.string();
  check_options(o, where);
  if (!fs::is_regular_file(cad)) throw InputError(where, "file", "cannot be opened (missing or unreadable)");
  if (!(cad_unit_m > 0)) throw InputError(where, "unit", "must be > 0");
  // STEP and IGES come in mm (OpenCASCADE converts from the file's own unit); a BREP has no unit:
  // its coordinates are in cad_unit_m metres and are scaled to mm.
  const double scale = cad_unit_m * kMmPerM;
  const bool scaled = std::abs(scale - 1.0) > 1e-15;
  const double h = o.mesh_size_m * kMmPerM, h0 = load_size(o) * kMmPerM;
  const Eigen::Vector3d p_mm = load_point_m * kMmPerM;
  const fs::path copy = folder / (name + "_part" + cad.extension().string());

  MeshResult r;
  GmshSession session(name);
  std::vector<int> volumes, probe_tags;
  int load_tag = -1, load_face = -1;
  gmsh_step(where, "read CAD", [&] {
    gmsh::option::setString("Geometry.OCCTargetUnit", "MM");
    gmsh::vectorpair out;
    gmsh::model::occ::importShapes(cad.string(), out, true);
    gmsh::vectorpair vols;
    gmsh::model::occ::getEntities(vols, 3);
    if (vols.empty()) throw InputError(where, "solids", "the file holds no solid");
    if (scaled) gmsh::model::occ::dilate(vols, 0, 0, 0, scale, scale, scale);
    gmsh::model::occ::synchronize();
    gmsh::model::getEntities(vols, 3);
    r.quality.part_volume_m3 = 0;
    for (const auto& [d, t] : vols) {
      double m = 0;
      gmsh::model::occ::getMass(3, t, m);
      r.quality.part_volume_m3 += m / std::pow(kMmPerM, 3);
      volumes.push_back(t);
    }
    // LOAD: a point embedded in the face nearest to the load point (a node exactly there).
    gmsh::vectorpair faces;
    gmsh::model::getEntities(faces, 2);
    double best = 1e300;
    Eigen::Vector3d foot = p_mm;
    for (const auto& [d, t] : faces) {
      std::vector<double> cp, uv, uv2;
      try {
        gmsh::model::getClosestPoint(2, t, {p_mm.x(), p_mm.y(), p_mm.z()}, cp, uv);
        gmsh::model::getParametrization(2, t, cp, uv2);
        if (!gmsh::model::isInside(2, t, uv2)) continue;
      } catch (...) {
        continue;  // the projection left the face: another face is nearer
      }
      const Eigen::Vector3d c(cp[0], cp[1], cp[2]);
      if ((c - p_mm).norm() < best) best = (c - p_mm).norm(), load_face = t, foot = c;
    }
    double size_mm = 0;
    {
      double x0, y0, z0, x1, y1, z1;
      gmsh::model::getBoundingBox(-1, -1, x0, y0, z0, x1, y1, z1);
      size_mm = std::max({x1 - x0, y1 - y0, z1 - z0});
    }
    if (load_face < 0 || best > 0.01 * size_mm) {
      throw InputError(where, "load point", "not within 1 % of the size of a face of the part");
    }
    load_tag = gmsh::model::occ::addPoint(foot.x(), foot.y(), foot.z());
    for (const auto& pr : o.probes_m) {
      const Eigen::Vector3d pm = pr * kMmPerM;
      probe_tags.push_back(gmsh::model::occ::addPoint(pm.x(), pm.y(), pm.z()));
    }
    gmsh::model::occ::synchronize();
    gmsh::model::mesh::embed(0, {load_tag}, 2, load_face);
    if (!probe_tags.empty()) gmsh::model::mesh::embed(0, probe_tags, 3, volumes.front());
    gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, volumes), "BODY");
    gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {load_tag}), "LOAD");
    add_probe_groups(probe_tags);
  });
  generate_tets(where, o, p_mm, h0, h);
  finish_point_mesh(where, o, folder, name, load_tag, probe_tags, p_mm, r);
  fs::copy_file(cad, copy, fs::copy_options::overwrite_existing);

  std::ostringstream g;
  g << geo_header("CAD part from " + cad.filename().string() + " (copied as " + copy.filename().string() + ")");
  g << "SetFactory(\"OpenCASCADE\");\nGeometry.OCCTargetUnit = \"MM\";\n" << geo_options(h, o.algorithm_3d);
  g << "Merge \"" << copy.filename().string() << "\";\n";
  if (scaled) g << "Dilate {{0, 0, 0}, {" << fmt(scale) << ", " << fmt(scale) << ", " << fmt(scale) << "}} { Volume{:}; }\n";
  const Eigen::Vector3d lp = r.mesh.nodes_m[r.mesh.node_of("LOAD")] * kMmPerM;
  g << "Point(2000) = {" << fmt(lp.x()) << ", " << fmt(lp.y()) << ", " << fmt(lp.z()) << "};\n"
    << "Point{2000} In Surface{" << load_face << "};\n";
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    const Eigen::Vector3d pm = o.probes_m[i] * kMmPerM;
    g << "Point(" << 1000 + i << ") = {" << fmt(pm.x()) << ", " << fmt(pm.y()) << ", " << fmt(pm.z())
      << "};\nPoint{" << 1000 + i << "} In Volume{" << volumes.front() << "};\n";
  }
  g << geo_size_field(p_mm, h0, h);
  g << "Physical Volume(\"BODY\") = {Volume{:}};\nPhysical Point(\"LOAD\") = {2000};\n";
  g << geo_probe_groups(o);
  r.geo = folder / (name + ".geo");
  write_file_atomically(r.geo, g.str());
  return r;
}

}  // namespace impactdeck::fem_export

// The plugin's entry point (gmsh_plugin.hpp); everything else in this library is hidden.
extern "C" __attribute__((visibility("default"))) const void* impactdeck_gmsh_mesher_v1() {
  using namespace impactdeck::fem_export;
  static const detail::GmshMesherV1 table{impactdeck::kVersion, sizeof(MeshResult), sizeof(MeshOptions),
                                          &mesh_ellipsoid_with_gmsh, &mesh_stl_with_gmsh,
                                          &mesh_cad_with_gmsh};
  return &table;
}
