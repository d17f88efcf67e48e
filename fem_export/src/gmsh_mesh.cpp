// Gmsh meshing of the target body (see mesh.hpp). gmsh.h is used only in this file, which is
// built into the plugin libimpactdeck_gmsh_mesher.so (gmsh_plugin.hpp, gmsh_loader.cpp).
#include <gmsh.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <array>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "impactdeck/common/numeric.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/child_process.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/guarded_step.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/fem_export/mesh.hpp"
#include "gmsh_home_files.hpp"
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
    initialize_gmsh_without_home_files();  // no FLTK preferences, no ~/.gmsh-tmp (gmsh_home_files.hpp)
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
void gmsh_step(const InputContext& where, const std::string& step, F&& f) {
  run_as_input_error(where, "gmsh " + step, std::forward<F>(f), &GmshSession::last_error);
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// The mesh-size field: size h0 within r0 of the load point, then growing with slope
// (h - h0) / (4 h) up to h (r0 = 0: h0 growing linearly to h at distance 4 h).
std::string size_formula(const Eigen::Vector3d& p_mm, double h0_mm, double h_mm, double r0_mm) {
  std::ostringstream f;
  f.precision(17);
  f << "Min(" << h_mm << ", " << h0_mm << " + " << (h_mm - h0_mm) / (4.0 * h_mm) << " * Max(0, Sqrt((x - ("
    << p_mm.x() << "))^2 + (y - (" << p_mm.y() << "))^2 + (z - (" << p_mm.z() << "))^2) - " << r0_mm << "))";
  return f.str();
}

// Curvature-adapted sizing (MeshOptions::curvature_elements): Gmsh sizes the curves and surfaces
// for that many elements per 2 pi radians of their curvature, never below the smallest size asked
// for anywhere else (h0) nor below h / kCurvatureMinSizeDivisor (a small fillet must not flood the
// mesh; the element count is checked after meshing all the same).
constexpr double kCurvatureMinSizeDivisor = 4.0;
double curvature_min_size(const MeshOptions& o, double h_mm, double h0_mm) {
  return o.curvature_elements > 0 ? std::min(h_mm / kCurvatureMinSizeDivisor, h0_mm) : 0.0;
}

void set_common_options(const MeshOptions& o, double h_mm, double h0_mm, int algorithm_2d) {
  gmsh::option::setNumber("Mesh.CharacteristicLengthMax", h_mm);
  gmsh::option::setNumber("Mesh.CharacteristicLengthMin", curvature_min_size(o, h_mm, h0_mm));
  gmsh::option::setNumber("Mesh.CharacteristicLengthFromPoints", 0);
  gmsh::option::setNumber("Mesh.CharacteristicLengthFromCurvature", o.curvature_elements);
  gmsh::option::setNumber("Mesh.CharacteristicLengthExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.Algorithm", algorithm_2d);
  gmsh::option::setNumber("Mesh.Algorithm3D", o.algorithm_3d);
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  gmsh::option::setNumber("Mesh.Optimize", 1);
}

// The .geo's mesh options; h and h0 in the script's length unit (geo_header).
std::string geo_options(const MeshOptions& o, double h, double h0, int algorithm_2d) {
  std::ostringstream g;
  g << "Mesh.CharacteristicLengthMax = " << fmt(h) << ";\n"
    << "Mesh.CharacteristicLengthMin = " << fmt(curvature_min_size(o, h, h0)) << ";\n"
    << "Mesh.CharacteristicLengthFromPoints = 0;\n"
    << "Mesh.CharacteristicLengthFromCurvature = " << o.curvature_elements
    << "; // elements per 2 Pi of curvature (0: off)\n"
    << "Mesh.CharacteristicLengthExtendFromBoundary = 0;\n"
    << "Mesh.Algorithm = " << algorithm_2d << "; // 1 MeshAdapt, 5 Delaunay, 6 Frontal-Delaunay\n"
    << "Mesh.Algorithm3D = " << o.algorithm_3d << "; // 1 Delaunay, 10 HXT\n"
    << "Mesh.ElementOrder = 1;\n"
    << "Mesh.Optimize = 1;\n"
    << "General.NumThreads = 1;\n";
  return g.str();
}

int add_size_field(const Eigen::Vector3d& p_mm, double h0_mm, double h_mm, double r0_mm) {
  const int f = gmsh::model::mesh::field::add("MathEval");
  gmsh::model::mesh::field::setString(f, "F", size_formula(p_mm, h0_mm, h_mm, r0_mm));
  gmsh::model::mesh::field::setAsBackgroundMesh(f);
  return f;
}

std::string probe_name(std::size_t i) { return "PROBE" + std::to_string(i + 1); }

// Size field around the load point, then the 3D mesh (both routes).
void generate_tets(const InputContext& where, const MeshOptions& o, int algorithm_2d, const Eigen::Vector3d& p_mm,
                   double h0, double h) {
  gmsh_step(where, "mesh", [&] {
    set_common_options(o, h, h0, algorithm_2d);
    add_size_field(p_mm, h0, h, o.load_zone_radius_m * kMmPerM);
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
// per_m: the script's length unit per metre (mm scripts: kMmPerM).
std::string geo_probe_points(const MeshOptions& o, int first_tag = 1000, double per_m = kMmPerM) {
  std::ostringstream g;
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    const Eigen::Vector3d pm = o.probes_m[i] * per_m;
    g << "Point(" << first_tag + i << ") = {" << fmt(pm.x()) << ", " << fmt(pm.y()) << ", " << fmt(pm.z())
      << "};\nPoint{" << first_tag + i << "} In Volume{1};\n";
  }
  return g.str();
}

std::string geo_probe_groups(const MeshOptions& o, int first_tag = 1000) {
  std::ostringstream g;
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    g << "Physical Point(\"" << probe_name(i) << "\") = {" << first_tag + i << "};\n";
  }
  return g.str();
}

// The .geo's size field; p, h0, h and r0 in the script's length unit (size_formula is unit-free).
std::string geo_size_field(const Eigen::Vector3d& p, double h0, double h, double r0) {
  return "Field[1] = MathEval;\nField[1].F = \"" + size_formula(p, h0, h, r0) +
         "\";\nBackground Field = 1;\n";
}

void check_options(const MeshOptions& o, const InputContext& where) {
  if (!(o.mesh_size_m > 0.0) || !std::isfinite(o.mesh_size_m)) {
    throw where.error("mesh_size", "must be > 0");
  }
  if (o.load_mesh_size_m < 0.0 || !std::isfinite(o.load_mesh_size_m)) {
    throw where.error("load_mesh_size", "must be >= 0");
  }
  if (o.algorithm_3d != 1 && o.algorithm_3d != 10) throw where.error("algorithm_3d", "must be 1 or 10");
  if (o.algorithm_2d != 0 && o.algorithm_2d != 1 && o.algorithm_2d != 5 && o.algorithm_2d != 6) {
    throw where.error("algorithm_2d", "must be 0 (default), 1, 5 or 6");
  }
  if (o.load_zone_radius_m < 0.0 || !std::isfinite(o.load_zone_radius_m)) {
    throw where.error("load_zone_radius", "must be >= 0");
  }
  if (o.probes_m.size() > 99) throw where.error("probes", "at most 99 probes");
}

double load_size(const MeshOptions& o) {
  const double h0 = o.load_mesh_size_m > 0 ? o.load_mesh_size_m : o.mesh_size_m / 3.0;
  return std::min(h0, o.mesh_size_m);
}

/// Reads the tetrahedra of the current model into a TetMesh (only nodes used by tetrahedra),
/// oriented positively; returns the map gmsh node tag -> index.
std::map<std::size_t, int> extract(TetMesh& m, const InputContext& where) {
  std::vector<std::size_t> tags;
  std::vector<double> xyz, par;
  gmsh::model::mesh::getNodes(tags, xyz, par, -1, -1, true, false);
  std::map<std::size_t, std::size_t> pos;
  for (std::size_t i = 0; i < tags.size(); ++i) pos[tags[i]] = i;

  std::vector<std::size_t> etags, enodes;
  gmsh::model::mesh::getElementsByType(4, etags, enodes);  // 4 = 4-node tetrahedron
  if (etags.empty()) {
    throw where.error("gmsh mesh", "Gmsh produced no tetrahedra (mesh size too large for "
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

int node_of_point_entity(int point_tag, const std::map<std::size_t, int>& index, const InputContext& where,
                         const std::string& what) {
  std::vector<std::size_t> tags;
  std::vector<double> xyz, par;
  gmsh::model::mesh::getNodes(tags, xyz, par, 0, point_tag, false, false);
  if (tags.empty() || !index.count(tags[0])) {
    throw where.error("gmsh mesh", what + ": no mesh node on its geometry point");
  }
  return index.at(tags[0]);
}

// Node groups LOAD (node `load`) and PROBEk (the nodes on the embedded probe points), with their
// distances to the requested points (both routes).
void add_node_groups(MeshResult& r, int load, const Eigen::Vector3d& p_mm, const std::vector<int>& probe_tags,
                     const std::map<std::size_t, int>& index, const MeshOptions& o, const InputContext& where) {
  r.mesh.node_groups.emplace_back("LOAD", load);
  r.quality.load_node_distance_m = (r.mesh.nodes_m[load] * kMmPerM - p_mm).norm() / kMmPerM;
  for (std::size_t i = 0; i < probe_tags.size(); ++i) {
    const int pn = node_of_point_entity(probe_tags[i], index, where, probe_name(i));
    r.mesh.node_groups.emplace_back(probe_name(i), pn);
    r.quality.probe_node_distance_m.push_back((r.mesh.nodes_m[pn] - o.probes_m[i]).norm());
  }
}

void fill_quality(const TetMesh& m, MeshQuality& q) {
  q.node_count = m.nodes_m.size();
  q.tet_count = m.tets.size();
  q.min_quality = q.min_gamma = 1.0;
  double sum = 0, gsum = 0;
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    const double rr = tet_quality(m, e), g = tet_gamma(m, e);
    q.min_quality = std::min(q.min_quality, rr);
    q.min_gamma = std::min(q.min_gamma, g);
    sum += rr;
    gsum += g;
  }
  q.mean_quality = sum / static_cast<double>(m.tets.size());
  q.mean_gamma = gsum / static_cast<double>(m.tets.size());
  q.fe_volume_m3 = m.volume_m3();
  q.volume_relative_difference = (q.fe_volume_m3 - q.part_volume_m3) / q.part_volume_m3;
}

void check_mesh(const MeshResult& r, const InputContext& where) {
  if (!(r.quality.min_quality > 1e-6)) {
    std::ostringstream s;
    s << "degenerate tetrahedron (radius ratio " << r.quality.min_quality
      << "): the solver would fail; change mesh_size";
    throw where.error("gmsh mesh", s.str());
  }
}

// Gmsh works in mm; the .msh files are written in the output unit.
double msh_scaling_factor(const MeshOptions& o) { return 1.0 / (kMmPerM * metres_per(o.output_unit)); }

void set_msh_paths(const fs::path& folder, const std::string& name, MeshResult& r) {
  r.msh41 = folder / (name + ".msh");
  r.msh22 = folder / (name + "_v22.msh");
}

void write_msh(const fs::path& folder, const std::string& name, const MeshOptions& o, MeshResult& r) {
  set_msh_paths(folder, name, r);
  gmsh::option::setNumber("Mesh.SaveAll", 0);  // physical groups only: BODY, LOAD, PROBEk
  gmsh::option::setNumber("Mesh.ScalingFactor", msh_scaling_factor(o));
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::write(r.msh41.string());
  gmsh::option::setNumber("Mesh.MshFileVersion", 2.2);
  gmsh::write(r.msh22.string());
}

// After meshing a body whose load point and probes are geometry points (ellipsoid and CAD routes):
// extract the tetrahedra, name LOAD and PROBEk, check and record the quality and the attempt,
// write the .msh files.
// The quality of a point mesh (ellipsoid and CAD routes), checked, and the try recorded.
void record_point_mesh(const InputContext& where, const MeshOptions& o, double h0_mm, int algorithm_2d,
                       const char* route, MeshResult& r) {
  fill_quality(r.mesh, r.quality);
  check_mesh(r, where);
  r.quality.mesh_size_m = o.mesh_size_m;
  r.quality.load_mesh_size_m = h0_mm / kMmPerM;
  r.quality.attempts.push_back({route, algorithm_2d, o.algorithm_3d, o.mesh_size_m, h0_mm / kMmPerM, "ok"});
}

void finish_point_mesh(const InputContext& where, const MeshOptions& o, const fs::path& folder,
                       const std::string& name, int load_tag, const std::vector<int>& probe_tags,
                       const Eigen::Vector3d& p_mm, double h0_mm, int algorithm_2d, const char* route,
                       MeshResult& r) {
  std::map<std::size_t, int> index;
  gmsh_step(where, "mesh", [&] {
    index = extract(r.mesh, where);
    add_node_groups(r, node_of_point_entity(load_tag, index, where, "LOAD"), p_mm, probe_tags, index, o, where);
  });
  record_point_mesh(where, o, h0_mm, algorithm_2d, route, r);
  gmsh_step(where, "write", [&] { write_msh(folder, name, o, r); });
}

// A point mesh passed back from the child process that made it (CAD and mesh-part routes): the tetrahedra, the
// node groups and their distances; the parent records the quality again from them.
std::string serialise_point_mesh(const MeshResult& r) {
  ByteWriter w;
  w.put<std::uint64_t>(r.mesh.nodes_m.size());
  for (const auto& n : r.mesh.nodes_m) {
    for (int k = 0; k < 3; ++k) w.put<double>(n[k]);
  }
  w.put<std::uint64_t>(r.mesh.tets.size());
  for (const auto& t : r.mesh.tets) {
    for (int k = 0; k < 4; ++k) w.put<std::int32_t>(t[k]);
  }
  w.put<std::uint64_t>(r.mesh.node_groups.size());
  for (const auto& [g, n] : r.mesh.node_groups) {
    w.put_string(g);
    w.put<std::int32_t>(n);
  }
  w.put<double>(r.quality.load_node_distance_m);
  w.put<std::uint64_t>(r.quality.probe_node_distance_m.size());
  for (double d : r.quality.probe_node_distance_m) w.put<double>(d);
  return w.take();
}

void read_point_mesh(const std::string& bytes, const InputContext& where, MeshResult& r) {
  ByteReader in(bytes, where, "gmsh mesh");
  const std::size_t nodes = in.count(3 * sizeof(double));
  for (std::size_t i = 0; i < nodes; ++i) {
    Eigen::Vector3d x;
    for (int k = 0; k < 3; ++k) x[k] = in.get<double>();
    r.mesh.nodes_m.push_back(x);
  }
  const std::size_t tets = in.count(4 * sizeof(std::int32_t));
  for (std::size_t i = 0; i < tets; ++i) {
    std::array<int, 4> t{};
    for (int k = 0; k < 4; ++k) {
      t[k] = in.get<std::int32_t>();
      if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= nodes) throw where.error("gmsh mesh", "a tetrahedron names an unknown node");
    }
    r.mesh.tets.push_back(t);
  }
  const std::size_t groups = in.count(8 + 4);
  for (std::size_t i = 0; i < groups; ++i) {
    std::string g = in.get_string();
    const int n = in.get<std::int32_t>();
    if (n < 0 || static_cast<std::size_t>(n) >= nodes) throw where.error("gmsh mesh", "a node group names an unknown node");
    r.mesh.node_groups.emplace_back(std::move(g), n);
  }
  r.quality.load_node_distance_m = in.get<double>();
  const std::size_t probes = in.count(sizeof(double));
  for (std::size_t i = 0; i < probes; ++i) r.quality.probe_node_distance_m.push_back(in.get<double>());
}

// The B-rep's 2D and 3D mesh may abort the process (Gmsh 4.8 throws inside its OpenMP face
// meshing, where no catch reaches), crash, or run for minutes: each CAD try meshes in a child
// process; all tries together are stopped after this many seconds.
constexpr double kCadMeshDeadlineS = 600;
// The same for a mesh part's tries (each in a child process too: mesh_part_with_gmsh).
constexpr double kPartMeshDeadlineS = 600;

// The seconds the next try has before all tries together reach `deadline_s` (started at t0);
// throws "no try left" when none.
double seconds_left(std::chrono::steady_clock::time_point t0, double deadline_s, const InputContext& where) {
  const double left = deadline_s - std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (left <= 0) {
    std::ostringstream m;
    m << "no try left within " << deadline_s << " s";
    throw where.error("gmsh mesh", m.str());
  }
  return left;
}


// The .geo's first lines: what it meshes, the unit its numbers are in (`script`: mm, Gmsh's working
// unit, for the ellipsoid and CAD routes; the deck's own unit for the part route, whose STL is in
// it), and Mesh.ScalingFactor so that the mesh is saved in the deck's unit like mesh.msh.
std::string geo_header(const std::string& what, const MeshOptions& o, LengthUnit script = LengthUnit::mm) {
  std::ostringstream s;
  s << std::setprecision(17) << metres_per(script) / metres_per(o.output_unit);
  return "// impactdeck " + std::string(kVersion) + ": " + what + "\n// Units: this script is in " + to_string(script) +
         "; the mesh is saved in " + to_string(o.output_unit) +
         " (Mesh.ScalingFactor), like the deck's mesh.msh.\n// Reproduce the mesh with: gmsh -3 -format msh41 <this file>\n"
         "Mesh.ScalingFactor = " + s.str() + ";\n";
}

}  // namespace

MeshResult mesh_ellipsoid_with_gmsh(const Eigen::Vector3d& semi_axes_m, const Eigen::Vector3d& load_point_m,
                          const MeshOptions& o, const fs::path& folder, const std::string& name) {
  const InputContext where = o.context.in_file((folder / (name + ".geo")).string());
  check_options(o, where);
  if (!((semi_axes_m.array() > 0).all())) throw where.error("semi_axes", "must be > 0");
  const Eigen::Vector3d ax = semi_axes_m * kMmPerM;
  const double size_mm = ax.maxCoeff();
  // Radial projection onto the surface through the unit sphere.
  const Eigen::Vector3d q = (load_point_m * kMmPerM).cwiseQuotient(ax);
  if (!(q.norm() > 1e-9)) throw where.error("load point", "must not be the centre");
  const Eigen::Vector3d qhat = q.normalized();
  const Eigen::Vector3d p_mm = ax.cwiseProduct(qhat);
  if ((p_mm - load_point_m * kMmPerM).norm() > 0.01 * size_mm) {
    throw where.error("load point", "more than 1 % of the size away from the surface");
  }
  const double h = o.mesh_size_m * kMmPerM, h0 = load_size(o) * kMmPerM;
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    if (o.probes_m[i].cwiseQuotient(semi_axes_m).squaredNorm() >= 1.0) {
      throw where.error(probe_name(i), "probe point is not inside the ellipsoid");
    }
  }
  // Rotation taking the north pole (0, 0, 1) onto qhat.
  const Eigen::Vector3d ez(0, 0, 1);
  double angle = std::acos(std::clamp(ez.dot(qhat), -1.0, 1.0));
  Eigen::Vector3d axis = ez.cross(qhat);
  if (axis.norm() < 1e-12) axis = Eigen::Vector3d(1, 0, 0);
  axis.normalize();

  MeshResult r;
  r.quality.part_volume_m3 = ellipsoid_volume(semi_axes_m.x(), semi_axes_m.y(), semi_axes_m.z());
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
      throw where.error("gmsh geometry", "no sphere pole on the load point");
    }
    gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {vol}), "BODY");
    gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {load_tag}), "LOAD");
    add_probe_groups(probe_tags);
  });
  const int alg2 = o.algorithm_2d ? o.algorithm_2d : 1;  // MeshAdapt: Gmsh 4.8.4's default fails on the dilated OCC sphere
  generate_tets(where, o, alg2, p_mm, h0, h);
  finish_point_mesh(where, o, folder, name, load_tag, probe_tags, p_mm, h0, alg2, "analytic", r);

  std::ostringstream g;
  g << geo_header("ellipsoid " + fmt(ax.x()) + " x " + fmt(ax.y()) + " x " + fmt(ax.z()) +
                  " mm (semi-axes), load point at a sphere pole", o);
  g << "SetFactory(\"OpenCASCADE\");\n" << geo_options(o, h, h0, alg2);
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
  g << geo_size_field(p_mm, h0, h, o.load_zone_radius_m * kMmPerM);
  g << "Physical Volume(\"BODY\") = {1};\nPhysical Point(\"LOAD\") = {load()};\n";
  g << geo_probe_groups(o);
  r.geo = folder / (name + ".geo");
  write_file_atomically(r.geo, g.str());
  return r;
}

