// The full-contact CalculiX model of an impact (see contact_model.hpp).
#include "impactdeck/fem_export/contact_model.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/common/json_number.hpp"
#include "calculix.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// SI -> mm-N-s-tonne.
constexpr double kMm = 1000.0;
// The quasi-static route's files: the model both runs include, and the first run's job.
constexpr const char* kQuasiStaticModel = "model.inp";
constexpr const char* kQuasiStaticLoadJob = "load";
// The `impact` run's loading work at d_max may miss 1/2 m* V^2 by this fraction (the two runs'
// samples of one path: linear chords of a curve, O(1/increments^2)); more is an error.
constexpr double kQuasiStaticEnergyTolerance = 0.1;
constexpr double kMPa = 1e-6;
constexpr double kTonnePerMm3 = 1e-12;
// ccx face numbers of a tetrahedron (corner triples, 0-based): S1 1-2-3, S2 1-4-2, S3 2-4-3, S4 3-4-1.
constexpr int kTetFaces[4][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};

// A number of the deck text (12 digits, always with a decimal point or exponent).
std::string deck_number(double v) {
  std::ostringstream s;
  s << std::setprecision(12) << v + 0.0;
  std::string t = s.str();
  if (t.find_first_of(".eE") == std::string::npos) t += ".0";
  return t;
}

Eigen::Vector3d vec3(const json& j) { return Eigen::Vector3d(j.at(0), j.at(1), j.at(2)); }
json m3(const Eigen::Matrix3d& m) {
  return json::array({json_vector(m.row(0).transpose()), json_vector(m.row(1).transpose()), json_vector(m.row(2).transpose())});
}
Eigen::Matrix3d mat3(const json& j) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) m.row(r) = vec3(j.at(r)).transpose();
  return m;
}

// A body's quadratic mesh in the deck frame (m), and what the reader needs of it.
struct QuadBody {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::array<int, 10>> elements;  // 0-based, body-local
  std::vector<std::pair<int, int>> contact_faces;  // (element, ccx face 0..3)
  std::vector<double> node_mass_kg;  // w_n = int rho N_n dV (row sums of the consistent mass matrix)
  double mass_kg = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

// Linear tetrahedra -> C3D10 (ccx node order), placed in the deck frame; analytic bodies get their
// boundary edges' middle nodes on the exact surface.
QuadBody quadratic(const TetMesh& lin, const ContactBody& b, const Eigen::Vector3d& origin_m) {
  QuadBody q;
  std::vector<Eigen::Vector3d> own = lin.nodes_m;
  std::map<std::pair<int, int>, int> edge_node;
  q.elements.reserve(lin.tets.size());
  for (const auto& t : lin.tets) {
    std::array<int, 10> e{};
    for (int i = 0; i < 4; ++i) e[i] = t[i];
    for (int k = 0; k < 6; ++k) {
      int i = t[kTet10Edges[k][0]], j = t[kTet10Edges[k][1]];
      const auto key = std::minmax(i, j);
      auto it = edge_node.find(key);
      if (it == edge_node.end()) {
        it = edge_node.emplace(key, static_cast<int>(own.size())).first;
        own.push_back(0.5 * (lin.nodes_m[i] + lin.nodes_m[j]));
      }
      e[4 + k] = it->second;
    }
    q.elements.push_back(e);
  }
  // Boundary faces: those of one element only.
  std::map<std::array<int, 3>, std::pair<int, int>> faces;
  std::map<std::array<int, 3>, int> count;
  for (std::size_t e = 0; e < lin.tets.size(); ++e) {
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> k = {lin.tets[e][kTetFaces[f][0]], lin.tets[e][kTetFaces[f][1]], lin.tets[e][kTetFaces[f][2]]};
      std::sort(k.begin(), k.end());
      ++count[k];
      faces[k] = {static_cast<int>(e), f};
    }
  }
  if (b.body.kind == BodyKind::ellipsoid) {
    const Eigen::Vector3d ax = b.body.semi_axes_m;
    for (const auto& [k, c] : count) {
      if (c != 1) continue;
      for (int i = 0; i < 3; ++i) {
        const auto key = std::minmax(k[i], k[(i + 1) % 3]);
        Eigen::Vector3d& p = own[edge_node.at(key)];
        p /= std::sqrt(p.cwiseQuotient(ax).squaredNorm());  // onto the ellipsoid (exact surface)
      }
    }
  }
  q.nodes.reserve(own.size());
  for (const auto& p : own) q.nodes.push_back(b.rotation * p + b.position_m - origin_m);
  // Contact face candidates: every boundary face (the deck keeps those near the contact point).
  for (const auto& [k, c] : count) {
    if (c == 1) q.contact_faces.push_back(faces.at(k));
  }
  // Mass properties by the 4-point rule (exact for straight edges: degree 2 in x).
  const double rho = b.material.density_kg_m3;
  q.node_mass_kg.assign(q.nodes.size(), 0.0);
  const double ga = 0.5854101966249685, gb = 0.1381966011250105;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& e : q.elements) {
    for (int g = 0; g < 4; ++g) {
      double L[4] = {gb, gb, gb, gb};
      L[g] = ga;
      double N[10], dN[10][4];  // dN/dL_i
      for (int i = 0; i < 4; ++i) {
        N[i] = L[i] * (2 * L[i] - 1);
        for (int j = 0; j < 4; ++j) dN[i][j] = i == j ? 4 * L[i] - 1 : 0;
      }
      for (int k = 0; k < 6; ++k) {
        const int i = kTet10Edges[k][0], j = kTet10Edges[k][1];
        N[4 + k] = 4 * L[i] * L[j];
        for (int m = 0; m < 4; ++m) dN[4 + k][m] = (m == i ? 4 * L[j] : 0) + (m == j ? 4 * L[i] : 0);
      }
      // Reference coordinates xi_m = L_{m+1}, L_0 = 1 - sum: d/dxi_m = d/dL_{m+1} - d/dL_0.
      Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int n = 0; n < 10; ++n) {
        const Eigen::Vector3d& p = q.nodes[e[n]];
        x += N[n] * p;
        for (int m = 0; m < 3; ++m) J.col(m) += (dN[n][m + 1] - dN[n][0]) * p;
      }
      const double w = rho * J.determinant() / 24.0;
      for (int n = 0; n < 10; ++n) q.node_mass_kg[e[n]] += w * N[n];
      q.mass_kg += w;
      first += w * x;
      second += w * x * x.transpose();
    }
  }
  q.centroid = first / q.mass_kg;
  const Eigen::Matrix3d s = second - q.mass_kg * q.centroid * q.centroid.transpose();
  q.inertia = s.trace() * Eigen::Matrix3d::Identity() - s;
  return q;
}