namespace {

// The classified edge (a discrete curve of createGeometry) that passes within `tol_mm` of p_mm, or
// -1; from the segments the classification gave each edge (getClosestPoint does not answer on these
// discrete curves in Gmsh 4.8).
int edge_through(const Eigen::Vector3d& p_mm, double tol_mm) {
  gmsh::vectorpair edges;
  gmsh::model::getEntities(edges, 1);
  for (const auto& [d, tag] : edges) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> elements, nodes;
    gmsh::model::mesh::getElements(types, elements, nodes, 1, tag);
    std::vector<std::size_t> node_tags;
    std::vector<double> xyz, par;
    gmsh::model::mesh::getNodes(node_tags, xyz, par, 1, tag, true, false);
    std::map<std::size_t, Eigen::Vector3d> at;
    for (std::size_t i = 0; i < node_tags.size(); ++i) at[node_tags[i]] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    for (std::size_t k = 0; k < types.size(); ++k) {
      if (types[k] != 1) continue;  // 2-node lines
      for (std::size_t e = 0; e + 1 < nodes[k].size(); e += 2) {
        const auto a = at.find(nodes[k][e]), b = at.find(nodes[k][e + 1]);
        if (a == at.end() || b == at.end()) continue;
        const Eigen::Vector3d ab = b->second - a->second;
        const double u = std::clamp((p_mm - a->second).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
        if ((a->second + u * ab - p_mm).norm() <= tol_mm) return tag;
      }
    }
  }
  return -1;
}

// Tags of the geometry points the part route adds (above any tag createGeometry hands out).
constexpr int kLoadPointTag = 100000;
constexpr int kFirstProbeTag = 100001;

// The part surface as ASCII STL in the deck's length unit `unit` with 17 significant digits: Gmsh
// reads it back exactly. It is the input of mesh.geo, written in the same unit; the solid's name line
// states the unit.
std::string part_stl(const PartSurface& s, LengthUnit unit) {
  std::ostringstream o;
  o.precision(17);
  const double per_m = 1.0 / metres_per(unit);
  const std::string name = "part coordinates in " + std::string(to_string(unit)) + " (the deck's length unit)";
  o << "solid " << name << "\n";
  for (const auto& t : s.triangles) {
    const Eigen::Vector3d a = s.vertices_m[t[0]] * per_m, b = s.vertices_m[t[1]] * per_m, c = s.vertices_m[t[2]] * per_m;
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() > 0) n.normalize();
    o << "facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n outer loop\n";
    for (const Eigen::Vector3d* v : {&a, &b, &c}) o << "  vertex " << v->x() << " " << v->y() << " " << v->z() << "\n";
    o << " endloop\nendfacet\n";
  }
  o << "endsolid " << name << "\n";
  return o.str();
}

// Volume enclosed by the outward surface (divergence theorem about the first vertex).
double enclosed_volume_m3(const PartSurface& s) {
  const Eigen::Vector3d o = s.vertices_m.front();
  double v6 = 0;
  for (const auto& t : s.triangles) {
    v6 += (s.vertices_m[t[0]] - o).dot((s.vertices_m[t[1]] - o).cross(s.vertices_m[t[2]] - o));
  }
  return v6 / 6.0;
}

// Winding number of the closed surface around q (1 inside, 0 outside; van Oosterom-Strackee).
double winding_number(const PartSurface& s, const Eigen::Vector3d& q) {
  double w = 0;
  for (const auto& t : s.triangles) {
    const Eigen::Vector3d a = s.vertices_m[t[0]] - q, b = s.vertices_m[t[1]] - q, c = s.vertices_m[t[2]] - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    w += 2.0 * std::atan2(num, den);
  }
  return w / (4.0 * kPi);
}

void check_part_surface(const PartSurface& s, const InputContext& where) {
  if (s.triangles.empty() || s.vertices_m.empty()) throw where.error("part surface", "no triangles");
  for (const auto& v : s.vertices_m) {
    if (!v.allFinite()) throw where.error("part surface", "a vertex is not finite");
  }
  const int n = static_cast<int>(s.vertices_m.size());
  for (const auto& t : s.triangles) {
    for (int k : t) {
      if (k < 0 || k >= n) throw where.error("part surface", "a triangle names a vertex that does not exist");
    }
  }
}