MeshResult mesh_body(const ContactBody& b, const MeshOptions& mo, const fs::path& folder, const std::string& name) {
  switch (b.body.kind) {
    case BodyKind::ellipsoid:
      return mesh_ellipsoid(b.body.semi_axes_m, b.contact_point_own_m, mo, folder, name);
    case BodyKind::part:
      return mesh_part(b.body.surface, b.contact_point_own_m, mo, folder, name, b.body.name);
    case BodyKind::cad:
      return mesh_cad(b.body.cad, b.body.cad_unit_m, b.contact_point_own_m, mo, folder, name);
  }
  throw Error(ExitCode::internal_error, "unknown body kind");
}

}  // namespace

PartSurface floor_block(const Eigen::Vector3d& p, const Eigen::Vector3d& outward_normal, double size_m) {
  const Eigen::Vector3d n = outward_normal.normalized();
  // Two tangents completing n to a right-handed frame (t1, t2, n).
  const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  PartSurface s;
  // Corners: bottom (depth size) 0..3, top 4..7, counter-clockwise about n seen from above.
  for (double depth : {size_m, 0.0}) {
    for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      s.vertices_m.push_back(p + size_m * (u * t1 + v * t2) - depth * n);
    }
  }
  // Outward triangles: top (+n), bottom (-n), and the four sides.
  s.triangles = {{4, 5, 6}, {4, 6, 7}, {0, 2, 1}, {0, 3, 2}};
  for (int k = 0; k < 4; ++k) {
    const int a = k, b = (k + 1) % 4;
    s.triangles.push_back({a, b, b + 4});
    s.triangles.push_back({a, b + 4, a + 4});
  }
  return s;
}