// The part surface with a vertex exactly at p (a point on it): an existing vertex within
// 1e-9 of the size, else the nearest triangle split in three, or its edge (and the neighbour
// across it) split in two when p lies close to that edge (barycentric coordinate < 0.05, which
// would give a sliver). Returns the vertex index in `at`.
PartSurface with_vertex_at(const PartSurface& s, const Eigen::Vector3d& p, double size, int& at) {
  PartSurface r = s;
  std::size_t best = 0;
  double best_d = 1e300;
  Eigen::Vector3d bary(1, 0, 0);
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Eigen::Vector3d a = s.vertices_m[s.triangles[t][0]], b = s.vertices_m[s.triangles[t][1]],
                          c = s.vertices_m[s.triangles[t][2]];
    // Closest point on the triangle (Ericson, Real-Time Collision Detection, 5.1.5).
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    Eigen::Vector3d w;
    const Eigen::Vector3d bp = p - b, cp = p - c;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp), d5 = ab.dot(cp), d6 = ac.dot(cp);
    const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    if (d1 <= 0 && d2 <= 0) w = {1, 0, 0};
    else if (d3 >= 0 && d4 <= d3) w = {0, 1, 0};
    else if (d6 >= 0 && d5 <= d6) w = {0, 0, 1};
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) w = {1 - d1 / (d1 - d3), d1 / (d1 - d3), 0};
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) w = {1 - d2 / (d2 - d6), 0, d2 / (d2 - d6)};
    else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      const double x = (d4 - d3) / ((d4 - d3) + (d5 - d6));
      w = {0, 1 - x, x};
    } else {
      const double den = 1.0 / (va + vb + vc);
      w = {va * den, vb * den, vc * den};
    }
    const double d = (w[0] * a + w[1] * b + w[2] * c - p).norm();
    if (d < best_d) best_d = d, best = t, bary = w;
  }
  const std::array<int, 3> T = s.triangles[best];
  for (int k = 0; k < 3; ++k) {
    if ((s.vertices_m[T[k]] - p).norm() <= 1e-9 * size) {
      at = T[k];
      return r;
    }
  }
  at = static_cast<int>(r.vertices_m.size());
  r.vertices_m.push_back(p);
  int k_min = 0;
  for (int k = 1; k < 3; ++k) {
    if (bary[k] < bary[k_min]) k_min = k;
  }
  if (bary[k_min] >= 0.05) {
    r.triangles[best] = {T[0], T[1], at};
    r.triangles.push_back({T[1], T[2], at});
    r.triangles.push_back({T[2], T[0], at});
    return r;
  }
  // Split the edge opposite corner k_min, in this triangle and in its neighbour across it.
  const int e0 = T[(k_min + 1) % 3], e1 = T[(k_min + 2) % 3], apex = T[k_min];
  r.triangles[best] = {apex, e0, at};
  r.triangles.push_back({apex, at, e1});
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& u = s.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (u[k] == e1 && u[(k + 1) % 3] == e0) {
        const int other = u[(k + 2) % 3];
        r.triangles[t] = {other, e1, at};
        r.triangles.push_back({other, at, e0});
        return r;
      }
    }
  }
  return r;  // an open edge: the part is validated closed, so this does not happen
}

// Whether every surface Gmsh's angle classification made of the current model (classifySurfaces
// without its split into parametrizable patches) is planar: within 1e-9 of its own size, stricter
// than Gmsh's own planarity test (1e-8 of the face's bounding box), so Gmsh maps each face by
// projection whatever its holes. Gmsh 4.8's split instead cuts the closed part surface in two
// before it looks at the feature edges, so the cut runs across faces along the triangles'
// diagonals; on a long planar face (a CAD export's two triangles of a 1000 x 20 mm side) its nodes
// lie 0.1-1 mm from the face's edge and leave slivers (min gamma 0.043 on the bench bar at 5 mm;
// 0.221 without the split, and ccx's conjugate gradients need 20 iterations a solve instead of 53).
// Curved faces keep the split: taken whole (as discs), fandisk.off's meshed worse (min gamma 0.015
// against 0.168 at 2 mm).
bool faces_all_planar() {
  gmsh::vectorpair surfaces;
  gmsh::model::getEntities(surfaces, 2);
  if (surfaces.empty()) return false;
  for (const auto& [dim, tag] : surfaces) {
    std::vector<std::size_t> triangle_tags, corners;
    gmsh::model::mesh::getElementsByType(2, triangle_tags, corners, tag);  // 2 = 3-node triangle
    if (triangle_tags.empty()) return false;
    std::vector<std::size_t> node_tags;
    std::vector<double> xyz, par;
    gmsh::model::mesh::getNodes(node_tags, xyz, par, 2, tag, true, false);
    std::map<std::size_t, Eigen::Vector3d> at;
    for (std::size_t i = 0; i < node_tags.size(); ++i) at[node_tags[i]] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (std::size_t t = 0; t < triangle_tags.size(); ++t) {
      const Eigen::Vector3d* v[3];
      for (std::size_t k = 0; k < 3; ++k) {
        const auto it = at.find(corners[3 * t + k]);
        if (it == at.end()) return false;
        v[k] = &it->second;
      }
      normal += (*v[1] - *v[0]).cross(*v[2] - *v[0]);
    }
    Eigen::Vector3d lo = at.begin()->second, hi = lo;
    for (const auto& [v, p] : at) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double diagonal = (hi - lo).norm(), nn = normal.norm();
    // A closed or folded face has (almost) no net area vector: not planar.
    if (!(diagonal > 0) || !(nn > 1e-6 * diagonal * diagonal)) return false;
    const Eigen::Vector3d unit = normal / nn, origin = at.begin()->second;
    for (const auto& [v, p] : at) {
      if (!(std::abs((p - origin).dot(unit)) <= 1e-9 * diagonal)) return false;
    }
  }
  return true;
}

// A fresh model `name` holding the part's triangles (in mm, not yet classified) as one discrete
// surface, built from memory as Gmsh's STL reader builds it from the STL copy the .geo merges:
// corners with equal coordinates are one node, numbered 3 j + k + 1 after the first corner (k of
// triangle j) that names it, and triangle j is element j + 1. So meshing from memory and the
// .geo's merge of the copy start from the same model, and the run never reads back a file it
// wrote.
void add_part(const PartSurface& s, const std::string& name) {
  gmsh::clear();
  gmsh::model::add(name);
  const int surface = gmsh::model::addDiscreteEntity(2);
  std::map<std::array<double, 3>, std::size_t> node_at;
  std::vector<std::size_t> node_tags, element_tags, element_nodes;
  std::vector<double> xyz;
  for (std::size_t j = 0; j < s.triangles.size(); ++j) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = s.vertices_m[s.triangles[j][k]] * kMmPerM;
      const auto [at, fresh] = node_at.try_emplace({p.x(), p.y(), p.z()}, 3 * j + k + 1);
      if (fresh) {
        node_tags.push_back(at->second);
        xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
      }
      element_nodes.push_back(at->second);
    }
    element_tags.push_back(j + 1);
  }
  gmsh::model::mesh::addNodes(2, surface, node_tags, xyz);
  gmsh::model::mesh::addElementsByType(surface, 2, element_tags, element_nodes);
}

// Gmsh's feature classification of the part (add_part), then its geometry: the faces as classified
// when all are planar (above), else Gmsh's split into parametrizable patches. Returns whether the
// split was used (the .geo repeats the choice).
bool classify_part_surfaces(double feature_angle_rad, const PartSurface& surf, const std::string& name) {
  gmsh::model::mesh::classifySurfaces(feature_angle_rad, true, false, kPi);
  if (faces_all_planar()) {
    try {
      gmsh::model::mesh::createGeometry();
      return false;
    } catch (...) {  // Gmsh 4.8 throws strings as well as exceptions
      // Gmsh could not parametrize a face after all: the split below, as for any other part.
    }
  }
  add_part(surf, name);
  gmsh::model::mesh::classifySurfaces(feature_angle_rad, true, true, kPi);
  gmsh::model::mesh::createGeometry();
  return true;
}

// MeshAttempt::patches of a remeshed try that meshed (classify_part_surfaces' choice).
const char* patches_word(bool split_patches) {
  return split_patches ? "parametrizable patches" : "feature faces";
}

// The tries of the mesh-part route (MeshOptions::fallback).
struct Try {
  bool own_triangles;
  int algorithm_2d;
  double size_factor;
};
std::vector<Try> part_tries(const MeshOptions& o) {
  const int first = o.algorithm_2d ? o.algorithm_2d : 6;
  std::vector<Try> t{{false, first, 1.0}};
  if (!o.fallback) return t;
  for (int a : {6, 1, 5}) {
    if (a != first) t.push_back({false, a, 1.0});
  }
  t.push_back({false, first, 0.5});
  t.push_back({false, first, 0.25});
  t.push_back({true, 0, 1.0});
  return t;
}

}  // namespace