namespace {

void check_request(const ContactModelRequest& r, const InputContext& where) {
  const ContactModelOptions& o = r.options;
  if (!(r.semi_axis_b_m > 0) || !(r.semi_axis_a_m >= r.semi_axis_b_m) || !(r.compression_time_s > 0)) {
    throw where.error("contact model", "needs the Hertz contact semi-axes (a >= b > 0) and t_m > 0");
  }
  if (!(o.contact_elements > 0) || o.contact_increments < 4 || !(o.penalty_factor > 0) || !(o.end_time_factor >= 1)) {
    throw where.error("contact model options", "contact_elements and penalty_factor > 0, increments >= 4, end factor >= 1");
  }
  if (o.quasi_static && (!(r.effective_mass_kg > 0) || !(r.approach_speed_m_s > 0) || !(r.probe_approach_m > 0) ||
                         o.static_increments < 2 || (r.target.support_depth_m && r.impactor.support_depth_m))) {
    throw where.error("contact model", "the quasi-static route needs m* > 0, V > 0, a probe approach > 0, at least 2 "
                                       "increments and a free body");
  }
  for (const ContactBody* b : {&r.target, &r.impactor}) {
    if (!(b->material.youngs_modulus_Pa > 0) || !(b->material.density_kg_m3 > 0) || !(b->far_mesh_size_m > 0)) {
      throw where.error("body '" + b->name + "'", "modulus, density and mesh size must be > 0");
    }
    if (b->material.model == MaterialModel::plastic && !(b->yield_strength_Pa > 0)) {
      throw where.error("body '" + b->name + "'", "a plastic material needs a yield strength > 0");
    }
    if (b->support_depth_m && !(*b->support_depth_m > 0)) {
      throw where.error("body '" + b->name + "'", "a fixed body's support depth must be > 0");
    }
  }
}

// The element sizes and zones of the model: h_c and where it holds.
struct Sizing {
  double hc = 0;            ///< element size at the contact
  double zone = 0;          ///< radius of the h_c zone
  double surface_zone = 0;  ///< contact faces lie within it
};

// One body as the deck needs it: its quadratic mesh in the deck frame, its held nodes, and (the
// target) its probe nodes.
struct DeckBodyMesh {
  const ContactBody* body = nullptr;
  const char* role = "";             ///< "target" or "impactor"
  Eigen::Vector3d inward_normal;     ///< deck frame: the target's -n, the impactor's n
  QuadBody q;
  std::vector<int> fixed;            ///< body-local nodes held by *BOUNDARY
  std::vector<int> driven;           ///< quasi-static: body-local nodes pushed by the approach
  std::vector<std::pair<std::string, int>> probe_nodes;  ///< 0-based, body-local
  ContactBodyMesh* summary = nullptr;  ///< the ContactDeck's record of it
  bool held_at_half_depth = false;     ///< quasi-static: the target of two free bodies is held
};

// Meshes b.body into `stage`, makes it quadratic in the deck frame, picks its held nodes and its
// contact faces, and fills b.summary.
void mesh_deck_body(const ContactModelRequest& r, const Sizing& z, const fs::path& stage, const InputContext& where,
                    DeckBodyMesh& b) {
  const ContactBody& body = *b.body;
  MeshOptions mo;
  mo.mesh_size_m = std::max(body.far_mesh_size_m, z.hc);
  mo.load_mesh_size_m = z.hc;
  mo.load_zone_radius_m = z.zone;
  mo.probes_m = body.probes_own_m;
  MeshResult m;
  try {
    m = mesh_body(body, mo, stage, b.role);
  } catch (const InputError& e) {
    // The mesher names its file in the private stage folder: name the deck folder and the body.
    throw where.error("body '" + body.name + "'", "meshing failed: " + e.reason());
  }
  b.q = quadratic(m.mesh, body, r.contact_point_m);
  b.summary->contact_node = static_cast<std::size_t>(m.mesh.node_of("LOAD"));  // corner nodes come first
  double deepest = 0;
  for (const auto& x : b.q.nodes) deepest = std::max(deepest, b.inward_normal.dot(x));
  if (body.support_depth_m || b.held_at_half_depth) {
    // The held nodes: at least the support depth under the contact point, or past half the
    // body's depth when it is shallower (a small fixed body, or a free body held in the
    // quasi-static route).
    const double depth = body.support_depth_m && deepest >= *body.support_depth_m ? *body.support_depth_m : 0.5 * deepest;
    for (std::size_t n = 0; n < b.q.nodes.size(); ++n)
      if (b.inward_normal.dot(b.q.nodes[n]) >= depth) b.fixed.push_back(static_cast<int>(n));
    if (b.fixed.empty()) throw where.error("body '" + body.name + "'", "no node to hold the fixed body by");
  } else if (r.options.quasi_static) {
    // The driven nodes: past half the body's depth (a sphere's far hemisphere), moved as one.
    for (std::size_t n = 0; n < b.q.nodes.size(); ++n)
      if (b.inward_normal.dot(b.q.nodes[n]) >= 0.5 * deepest) b.driven.push_back(static_cast<int>(n));
    if (b.driven.empty()) throw where.error("body '" + body.name + "'", "no node to push the body by");
  }
  // Probe nodes keep their numbers: the corner nodes come first in the quadratic mesh.
  for (const auto& [group, node] : m.mesh.node_groups)
    if (group.rfind("PROBE", 0) == 0) b.probe_nodes.emplace_back(group, node);
  // Keep only the faces near the contact.
  auto& cf = b.q.contact_faces;
  cf.erase(std::remove_if(cf.begin(), cf.end(),
                          [&](const std::pair<int, int>& f) {
                            const auto& e = b.q.elements[f.first];
                            Eigen::Vector3d c = Eigen::Vector3d::Zero();
                            for (int k = 0; k < 3; ++k) c += b.q.nodes[e[kTetFaces[f.second][k]]];
                            return (c / 3.0).norm() > z.surface_zone;
                          }),
           cf.end());
  if (cf.empty()) throw where.error("body '" + body.name + "'", "no boundary face near the contact point");
  ContactBodyMesh& bm = *b.summary;
  bm.node_count = b.q.nodes.size();
  bm.element_count = b.q.elements.size();
  bm.contact_faces = cf.size();
  bm.contact_mesh_size_m = z.hc;
  bm.far_mesh_size_m = mo.mesh_size_m;
  bm.fe_mass_kg = b.q.mass_kg;
  bm.fe_centroid_m = b.q.centroid;
  bm.fe_inertia_kg_m2 = b.q.inertia;
  bm.fixed_nodes = b.fixed.size();
  bm.plastic = body.material.model == MaterialModel::plastic;
}

// impact.inp: both bodies (C3D10, mm-N-s-tonne), their materials, the held nodes, the penalty
// contact pair, the initial velocities, the dynamic step and the final printing increment.
std::string contact_inp(const ContactModelRequest& r, const ContactDeck& out, const std::array<DeckBodyMesh, 2>& b,
                        bool plastic) {
  const ContactModelOptions& o = r.options;
  const double hc = out.contact_mesh_size_m;
  std::ostringstream d;
  d << "** impactdeck " << kVersion << ": full-contact model of impact '" << r.impact << "' from " << r.source << "\n"
    << "** units mm-N-s-tonne; frame: world translated so that the contact point is the origin\n"
    << "** penalty slope K = " << o.penalty_factor << " E* / h_c, h_c = " << hc * kMm << " mm\n";
  d << "*NODE, NSET=NALL\n";
  const std::size_t base[2] = {0, out.target.node_count};
  const std::size_t ebase[2] = {0, out.target.element_count};
  for (int i = 0; i < 2; ++i) {
    for (std::size_t n = 0; n < b[i].q.nodes.size(); ++n) {
      const Eigen::Vector3d p = b[i].q.nodes[n] * kMm;
      d << base[i] + n + 1 << ", " << deck_number(p.x()) << ", " << deck_number(p.y()) << ", " << deck_number(p.z()) << "\n";
    }
  }
  const char* eset[2] = {"ETGT", "EIMP"};
  for (int i = 0; i < 2; ++i) {
    d << "*ELEMENT, TYPE=C3D10, ELSET=" << eset[i] << "\n";
    for (std::size_t e = 0; e < b[i].q.elements.size(); ++e) {
      d << ebase[i] + e + 1;
      for (int k = 0; k < 10; ++k) d << ", " << base[i] + b[i].q.elements[e][k] + 1;
      d << "\n";
    }
  }
  if (!b[0].probe_nodes.empty()) {
    d << "*NSET, NSET=NPROBES\n";
    for (const auto& pn : b[0].probe_nodes) d << pn.second + 1 << "\n";
  }
  const char* sname[2] = {"STGT", "SIMP"};
  for (int i = 0; i < 2; ++i) {
    d << "*SURFACE, NAME=" << sname[i] << ", TYPE=ELEMENT\n";
    for (const auto& [e, f] : b[i].q.contact_faces) d << ebase[i] + e + 1 << ", S" << f + 1 << "\n";
  }
  const char* mname[2] = {"MTGT", "MIMP"};
  for (int i = 0; i < 2; ++i) {
    // The hybrid deck's material writer: elastic, or bilinear elastic-plastic (*PLASTIC).
    d << calculix::material_cards(mname[i], b[i].body->material, b[i].body->yield_strength_Pa, kMPa, kTonnePerMm3)
      << "*SOLID SECTION, ELSET=" << eset[i] << ", MATERIAL=" << mname[i] << "\n";
  }
  // A fixed body: its deep nodes held (the floor block's bottom face).
  for (int i = 0; i < 2; ++i) {
    if (b[i].fixed.empty()) continue;
    d << "*NSET, NSET=NFIX" << i << "\n";
    for (int n : b[i].fixed) d << base[i] + n + 1 << "\n";
    d << "*BOUNDARY\nNFIX" << i << ", 1, 3\n";
  }
  // Slave: the impactor's surface; master: the target's (both refined alike).
  d << "*SURFACE INTERACTION, NAME=SI1\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n"
    << deck_number(out.penalty_N_m3 * kMPa / kMm) << "\n"
    << "*CONTACT PAIR, INTERACTION=SI1, TYPE=SURFACE TO SURFACE\nSIMP, STGT\n";
  if (r.options.quasi_static) {
    // The steps are the runs' own (quasi_static_inp): here the pushed nodes and the contact
    // nodes whose displacements give the dents.
    for (int i = 0; i < 2; ++i) {
      if (b[i].driven.empty()) continue;
      d << "*NSET, NSET=NDRIVEN\n";
      for (int n : b[i].driven) d << base[i] + n + 1 << "\n";
    }
    d << "*NSET, NSET=NCONTACT\n"
      << base[0] + out.target.contact_node + 1 << "\n" << base[1] + out.impactor.contact_node + 1 << "\n";
    return d.str();
  }
  // Initial velocities: v + omega x (x - c) of each body (mm/s).
  d << "*INITIAL CONDITIONS, TYPE=VELOCITY\n";
  for (int i = 0; i < 2; ++i) {
    const ContactBody& body = *b[i].body;
    if (body.support_depth_m) continue;  // a fixed body starts at rest
    const Eigen::Vector3d c = body.rotation * body.centroid_own_m + body.position_m - r.contact_point_m;
    for (std::size_t n = 0; n < b[i].q.nodes.size(); ++n) {
      const Eigen::Vector3d v = (body.velocity_m_s + body.angular_velocity_rad_s.cross(b[i].q.nodes[n] - c)) * kMm;
      for (int k = 0; k < 3; ++k) d << base[i] + n + 1 << ", " << k + 1 << ", " << deck_number(v[k]) << "\n";
    }
  }
  const std::string solver = o.iterative_solver ? ", SOLVER=ITERATIVE SCALING" : "";
  // Automatic incrementation capped at the nominal step: ccx's contact may cut the first
  // increment back (seen on an eccentric sphere-on-ellipsoid hit: a fixed step diverged there).
  // The floor dt / 20 allows two cutbacks, and keeps the small steps ccx takes when the contact
  // opens ("impact rules") from costing many increments after the separation.
  // Plastic bodies: NLGEOM (a dent's strains are not small), as in the hybrid plastic deck.
  const char* nlgeom = plastic ? ", NLGEOM" : "";
  d << "*STEP" << nlgeom << ", INC=" << 20 * out.increments + 200 << "\n*DYNAMIC" << solver << "\n"
    << deck_number(out.time_step_s) << ", " << deck_number(out.end_time_s - out.time_step_s) << ", "
    << deck_number(0.05 * out.time_step_s) << ", " << deck_number(out.time_step_s) << "\n"
    << "*CONTACT PRINT, FREQUENCY=1, SLAVE=SIMP, MASTER=STGT\nCF\n"
    << (b[0].probe_nodes.empty() ? "" : "*EL FILE, FREQUENCY=1, NSET=NPROBES\nS\n") << "*END STEP\n";
  // One more increment that prints the final state of every node and the energies.
  d << "*STEP" << nlgeom << ", INC=100\n*DYNAMIC, DIRECT" << solver << "\n" << deck_number(out.time_step_s) << ", "
    << deck_number(out.time_step_s) << "\n"
    << "*CONTACT PRINT, SLAVE=SIMP, MASTER=STGT\nCF\n*NODE PRINT, NSET=NALL\nU, V\n"
    << "*EL PRINT, ELSET=ETGT, TOTALS=ONLY\nELSE, ELKE\n*EL PRINT, ELSET=EIMP, TOTALS=ONLY\nELSE, ELKE\n*END STEP\n";
  return d.str();
}

// A quasi-static run's deck: model.inp, then the driven nodes pushed by `approach_m` along `drive`
// (deck frame, unit) and brought back to 0, each in `increments` increments (ccx may cut them back);
// the driven set's reaction and the contact nodes' displacements printed at every increment.
std::string quasi_static_inp(const std::string& impact, const std::string& source, double approach_m,
                             const Eigen::Vector3d& drive, int increments) {
  std::ostringstream d;
  d << "** impactdeck " << kVersion << ": quasi-static full-contact run of impact '" << impact << "' from " << source
    << "\n** units mm-N-s-tonne; the approach " << deck_number(approach_m * kMm) << " mm, then back to 0\n"
    << "*INCLUDE, INPUT=" << kQuasiStaticModel << "\n";
  const double inc = 1.0 / increments;
  for (int step = 0; step < 2; ++step) {
    const Eigen::Vector3d u = step == 0 ? Eigen::Vector3d(approach_m * kMm * drive) : Eigen::Vector3d::Zero();
    d << "*STEP, NLGEOM, INC=" << 50 * increments << "\n*STATIC\n"
      << deck_number(inc) << ", 1.0, " << deck_number(1e-4 * inc) << ", " << deck_number(inc) << "\n*BOUNDARY\n";
    for (int k = 0; k < 3; ++k) d << "NDRIVEN, " << k + 1 << ", " << k + 1 << ", " << deck_number(u[k]) << "\n";
    d << "*NODE PRINT, NSET=NDRIVEN, TOTALS=ONLY\nRF\n*NODE PRINT, NSET=NCONTACT\nU\n*END STEP\n";
  }
  return d.str();
}

// contact.json: what the reader of the run needs (each body's nodes, nodal masses and mass
// properties, the contact and fixed nodes, the probes).
json contact_description(const ContactModelRequest& r, const ContactDeck& out, const std::array<DeckBodyMesh, 2>& b,
                         bool plastic) {
  const std::size_t base[2] = {0, out.target.node_count};
  json bj = json::array();
  for (int i = 0; i < 2; ++i) {
    const ContactBody& body = *b[i].body;
    const QuadBody& q = b[i].q;
    json nodes = json::array(), w = json::array();
    for (std::size_t n = 0; n < q.nodes.size(); ++n) {
      nodes.push_back(json_vector(q.nodes[n]));
      w.push_back(q.node_mass_kg[n]);
    }
    bj.push_back({{"name", body.name},
                  {"role", b[i].role},
                  {"first_node", base[i] + 1},
                  {"node_count", q.nodes.size()},
                  {"contact_node", base[i] + b[i].summary->contact_node + 1},
                  {"inward_normal", json_vector(b[i].inward_normal)},
                  {"fixed", !b[i].fixed.empty()},
                  {"fixed_nodes", b[i].fixed.size()},
                  {"plastic", b[i].summary->plastic},
                  {"element_count", q.elements.size()},
                  {"contact_faces", q.contact_faces.size()},
                  {"fe_mass_kg", q.mass_kg},
                  {"fe_centroid_m", json_vector(q.centroid)},
                  {"fe_inertia_kg_m2", m3(q.inertia)},
                  {"velocity_m_s", json_vector(body.velocity_m_s)},
                  {"angular_velocity_rad_s", json_vector(body.angular_velocity_rad_s)},
                  {"nodes_m", nodes},
                  {"node_mass_kg", w}});
  }
  json cj = {{"impactdeck_version", kVersion},
             {"source", r.source},
             {"impact", r.impact},
             {"job", kJobName},
             {"deck_units", kDeckUnitsMmTS},
             {"frame", "world, origin at the contact point"},
             {"contact_point_m", json_vector(r.contact_point_m)},
             {"normal", json_vector(r.normal)},
             {"contact_mesh_size_m", out.contact_mesh_size_m},
             {"penalty_N_m3", out.penalty_N_m3},
             {"penalty_factor", r.options.penalty_factor},
             {"time_step_s", out.time_step_s},
             {"end_time_s", out.end_time_s},
             {"increments", out.increments},
             {"plastic", plastic},
             {"bodies", bj}};
  json probes = json::array();
  for (const auto& [name, node] : b[0].probe_nodes) {
    probes.push_back({{"name", name}, {"node", node + 1}, {"point_m", json_vector(b[0].q.nodes[node])}});
  }
  cj["probes"] = probes;
  return cj;
}

}  // namespace