MeshResult mesh_part_with_gmsh(const PartSurface& surf, const Eigen::Vector3d& load_point_m, const MeshOptions& o,
                               const fs::path& folder, const std::string& name, const std::string& part) {
  const InputContext where = o.context.in_file(part);
  check_options(o, where);
  check_part_surface(surf, where);
  Eigen::Vector3d lo = surf.vertices_m.front(), hi = lo;
  for (const auto& v : surf.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double size_m = (hi - lo).norm();
  const double size_mm = size_m * kMmPerM;
  const double part_volume = enclosed_volume_m3(surf);
  if (!(part_volume > 0)) throw where.error("part surface", "encloses no volume (open or inward-oriented?)");
  for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
    if (!(winding_number(surf, o.probes_m[i]) > 0.5)) {
      throw where.error(probe_name(i), "probe point is not inside the part");
    }
  }
  const Eigen::Vector3d p_mm = load_point_m * kMmPerM;
  const fs::path stl_copy = folder / (name + "_part.stl");

  const double h_first = o.mesh_size_m * kMmPerM, h0_first = load_size(o) * kMmPerM;
  const std::vector<Try> tries = part_tries(o);
  std::vector<MeshAttempt> attempts;
  const auto t0 = std::chrono::steady_clock::now();  // the tries' shared deadline
  GmshSession session(name);
  int load_surface = -1;       // remeshed: the surface the load point is embedded in
  int load_point = kLoadPointTag;  // remeshed: LOAD's point entity (a classified corner when it is one)
  int load_edge = -1;  // remeshed: the classified edge the embedded load point lies on, else -1
  bool load_on_edge_node = false;  // the kept try: LOAD is load_edge's node nearest to the point
  std::vector<int> probe_tags;
  bool split_patches = false;  // remeshed: Gmsh split the surface into parametrizable patches

  // The surface a try meshes: the part's, or (own triangles) the part's with a vertex at the load
  // point, made once.
  std::optional<PartSurface> split;
  auto surface_of = [&](bool own) -> const PartSurface& {
    if (!own) return surf;
    if (!split) {
      int at = -1;
      split = with_vertex_at(surf, load_point_m, size_m, at);
      if ((split->vertices_m[at] - load_point_m).norm() > 1e-6 * size_m) {
        throw where.error("load point", "is not on the part's surface");
      }
    }
    return *split;
  };

  // The child's part of a try: the tetrahedra, LOAD and PROBEk, the .msh files.
  auto mesh_in_child = [&](const Try& t, MeshResult& r, bool& edge_node) {
    const double h = h_first * t.size_factor, h0 = std::min(h0_first, h);
    generate_tets(where, o, t.own_triangles ? 6 : t.algorithm_2d, p_mm, h0, h);
    gmsh_step(where, "mesh", [&] {
      const std::map<std::size_t, int> index = extract(r.mesh, where);
      int ln = -1;
      std::size_t load_tag = 0;  // part triangles or an edge: the Gmsh node at (or nearest) the load point
      std::vector<std::size_t> at_point;
      if (!t.own_triangles) {
        std::vector<double> xyz, par;
        gmsh::model::mesh::getNodes(at_point, xyz, par, 0, load_point, false, false);
      }
      // A node of the point that no tetrahedron uses is no node of the mesh either.
      edge_node = !t.own_triangles && (at_point.empty() || !index.count(at_point[0])) && load_edge >= 0;
      if (t.own_triangles || edge_node) {
        // LOAD: the part's vertex at the load point; or, where Gmsh gave the point embedded on an
        // edge between faces no node of the mesh (it embeds points in surfaces, and one on a
        // surface's boundary may be left out of the tetrahedra), the edge's node nearest to it,
        // about h0/2 away at most (the size field centres h0 on the point). A discrete point
        // entity in the .msh files.
        std::vector<std::size_t> tags;
        std::vector<double> xyz, par;
        gmsh::model::mesh::getNodes(tags, xyz, par, t.own_triangles ? 2 : 1, t.own_triangles ? -1 : load_edge, true,
                                    false);
        double best = 1e300;
        for (std::size_t i = 0; i < tags.size(); ++i) {
          const double d = (Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) - p_mm).norm();
          if (d < best && index.count(tags[i])) best = d, load_tag = tags[i];
        }
        if (!(best <= (t.own_triangles ? 1e-6 * size_mm : h0))) {
          throw where.error("gmsh mesh", "no mesh node at the load point");
        }
        ln = index.at(load_tag);
        const int pt = gmsh::model::addDiscreteEntity(0);
        gmsh::model::mesh::addElementsByType(pt, 15, {}, {load_tag});
        gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {pt}), "LOAD");
      } else {
        ln = node_of_point_entity(load_point, index, where, "LOAD");
        gmsh::model::setPhysicalName(0, gmsh::model::addPhysicalGroup(0, {load_point}), "LOAD");
      }
      add_node_groups(r, ln, p_mm, probe_tags, index, o, where);
    });
    gmsh_step(where, "write", [&] { write_msh(folder, name, o, r); });
  };

  // Builds the geometry from the try's surface and meshes it with the try's settings.
  auto mesh_try = [&](const Try& t, MeshResult& r) {
    const double h = h_first * t.size_factor, h0 = std::min(h0_first, h);
    r = MeshResult{};
    r.quality.part_volume_m3 = part_volume;
    r.quality.mesh_size_m = h / kMmPerM;
    r.quality.load_mesh_size_m = h0 / kMmPerM;
    probe_tags.clear();
    split_patches = false;
    const PartSurface& tried = surface_of(t.own_triangles);
    gmsh_step(where, "read part", [&] { add_part(tried, name); });
    gmsh_step(where, t.own_triangles ? "volume" : "classify surfaces", [&] {
      std::vector<int> st;
      if (!t.own_triangles) {
        split_patches = classify_part_surfaces(o.feature_angle_deg * kPi / 180.0, tried, name);
      }
      gmsh::vectorpair surfs;
      gmsh::model::getEntities(surfs, 2);
      for (const auto& [d, tag] : surfs) st.push_back(tag);
      gmsh::model::geo::addSurfaceLoop(st, 1);
      gmsh::model::geo::addVolume({1}, 1);
      if (!t.own_triangles) {
        // A load point on a corner of the classified surfaces (a part dropped on a corner) is that
        // corner's point: a second point there would be embedded on the surface's boundary, where
        // Gmsh meshes no node for it.
        load_point = kLoadPointTag;
        gmsh::vectorpair corners;
        gmsh::model::getEntities(corners, 0);
        for (const auto& [d, tag] : corners) {
          std::vector<double> xyz;
          gmsh::model::getValue(0, tag, {}, xyz);
          if (xyz.size() == 3 && (Eigen::Vector3d(xyz[0], xyz[1], xyz[2]) - p_mm).norm() <= 1e-6 * size_mm) load_point = tag;
        }
        if (load_point == kLoadPointTag) gmsh::model::geo::addPoint(p_mm.x(), p_mm.y(), p_mm.z(), 0, kLoadPointTag);
        // The classified edge it lies on, if any (the child's stand-in when the point gets no node).
        load_edge = load_point == kLoadPointTag ? edge_through(p_mm, 1e-6 * size_mm) : -1;
      }
      for (std::size_t i = 0; i < o.probes_m.size(); ++i) {
        const Eigen::Vector3d pm = o.probes_m[i] * kMmPerM;
        probe_tags.push_back(gmsh::model::geo::addPoint(pm.x(), pm.y(), pm.z(), 0, kFirstProbeTag + static_cast<int>(i)));
      }
      gmsh::model::geo::synchronize();
      if (!t.own_triangles) {
        // The load point becomes a node of the surface that holds it.
        double best = 1e300;
        for (int tag : st) {
          std::vector<double> cp, par;
          gmsh::model::getClosestPoint(2, tag, {p_mm.x(), p_mm.y(), p_mm.z()}, cp, par);
          const double dist = (Eigen::Vector3d(cp[0], cp[1], cp[2]) - p_mm).norm();
          if (dist < best) best = dist, load_surface = tag;
        }
        if (load_surface < 0 || !(best <= 1e-6 * size_mm)) {
          std::ostringstream m;
          m << "the load point is " << best / kMmPerM << " m from the part's surface (must lie on it)";
          throw where.error("load point", m.str());
        }
        if (load_point == kLoadPointTag) gmsh::model::mesh::embed(0, {kLoadPointTag}, 2, load_surface);
      }
      if (!probe_tags.empty()) gmsh::model::mesh::embed(0, probe_tags, 3, 1);
      gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {1}), "BODY");
      add_probe_groups(probe_tags);  // LOAD: the child names it once meshed
    });
    // In a child process, stopped at the deadline: Gmsh 4.8 throws from inside its OpenMP face
    // meshing, where no catch reaches (std::terminate; seen with a load point embedded on a face's
    // boundary), and may run long. The child meshes, names LOAD and PROBEk, and writes the .msh
    // files; the last try that meshed wrote them, and the kept try is always the last one run.
    const double left = seconds_left(t0, kPartMeshDeadlineS, where);
    const std::string mesher =
        "Gmsh's mesher (" + (t.own_triangles ? std::string("part triangles") : "2D algorithm " + std::to_string(t.algorithm_2d)) + ")";
    const std::string made = run_in_child(
        where, "gmsh mesh", mesher, left,
        [&] {
          MeshResult c;
          bool edge_node = false;
          mesh_in_child(t, c, edge_node);
          return std::string(1, edge_node ? '1' : '0') + serialise_point_mesh(c);
        },
        &GmshSession::last_error);
    if (made.empty()) throw where.error("gmsh mesh", "the child process's result is truncated");
    load_on_edge_node = made[0] == '1';
    read_point_mesh(made.substr(1), where, r);
    fill_quality(r.mesh, r.quality);
    check_mesh(r, where);
  };

  MeshResult r;
  std::size_t kept = tries.size();  // index of the try whose mesh is kept
  double best_gamma = -1;
  bool accepted = false;
  for (std::size_t i = 0; i < tries.size() && !accepted; ++i) {
    const Try& t = tries[i];
    MeshAttempt a{t.own_triangles ? "part triangles" : "remeshed", t.algorithm_2d, o.algorithm_3d,
                  o.mesh_size_m * t.size_factor, std::min(h0_first, h_first * t.size_factor) / kMmPerM, "ok"};
    try {
      MeshResult ri;
      mesh_try(t, ri);
      if (!t.own_triangles) a.patches = patches_word(split_patches);
      if (o.fallback && ri.quality.min_gamma < o.quality_floor_gamma) {
        std::ostringstream m;
        m << "min gamma " << ri.quality.min_gamma << " below " << o.quality_floor_gamma;
        a.outcome = m.str();
        if (ri.quality.min_gamma > best_gamma) best_gamma = ri.quality.min_gamma, kept = i;
      } else {
        r = std::move(ri);
        kept = i;
        accepted = true;
      }
      attempts.push_back(a);
    } catch (const InputError& e) {
      // Bad input (a probe, the load point) is not a mesher failure: no retry.
      if (e.place() == "load point" || e.place().rfind("PROBE", 0) == 0 || !o.fallback) throw;
      a.outcome = e.place() + ": " + e.reason();
      attempts.push_back(a);
      // Gmsh could not classify / reparametrize the surface: other 2D settings will not help.
      if (e.place() == "gmsh classify surfaces") {
        while (i + 1 < tries.size() && !tries[i + 1].own_triangles) ++i;
      }
    }
  }
  if (kept == tries.size()) {
    std::string why;
    for (const auto& a : attempts) why += (why.empty() ? "" : "; ") + describe(a) + ": " + a.outcome;
    throw where.error("gmsh mesh", "every try failed (" + why + ")");
  }
  if (!accepted) {
    // No try met the quality floor: keep the best one (the decks' quality check reports it).
    mesh_try(tries[kept], r);
    attempts.push_back({tries[kept].own_triangles ? "part triangles" : "remeshed", tries[kept].algorithm_2d,
                        o.algorithm_3d, o.mesh_size_m * tries[kept].size_factor, r.quality.load_mesh_size_m,
                        "kept: the best min gamma of the tries",
                        tries[kept].own_triangles ? "" : patches_word(split_patches)});
  }
  r.quality.attempts = attempts;
  set_msh_paths(folder, name, r);  // the kept try wrote them (the last one run)

  const Try& t = tries[kept];
  // The .geo is in the deck's length unit, that of the STL it merges (Gmsh cannot scale a merged
  // STL). The run meshed in mm: Gmsh's tolerances are not all relative, so in another unit the
  // script's mesh may differ from mesh.msh by a few elements (docs/fem.md).
  const double k = kMmPerM * metres_per(o.output_unit);  // mm per script unit
  const double h = h_first * t.size_factor / k, h0 = std::min(h0_first, h_first * t.size_factor) / k;
  const Eigen::Vector3d p = p_mm / k;
  const std::string unit = to_string(o.output_unit);
  // The kept try's surface, for the .geo to merge (the run itself meshed it from memory).
  write_file_atomically(stl_copy, part_stl(surface_of(t.own_triangles), o.output_unit));
  std::ostringstream g;
  g << geo_header("mesh part (" + part + ") from memory, written as " + stl_copy.filename().string() + " (" + unit +
                      ")",
                  o, o.output_unit);
  if (attempts.size() > 1) g << "// Settings of try " << kept + 1 << " (see mesh_attempts in mesh_quality.json).\n";
  g << geo_options(o, h, h0, t.own_triangles ? 6 : t.algorithm_2d);
  g << "Merge \"" << stl_copy.filename().string() << "\";\n";
  if (t.own_triangles) {
    g << "// The part's own triangles are the boundary (no 2D remeshing); LOAD is its vertex at (" << fmt(p.x())
      << ", " << fmt(p.y()) << ", " << fmt(p.z()) << ") " << unit << "\n// (impactdeck writes it into the .msh files).\n"
      << "Surface Loop(1) = Surface{:};\nVolume(1) = {1};\n";
  } else {
    if (!split_patches) g << "// Every classified face is planar: no split into parametrizable patches.\n";
    g << "ClassifySurfaces{" << fmt(o.feature_angle_deg * kPi / 180.0) << ", 1, " << (split_patches ? 1 : 0) << ", "
      << fmt(kPi) << "};\n"
      << "CreateGeometry;\n"
      << "Surface Loop(1) = Surface{:};\nVolume(1) = {1};\n";
    if (load_point == kLoadPointTag) {
      g << "Point(" << kLoadPointTag << ") = {" << fmt(p.x()) << ", " << fmt(p.y()) << ", " << fmt(p.z())
        << "};  // the load point, a node of the surface that holds it\n"
        << "Point{" << kLoadPointTag << "} In Surface{" << load_surface << "};\n";
      if (load_on_edge_node) {
        g << "// It lies on edge " << load_edge << ", where Gmsh gives it no node: LOAD is that edge's node nearest to it\n"
          << "// (impactdeck writes it into the .msh files).\n";
      }
    } else {
      g << "// The load point (" << fmt(p.x()) << ", " << fmt(p.y()) << ", " << fmt(p.z()) << ") " << unit
        << " is CreateGeometry's corner point " << load_point << ".\n";
    }
  }
  g << geo_probe_points(o, kFirstProbeTag, kMmPerM / k);
  g << geo_size_field(p, h0, h, o.load_zone_radius_m * kMmPerM / k);
  g << "Physical Volume(\"BODY\") = {1};\n";
  if (!t.own_triangles && !load_on_edge_node) g << "Physical Point(\"LOAD\") = {" << load_point << "};\n";
  g << geo_probe_groups(o, kFirstProbeTag);
  r.geo = folder / (name + ".geo");
  write_file_atomically(r.geo, g.str());
  return r;
}

// One try of the CAD route with Gmsh's 2D algorithm alg2, in a session of its own.
MeshResult mesh_cad_once(const fs::path& cad, double cad_unit_m, const Eigen::Vector3d& load_point_m,
                         const MeshOptions& o, const fs::path& folder, const std::string& name, int alg2,
                         double deadline_s) {
  const InputContext where = o.context.in_file(cad.string());
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
    if (vols.empty()) throw where.error("solids", "the file holds no solid");
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
      throw where.error("load point", "not within 1 % of the size of a face of the part");
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
  // In a child process (stopped after deadline_s): the mesh, its tetrahedra and node groups, the .msh files.
  const std::string made = run_in_child(
      where, "gmsh mesh", "Gmsh's mesher (2D algorithm " + std::to_string(alg2) + ")", deadline_s,
      [&] {
        MeshResult c = r;
        generate_tets(where, o, alg2, p_mm, h0, h);
        finish_point_mesh(where, o, folder, name, load_tag, probe_tags, p_mm, h0, alg2, "cad", c);
        return serialise_point_mesh(c);
      },
      &GmshSession::last_error);
  read_point_mesh(made, where, r);
  record_point_mesh(where, o, h0, alg2, "cad", r);
  set_msh_paths(folder, name, r);
  fs::copy_file(cad, copy, fs::copy_options::overwrite_existing);

  std::ostringstream g;
  g << geo_header("CAD part from " + cad.filename().string() + " (copied as " + copy.filename().string() + ")", o);
  g << "SetFactory(\"OpenCASCADE\");\nGeometry.OCCTargetUnit = \"MM\";\n" << geo_options(o, h, h0, alg2);
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
  g << geo_size_field(p_mm, h0, h, o.load_zone_radius_m * kMmPerM);
  g << "Physical Volume(\"BODY\") = {Volume{:}};\nPhysical Point(\"LOAD\") = {2000};\n";
  g << geo_probe_groups(o);
  r.geo = folder / (name + ".geo");
  write_file_atomically(r.geo, g.str());
  return r;
}