ContactDeck write_contact_deck(const ContactModelRequest& r, const fs::path& folder) {
  const InputContext where = r.context.in_file(folder.string());
  check_request(r, where);
  const ContactModelOptions& o = r.options;
  ContactDeck out;
  Sizing z;
  z.hc = r.semi_axis_b_m / o.contact_elements;
  z.zone = std::max(o.refined_zone_factor * r.semi_axis_a_m, 2 * z.hc);
  z.surface_zone = std::max(o.surface_zone_factor * r.semi_axis_a_m, 4 * z.hc);
  out.contact_mesh_size_m = z.hc;
  const double duration = r.contact_duration_s > 0 ? r.contact_duration_s : 2.0 * r.compression_time_s;
  out.time_step_s = duration / o.contact_increments;
  out.increments = static_cast<std::size_t>(std::ceil(o.end_time_factor * o.contact_increments - 1e-9));
  out.end_time_s = out.increments * out.time_step_s;
  out.penalty_N_m3 = o.penalty_factor * r.effective_modulus_Pa / z.hc;

  const fs::path parent = folder.parent_path().empty() ? fs::path(".") : folder.parent_path();
  if (!fs::is_directory(parent)) throw where.error("folder", "its parent folder does not exist");
  const fs::path stage = parent / ("." + folder.filename().string() + ".stage-" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(stage, ec);
  fs::create_directories(stage);
  try {
    const auto t0 = std::chrono::steady_clock::now();
    std::array<DeckBodyMesh, 2> b;
    b[0].body = &r.target, b[0].role = "target", b[0].inward_normal = -r.normal.normalized(), b[0].summary = &out.target;
    b[1].body = &r.impactor, b[1].role = "impactor", b[1].inward_normal = r.normal.normalized(), b[1].summary = &out.impactor;
    // Quasi-static, two free bodies: the target is held, the impactor pushed.
    b[0].held_at_half_depth = o.quasi_static && !r.target.support_depth_m && !r.impactor.support_depth_m;
    for (DeckBodyMesh& body : b) mesh_deck_body(r, z, stage, where, body);
    b[1].probe_nodes.clear();  // probes are the target's
    const bool plastic = out.target.plastic || out.impactor.plastic;
    out.impactor.first_node = out.target.node_count;
    out.node_count = out.target.node_count + out.impactor.node_count;
    out.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    json cj = contact_description(r, out, b, plastic);
    if (o.quasi_static) {
      // model.inp: the bodies, materials, supports and contact; load.inp: the first run's steps.
      // impact.inp follows from load's result (run_contact_model).
      write_file_atomically(stage / kQuasiStaticModel, contact_inp(r, out, b, plastic));
      const Eigen::Vector3d drive = -(b[0].driven.empty() ? b[1] : b[0]).inward_normal;
      cj["quasi_static"] = true;
      cj["drive_direction"] = json_vector(drive);
      cj["driven_body"] = b[0].driven.empty() ? "impactor" : "target";
      cj["effective_mass_kg"] = r.effective_mass_kg;
      cj["approach_speed_m_s"] = r.approach_speed_m_s;
      cj["probe_approach_m"] = r.probe_approach_m;
      cj["static_increments"] = o.static_increments;
      write_file_atomically(stage / (std::string(kQuasiStaticLoadJob) + ".inp"),
                            quasi_static_inp(r.impact, r.source, r.probe_approach_m, drive, o.static_increments));
    } else {
      write_file_atomically(stage / (std::string(kJobName) + ".inp"), contact_inp(r, out, b, plastic));
    }
    write_file_atomically(stage / "contact.json", cj.dump() + "\n");
    out.description = std::move(cj);

    const fs::path old = parent / ("." + folder.filename().string() + ".old-" + std::to_string(::getpid()));
    fs::remove_all(old, ec);
    if (fs::exists(folder)) fs::rename(folder, old);
    fs::rename(stage, folder);
    fs::remove_all(old, ec);
    out.folder = folder;
  } catch (...) {
    fs::remove_all(stage, ec);
    throw;
  }
  return out;
}

namespace {

struct ContactDat {
  std::vector<double> time_s;
  std::vector<Eigen::Vector3d> force_N;  // on the slave (impactor) surface
  std::map<int, Eigen::Vector3d> u_m, v_m_s;  // final step, 1-based node
  double else_J[2] = {0, 0}, elke_J[2] = {0, 0};
};

ContactDat read_contact_dat(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw InputError(p.string(), "ccx output", "cannot be read");
  ContactDat d;
  enum { none, cf, disp, vel, energy } state = none;
  int energy_set = -1;
  std::string energy_kind;
  std::string l;
  auto time_of = [&](const std::string& s) {
    const auto k = s.rfind("time");
    double t = 0;
    std::istringstream ts(k == std::string::npos ? std::string() : s.substr(k + 4));
    if (!(ts >> t) || !std::isfinite(t)) throw InputError(p.string(), "contact force", "unreadable time in '" + s + "'");
    return t;
  };
  while (std::getline(in, l)) {
    if (l.find("statistics for slave set") != std::string::npos) {
      state = cf;
      d.time_s.push_back(time_of(l));
      d.force_N.push_back(Eigen::Vector3d::Zero());
      continue;
    }
    if (l.find("displacements (vx,vy,vz)") != std::string::npos) { state = disp; continue; }
    if (l.find("velocities (vx,vy,vz)") != std::string::npos) { state = vel; continue; }
    if (l.find("internal energy") != std::string::npos || l.find("kinetic energy") != std::string::npos) {
      state = energy;
      energy_kind = l.find("kinetic") != std::string::npos ? "ELKE" : "ELSE";
      energy_set = l.find("EIMP") != std::string::npos ? 1 : 0;
      continue;
    }
    std::istringstream ls(l);
    if (state == cf) {
      // " total surface force (fx,fy,fz) and moment about the origin(mx,my,mz)"  then the numbers
      if (l.find("total surface force") != std::string::npos) {
        std::string next;
        while (std::getline(in, next) && next.find_first_not_of(" \t") == std::string::npos) {}
        std::istringstream ns(next);
        Eigen::Vector3d f;
        if (ns >> f.x() >> f.y() >> f.z()) d.force_N.back() = f;
        state = none;
      }
      continue;
    }
    if (state == disp || state == vel) {
      int n;
      Eigen::Vector3d v;
      if (ls >> n >> v.x() >> v.y() >> v.z()) {
        (state == disp ? d.u_m : d.v_m_s)[n] = v / kMm;
      }
      continue;
    }
    if (state == energy) {
      double e;
      if (ls >> e) {
        (energy_kind == "ELKE" ? d.elke_J : d.else_J)[energy_set] = e / kMm;  // N mm -> J
        state = none;
      }
    }
  }
  return d;
}

}  // namespace

namespace {

ContactRunResult run_contact(const fs::path& folder, const json& cj, const CheckOptions& options);

// A quasi-static run's output: the driven set's reaction along the drive at each printed time
// (total time: step 1 in (0, 1], step 2 in (1, 2]) and the contact nodes' last displacements.
struct StaticDat {
  std::vector<double> time, force_N;
  std::map<int, Eigen::Vector3d> last_u_m;
  double last_u_time = -1;
};

StaticDat read_static_dat(const fs::path& p, const Eigen::Vector3d& drive) {
  std::ifstream in(p);
  if (!in) throw InputError(p.string(), "ccx output", "cannot be read");
  StaticDat d;
  enum { none, force, disp } state = none;
  std::string l;
  const std::size_t cap = 10000000;  // lines: bounded whatever the file
  for (std::size_t lines = 0; std::getline(in, l) && lines < cap; ++lines) {
    const bool is_force = l.find("total force (fx,fy,fz) for set NDRIVEN") != std::string::npos;
    const bool is_disp = l.find("displacements (vx,vy,vz) for set NCONTACT") != std::string::npos;
    if (is_force || is_disp) {
      const auto k = l.rfind("time");
      double t = 0;
      std::istringstream ts(k == std::string::npos ? std::string() : l.substr(k + 4));
      if (!(ts >> t) || !std::isfinite(t)) throw InputError(p.string(), "static run", "unreadable time in '" + l + "'");
      if (is_force) {
        state = force;
        d.time.push_back(t);
      } else {
        state = disp;
        d.last_u_time = t;
      }
      continue;
    }
    std::istringstream ls(l);
    if (state == force) {
      Eigen::Vector3d f;
      if (ls >> f.x() >> f.y() >> f.z()) {
        d.force_N.push_back(f.dot(drive));  // the support pushes the body along the drive
        state = none;
      }
    } else if (state == disp) {
      int n;
      Eigen::Vector3d u;
      if (ls >> n >> u.x() >> u.y() >> u.z()) d.last_u_m[n] = u / kMm;
    }
  }
  if (d.force_N.size() != d.time.size() || d.time.empty() || d.time.back() < 2 - 1e-6) {
    throw InputError(p.string(), "static run",
                     "ccx printed the driven nodes' force up to time " + std::to_string(d.time.empty() ? 0.0 : d.time.back()) +
                         " of 2 (load and unload)");
  }
  return d;
}

// The curves of a static run that pushed to `peak_m`: loading from (0, 0), unloading from the peak.
struct StaticCurves {
  std::vector<double> ld, lf, ud, uf;
};
StaticCurves curves_of(const StaticDat& d, double peak_m) {
  StaticCurves c{{0.0}, {0.0}, {}, {}};
  for (std::size_t i = 0; i < d.time.size(); ++i) {
    const double t = d.time[i];
    if (t <= 1 + 1e-9) {
      if (t * peak_m > c.ld.back()) {
        c.ld.push_back(t * peak_m);
        c.lf.push_back(d.force_N[i]);
      }
    } else {
      if (c.ud.empty()) {
        c.ud.push_back(c.ld.back());
        c.uf.push_back(c.lf.back());
      }
      const double x = (2 - t) * peak_m;
      if (x < c.ud.back()) {
        c.ud.push_back(x);
        c.uf.push_back(d.force_N[i]);
      }
    }
  }
  return c;
}

// The quasi-static route (contact_model.hpp, "Quasi-static"): run `load`, find d_max on its curve,
// write and run `impact`, and put the mass on its curves.
ContactRunResult run_quasi_static(const fs::path& folder, json cj, const CheckOptions& options) {
  ContactRunResult r;
  r.quasi_static = true;
  r.solver_runs = 0;
  const double mass = cj.at("effective_mass_kg"), speed = cj.at("approach_speed_m_s");
  const double energy = 0.5 * mass * speed * speed;
  const int increments = cj.at("static_increments");
  const Eigen::Vector3d drive = vec3(cj.at("drive_direction"));
  const std::string impact = cj.at("impact"), source = cj.at("source");
  std::size_t nodes = 0;
  for (const auto& b : cj.at("bodies")) nodes += b.at("node_count").get<std::size_t>();
  const std::size_t solves = 8 * 2 * static_cast<std::size_t>(increments);  // cutbacks: 8 per nominal increment
  auto dat = [&](const char* job) { return folder / (std::string(job) + ".dat"); };
  auto where = [&](const char* job) { return (folder / (std::string(job) + ".dat")).string(); };

  // Run `load`: its approach doubled (twice at most) until its loading work covers the energy.
  double probe = cj.at("probe_approach_m");
  double peak = cj.value("peak_approach_m", 0.0);
  if (peak <= 0 || options.run_solver) {
    for (int attempt = 0;; ++attempt) {
      if (options.run_solver) {
        if (attempt > 0) {
          write_file_atomically(folder / (std::string(kQuasiStaticLoadJob) + ".inp"),
                                quasi_static_inp(impact, source, probe, drive, increments));
        }
        r.wall_time_s += calculix::run_ccx_job(folder, options, 2.0, nodes, solves, kQuasiStaticLoadJob);
        ++r.solver_runs;
      }
      const StaticDat d = read_static_dat(dat(kQuasiStaticLoadJob), drive);
      r.increments += d.time.size();
      const StaticCurves c = curves_of(d, probe);
      if (const auto turn = approach_at_work(c.ld, c.lf, energy)) {
        peak = *turn;
        break;
      }
      if (attempt == 2 || !options.run_solver) {
        std::ostringstream m;
        m << "the contact took " << curve_work_J(c.ld, c.lf) << " J of the impact's " << energy << " J up to an approach of "
          << probe * 1e3 << " mm (the largest tried): the bodies are softer than every contact law";
        throw InputError(where(kQuasiStaticLoadJob), "static run", m.str());
      }
      probe *= 2;
    }
    cj["probe_approach_m"] = probe;
    cj["peak_approach_m"] = peak;
    write_file_atomically(folder / "contact.json", cj.dump() + "\n");
  }
  // Run `impact` to d_max and back.
  if (options.run_solver) {
    write_file_atomically(folder / (std::string(kJobName) + ".inp"), quasi_static_inp(impact, source, peak, drive, increments));
    r.wall_time_s += calculix::run_ccx_job(folder, options, 2.0, nodes, solves, kJobName);
    ++r.solver_runs;
  }
  const StaticDat d = read_static_dat(dat(kJobName), drive);
  r.increments += d.time.size();
  const StaticCurves c = curves_of(d, peak);
  CurveImpact ci;
  try {
    // The `impact` run samples the loading path at other approaches than `load`: its work at d_max
    // may fall a little short of 1/2 m* V^2 (energy_relative_error says how much); beyond
    // kQuasiStaticEnergyTolerance the runs disagree and this throws.
    ci = impact_on_curves(c.ld, c.lf, c.ud, c.uf, mass, speed, kQuasiStaticEnergyTolerance);
  } catch (const std::invalid_argument& e) {
    throw InputError(where(kJobName), "static run", e.what());
  }
  r.peak_approach_m = peak;
  r.energy_relative_error = std::abs(curve_work_J(c.ld, c.lf) / energy - 1);
  r.curve_approach_m = c.ld;
  r.curve_force_N = c.lf;
  r.curve_approach_m.insert(r.curve_approach_m.end(), c.ud.begin() + 1, c.ud.end());
  r.curve_force_N.insert(r.curve_force_N.end(), c.uf.begin() + 1, c.uf.end());
  r.time_s = ci.time_s;
  r.force_N = ci.force_N;
  r.max_force_N = ci.max_force_N;
  r.max_force_time_s = ci.max_force_time_s;
  r.impulse_Ns = ci.impulse_Ns;
  r.contact_duration_s = ci.contact_time_s;
  r.restitution = ci.restitution;
  // Each body's dent: its contact node's displacement into it at the end (both supports are back
  // where they started).
  for (int i = 0; i < 2; ++i) {
    const json& b = cj.at("bodies").at(i);
    ContactBodyMotion& m = i == 0 ? r.target : r.impactor;
    m.fixed = b.value("fixed", false);
    const int node = b.at("contact_node");
    const auto it = d.last_u_m.find(node);
    if (it == d.last_u_m.end() || d.last_u_time < 2 - 1e-6) {
      throw InputError(where(kJobName), "static run", "no final displacement of contact node " + std::to_string(node));
    }
    m.dent_m = it->second.dot(vec3(b.at("inward_normal")));
  }
  r.residual_indentation_m = r.target.dent_m + r.impactor.dent_m;
  return r;
}

}  // namespace

ContactRunResult run_contact_model(const fs::path& folder, const CheckOptions& options) {
  const fs::path cj_path = folder / "contact.json";
  std::ifstream cin(cj_path);
  if (!cin) throw InputError(cj_path.string(), "contact deck", "missing (not a contact-model folder)");
  json cj;
  try {
    cin >> cj;
  } catch (const std::exception& e) {
    throw InputError(cj_path.string(), "contact deck", std::string("unreadable: ") + e.what());
  }
  return run_contact(folder, cj, options);
}

ContactRunResult run_contact_model(const ContactDeck& written, const CheckOptions& options) {
  return run_contact(written.folder, written.description, options);
}

namespace {

ContactRunResult run_contact(const fs::path& folder, const json& cj, const CheckOptions& options) {
  if (cj.value("quasi_static", false)) return run_quasi_static(folder, cj, options);
  ContactRunResult r;
  const double end = cj.at("end_time_s");
  if (options.run_solver) {
    // Contact: a few equation solves per increment (3-6 seen), and cutbacks: 8 per nominal one.
    std::size_t nodes = 0;
    for (const auto& b : cj.at("bodies")) nodes += b.at("node_count").get<std::size_t>();
    r.wall_time_s = calculix::run_ccx_job(folder, options, end, nodes, 8 * cj.at("increments").get<std::size_t>());
  }
  const ContactDat d = read_contact_dat(folder / (std::string(kJobName) + ".dat"));
  const Eigen::Vector3d n = vec3(cj.at("normal"));
  r.increments = d.time_s.size();
  if (d.time_s.empty() || d.time_s.back() < (1 - 1e-6) * end) {
    std::ostringstream m;
    m << "ccx printed the contact force up to " << (d.time_s.empty() ? 0.0 : d.time_s.back()) << " s of " << end << " s";
    throw InputError((folder / "impact.dat").string(), "contact force", m.str());
  }
  // Force history (the first step's increments; the final step repeats the last time).
  r.time_s.push_back(0.0);
  r.force_N.push_back(0.0);
  for (std::size_t i = 0; i < d.time_s.size(); ++i) {
    if (d.time_s[i] <= r.time_s.back()) continue;
    r.time_s.push_back(d.time_s[i]);
    r.force_N.push_back(d.force_N[i].dot(n));
  }
  for (std::size_t i = 0; i < r.force_N.size(); ++i) {
    if (r.force_N[i] > r.max_force_N) { r.max_force_N = r.force_N[i]; r.max_force_time_s = r.time_s[i]; }
    if (i > 0) r.impulse_Ns += 0.5 * (r.force_N[i] + r.force_N[i - 1]) * (r.time_s[i] - r.time_s[i - 1]);
  }
  {
    double first = -1, last = -1;
    for (std::size_t i = 0; i < r.force_N.size(); ++i) {
      if (r.force_N[i] > 1e-3 * r.max_force_N) {
        if (first < 0) first = r.time_s[i - (i > 0 ? 1 : 0)];
        last = i + 1 < r.time_s.size() ? r.time_s[i + 1] : r.time_s[i];
      }
    }
    r.contact_duration_s = first >= 0 ? last - first : 0;
  }
  // The impulse on the impactor (the slave surface), a vector: a fixed body's support takes the
  // rest of the momentum, so a free body's change is checked against it.
  Eigen::Vector3d impulse_on_impactor = Eigen::Vector3d::Zero();
  for (std::size_t i = 1; i < d.time_s.size(); ++i) {
    if (d.time_s[i] <= d.time_s[i - 1]) continue;
    impulse_on_impactor += 0.5 * (d.force_N[i] + d.force_N[i - 1]) * (d.time_s[i] - d.time_s[i - 1]);
  }
  if (!d.time_s.empty()) impulse_on_impactor += 0.5 * d.force_N.front() * d.time_s.front();
  // Final state of each body.
  Eigen::Vector3d p_before = Eigen::Vector3d::Zero(), p_after = Eigen::Vector3d::Zero();
  Eigen::Vector3d l_before = Eigen::Vector3d::Zero(), l_after = Eigen::Vector3d::Zero();  // about the origin
  Eigen::Vector3d v_contact_before = Eigen::Vector3d::Zero(), v_contact_after = Eigen::Vector3d::Zero();
  bool any_fixed = false;
  double free_momentum_error = 0;
  for (int i = 0; i < 2; ++i) {
    const json& b = cj.at("bodies").at(i);
    const std::size_t first = b.at("first_node"), count = b.at("node_count");
    const bool fixed = b.value("fixed", false);
    const double mass = b.at("fe_mass_kg");
    const Eigen::Vector3d c0 = vec3(b.at("fe_centroid_m"));
    const Eigen::Matrix3d inertia = mat3(b.at("fe_inertia_kg_m2"));
    const Eigen::Vector3d v0 = vec3(b.at("velocity_m_s")), w0 = vec3(b.at("angular_velocity_rad_s"));
    const json& nodes = b.at("nodes_m");
    const json& wn = b.at("node_mass_kg");
    Eigen::Vector3d P = Eigen::Vector3d::Zero(), first_moment = Eigen::Vector3d::Zero();
    Eigen::Vector3d U = Eigen::Vector3d::Zero();  // sum w u: the mean displacement's numerator
    std::vector<Eigen::Vector3d> x0(count), u(count), v(count);
    std::vector<double> w(count);
    for (std::size_t k = 0; k < count; ++k) {
      const int id = static_cast<int>(first + k);
      const auto iu = d.u_m.find(id), iv = d.v_m_s.find(id);
      if (iu == d.u_m.end() || iv == d.v_m_s.end()) {
        throw InputError((folder / "impact.dat").string(), "final state", "node " + std::to_string(id) + " missing");
      }
      x0[k] = vec3(nodes.at(k));
      u[k] = iu->second;
      v[k] = iv->second;
      w[k] = wn.at(k);
      P += w[k] * v[k];
      U += w[k] * u[k];
      first_moment += w[k] * (x0[k] + u[k]);
    }
    ContactBodyMotion& m = i == 0 ? r.target : r.impactor;
    m.fixed = fixed;
    m.kinetic_energy_J = d.elke_J[i];
    m.strain_energy_J = d.else_J[i];
    // The contact node's displacement into the body, less the body's rigid displacement there.
    const std::size_t cn = b.value("contact_node", first) - first;
    const Eigen::Vector3d inward = b.contains("inward_normal") ? vec3(b.at("inward_normal"))
                                                               : (i == 0 ? -n : n);
    if (fixed) {
      // Infinite mass: no rigid motion; everything left in it is vibration.
      any_fixed = true;
      m.vibration_energy_J = m.kinetic_energy_J + m.strain_energy_J;
      if (cn < count) m.dent_m = u[cn].dot(inward);
      r.vibration_energy_J += m.vibration_energy_J;
      r.final_total_energy_J += m.kinetic_energy_J + m.strain_energy_J;
      continue;
    }
    const Eigen::Vector3d c = first_moment / mass;
    // L about c and the node-weighted inertia J_w: exact omega for a rigid field (contact_model.hpp).
    Eigen::Vector3d L = Eigen::Vector3d::Zero();
    Eigen::Matrix3d Jw = Eigen::Matrix3d::Zero(), J0 = Eigen::Matrix3d::Zero();
    const Eigen::Vector3d T = U / mass;  // the rigid translation
    Eigen::Vector3d turn = Eigen::Vector3d::Zero();  // sum w y0 x (u - T): the small rigid rotation's moment
    for (std::size_t k = 0; k < count; ++k) {
      const Eigen::Vector3d y = x0[k] + u[k] - c, y0 = x0[k] - c0;
      L += w[k] * y.cross(v[k]);
      Jw += w[k] * (y.squaredNorm() * Eigen::Matrix3d::Identity() - y * y.transpose());
      J0 += w[k] * (y0.squaredNorm() * Eigen::Matrix3d::Identity() - y0 * y0.transpose());
      turn += w[k] * y0.cross(u[k] - T);
    }
    const Eigen::Vector3d V = P / mass;
    const Eigen::Vector3d omega = Jw.ldlt().solve(L);
    if (cn < count) {
      const Eigen::Vector3d theta = J0.ldlt().solve(turn);
      const Eigen::Vector3d rigid = T + theta.cross(x0[cn] - c0);
      m.dent_m = (u[cn] - rigid).dot(inward);
    }
    m.delta_velocity_m_s = V - v0;
    m.delta_angular_velocity_rad_s = omega - w0;
    m.rigid_kinetic_energy_J = 0.5 * mass * V.squaredNorm() + 0.5 * omega.dot(inertia * omega);
    m.vibration_energy_J = m.kinetic_energy_J + m.strain_energy_J - m.rigid_kinetic_energy_J;
    r.initial_kinetic_energy_J += 0.5 * mass * v0.squaredNorm() + 0.5 * w0.dot(inertia * w0);
    r.vibration_energy_J += m.vibration_energy_J;
    r.final_total_energy_J += m.kinetic_energy_J + m.strain_energy_J;
    p_before += mass * v0;
    p_after += P;
    l_before += c0.cross(mass * v0) + inertia * w0;
    l_after += c.cross(P) + L;
    // Velocity of the body's material point at the contact (the origin), before and after; the
    // relative one is the impactor's less the target's.
    const double sign = i == 0 ? -1.0 : 1.0;
    v_contact_before += sign * (v0 + w0.cross(-c0));
    v_contact_after += sign * (V + omega.cross(-c));
    const Eigen::Vector3d expected = (i == 0 ? -1.0 : 1.0) * impulse_on_impactor;
    free_momentum_error = std::max(free_momentum_error, (P - mass * v0 - expected).norm());
  }
  r.residual_indentation_m = r.target.dent_m + r.impactor.dent_m;
  {
    const double approach = -v_contact_before.dot(n);
    r.restitution = approach > 0 ? v_contact_after.dot(n) / approach : 0.0;
  }
  if (const auto it = cj.find("probes"); it != cj.end() && !it->empty()) {
    for (const auto& p : *it) {
      ProbeStress ps;
      ps.name = p.at("name");
      ps.node = p.at("node");
      ps.point_m = vec3(p.at("point_m"));
      r.probes.push_back(ps);
    }
    // The first step's output only (the second step repeats the end state).
    r.probe_time_s = read_node_stresses(folder / (std::string(kJobName) + ".frd"), r.probes, end - 0.5 * cj.at("time_step_s").get<double>());
  }
  const double scale = std::max(std::abs(r.impulse_Ns), 1e-300);
  r.linear_momentum_relative_error = (any_fixed ? free_momentum_error : (p_after - p_before).norm()) / scale;
  // Angular momentum about the contact point, per impulse times the larger body's size.
  double size = 0;
  for (int i = 0; i < 2; ++i) {
    const json& b = cj.at("bodies").at(i);
    for (const auto& p : b.at("nodes_m")) size = std::max(size, vec3(p).norm());
  }
  r.angular_momentum_relative_error = (l_after - l_before).norm() / (scale * std::max(size, 1e-300));
  return r;
}

}  // namespace

}  // namespace impactdeck::fem_export