// Gmsh's 2D algorithms 6 (Frontal-Delaunay), 1 and 5 in turn (a face one algorithm cannot mesh,
// e.g. "overlapping facets", another often can), or only the user's; every try is recorded, each
// from a fresh import of the B-rep (a failed surface mesh leaves Gmsh's model in no state to retry).
// The B-rep's search triangulation is no fallback: its faces are not sewn.
MeshResult mesh_cad_with_gmsh(const fs::path& cad, double cad_unit_m, const Eigen::Vector3d& load_point_m,
                              const MeshOptions& o, const fs::path& folder, const std::string& name) {
  // Bad options or a missing file fail once, before any try.
  const InputContext file = o.context.in_file(cad.string());
  check_options(o, file);
  if (!fs::is_regular_file(cad)) throw file.error("file", "cannot be opened (missing or unreadable)");
  if (!(cad_unit_m > 0)) throw file.error("unit", "must be > 0");
  const std::vector<int> algorithms = o.algorithm_2d ? std::vector<int>{o.algorithm_2d} : std::vector<int>{6, 1, 5};
  std::vector<MeshAttempt> failed;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0;; ++k) {
    try {
      const double left = seconds_left(t0, kCadMeshDeadlineS, file);
      MeshResult r = mesh_cad_once(cad, cad_unit_m, load_point_m, o, folder, name, algorithms[k], left);
      r.quality.attempts.insert(r.quality.attempts.begin(), failed.begin(), failed.end());
      return r;
    } catch (const InputError& e) {
      if (k + 1 == algorithms.size()) {
        if (failed.empty()) throw;
        std::string why;
        for (const auto& a : failed) why += "2D algorithm " + std::to_string(a.algorithm_2d) + ": " + a.outcome + "; ";
        throw e.context().error(e.place(), why + "2D algorithm " + std::to_string(algorithms[k]) + ": " + e.reason());
      }
      failed.push_back({"cad", algorithms[k], o.algorithm_3d, o.mesh_size_m, load_size(o), e.reason()});
    }
  }
}

}  // namespace impactdeck::fem_export

// The plugin's entry point (gmsh_plugin.hpp); everything else in this library is hidden.
extern "C" __attribute__((visibility("default"))) const void* impactdeck_gmsh_mesher_v2() {
  using namespace impactdeck::fem_export;
  static const detail::GmshMesherV2 table{impactdeck::kVersion,     sizeof(MeshResult),      sizeof(MeshOptions),
                                          sizeof(PartSurface),      &mesh_ellipsoid_with_gmsh, &mesh_part_with_gmsh,
                                          &mesh_cad_with_gmsh};
  return &table;
}
