// CadShape (cad_shape.hpp): the host side of the CAD plugin (cad_plugin.hpp, cad_gmsh.cpp). Finds
// the plugin, checks the file's unit against the declared one, and answers surface queries by
// exact projections onto the faces the triangulation names as candidates.
#include "impactdeck/geometry/cad_shape.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "cad_plugin.hpp"
#include "sharp_vertex.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/plugin.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/section_radius.hpp"

namespace impactdeck::geometry {
namespace fs = std::filesystem;
using detail::CadLoaded;

namespace {

const detail::GmshCadV1& plugin() {
  static const PluginSpec spec{"libimpactdeck_gmsh_cad.so", IMPACTDECK_GMSH_CAD_ENTRY, "IMPACTDECK_GMSH_CAD_PLUGIN",
                               IMPACTDECK_GMSH_CAD_PLUGIN_BUILD_PATH, "Gmsh CAD plugin"};
  const auto* p = static_cast<const detail::GmshCadV1*>(load_plugin(spec));
  if (std::string(p->version) != kVersion || p->sizeof_loaded != sizeof(CadLoaded) ||
      p->sizeof_frame != sizeof(detail::CadFaceFrame)) {
    throw Error(ExitCode::internal_error, spec.file + ": not the Gmsh CAD plugin of this impactdeck build (" +
                                              std::string(kVersion) + ")");
  }
  return *p;
}

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  void add(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  double distance(const Eigen::Vector3d& q) const {
    return (lo - q).cwiseMax(q - hi).cwiseMax(0.0).norm();
  }
};

}  // namespace

struct CadShape::Impl {
  fs::path file;
  CadFormat format = CadFormat::step;
  std::optional<CadFileUnit> unit;
  CadShapeOptions options;
  CadLoaded loaded;
  std::unique_ptr<MeshShape> tess;
  double tess_volume_rel = 0;
  double size = 0;
  double margin = 0;  // tessellation-to-surface bound used to widen the candidate search
  std::vector<Box> face_box;
  std::vector<int> face_index_of_tag;  // tag -> index into loaded.faces (-1: none)
  struct SharpEdge {
    int tag;
    Box box;
    std::size_t index;  // into loaded.edges
  };
  std::vector<SharpEdge> sharp;
  std::vector<Box> edge_box;  // per loaded.edges entry: its polyline's box, padded by the chord sag
  double load_seconds = 0;

  ~Impl() {
    try {
      const auto& p = plugin();
      std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
      p.release(loaded.model);
    } catch (...) {
    }
  }

  int face_index(int tag) const {
    return tag >= 0 && tag < static_cast<int>(face_index_of_tag.size()) ? face_index_of_tag[tag] : -1;
  }

  bool project_face(int face, const Eigen::Vector3d& q, detail::CadFacePoint& out) const {
    std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
    return plugin().project_on_face(loaded.model, face, q, out);
  }
  bool project_edge(int edge, const Eigen::Vector3d& q, detail::CadEdgePoint& out) const {
    std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
    return plugin().project_on_edge(loaded.model, edge, q, out);
  }
  bool frame(int face, double u, double v, detail::CadFaceFrame& out) const {
    std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
    return plugin().face_frame(loaded.model, face, u, v, out);
  }

  CadLocation locate(const Eigen::Vector3d& q) const {
    const int tri = tess->closest_triangle(q);
    const SurfacePoint tp = tess->closest_point(q);
    const double d0 = (q - tp.point_m).norm();
    const int home = loaded.triangle_face[tri];
    std::vector<int> candidates = {home};
    for (std::size_t i = 0; i < loaded.faces.size(); ++i) {
      if (loaded.faces[i] != home && face_box[i].distance(q) <= d0 + margin) candidates.push_back(loaded.faces[i]);
    }
    CadLocation best;
    double best_d = std::numeric_limits<double>::infinity();
    for (int f : candidates) {
      detail::CadFacePoint fp;
      if (!project_face(f, q, fp) || !fp.inside) continue;
      const double d = (fp.point_m - q).norm();
      if (d < best_d) {
        best_d = d;
        best.face = f;
        best.u = fp.u;
        best.v = fp.v;
        best.point.point_m = fp.point_m;
        best.point.normal = fp.normal;
      }
    }
    // Closest point on an edge of a candidate face: nearer than any face foot, or no foot at all.
    for (std::size_t k = 0; k < loaded.edges.size(); ++k) {
      const auto& e = loaded.edges[k];
      if (edge_box[k].distance(q) > best_d) continue;  // cannot be nearer than the best foot
      bool near = false;
      for (int f : e.faces) near = near || std::find(candidates.begin(), candidates.end(), f) != candidates.end();
      if (!near) continue;
      detail::CadEdgePoint ep;
      if (!project_edge(e.tag, q, ep)) continue;
      const double d = (ep.point_m - q).norm();
      if (!(d < best_d - 1e-12 * size)) continue;
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      int face = -1;
      double u = 0, v = 0;
      for (int f : e.faces) {
        detail::CadFacePoint fp;
        if (project_face(f, ep.point_m, fp)) {
          n += fp.normal;
          if (face < 0) face = f, u = fp.u, v = fp.v;
        }
      }
      if (!(n.norm() > 1e-12)) continue;
      best_d = d;
      best = CadLocation{};
      best.edge = e.tag;
      best.face = face;
      best.u = u;
      best.v = v;
      best.point.point_m = ep.point_m;
      best.point.normal = n.normalized();
    }
    if (!std::isfinite(best_d)) {
      best.point = tp;
      best.face = home;
      best.from_triangulation = true;
      best_d = d0;
    }
    best.point.distance_m = best_d;
    return best;
  }

  /// The sharp edges passing within the band of p (at most `limit`), with p's projection on each.
  std::vector<std::pair<const SharpEdge*, detail::CadEdgePoint>> sharp_edges_near(const Eigen::Vector3d& p,
                                                                                   std::size_t limit) const {
    const double band = options.sharp_band_relative * size;
    std::vector<std::pair<const SharpEdge*, detail::CadEdgePoint>> out;
    for (const auto& e : sharp) {
      if (out.size() >= limit) break;
      if (e.box.distance(p) > band) continue;
      detail::CadEdgePoint ep;
      if (project_edge(e.tag, p, ep) && (ep.point_m - p).norm() <= band) out.emplace_back(&e, ep);
    }
    return out;
  }
  bool near_sharp_edge(const Eigen::Vector3d& p) const { return !sharp_edges_near(p, 1).empty(); }

  /// The interior dihedral angle (through the solid) of B-rep edge `e` at its point p with unit
  /// tangent `t`: pi - (angle between its two faces' outward normals) where the edge is convex,
  /// pi + it where concave; nullopt unless exactly two faces meet there and both project.
  std::optional<double> interior_dihedral_rad(const CadLoaded::Edge& e, const Eigen::Vector3d& p,
                                              const Eigen::Vector3d& t) const {
    if (e.faces.size() != 2 || e.faces[0] == e.faces[1]) return std::nullopt;
    detail::CadFacePoint f0, f1;
    if (!project_face(e.faces[0], p, f0) || !project_face(e.faces[1], p, f1)) return std::nullopt;
    const double theta = std::acos(std::clamp(f0.normal.dot(f1.normal), -1.0, 1.0));
    // Face 0's direction away from the edge, across it: its side is where face 0's triangles lie
    // (the centroid of its triangle nearest to p). Convex when face 1's normal points against it.
    Eigen::Vector3d w = f0.normal.cross(t);
    if (!(w.norm() > 0)) return std::nullopt;
    double best = std::numeric_limits<double>::infinity();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < loaded.triangles.size(); ++k) {
      if (loaded.triangle_face[k] != e.faces[0]) continue;
      const auto& tri = loaded.triangles[k];
      const Eigen::Vector3d c = (loaded.nodes_m[tri[0]] + loaded.nodes_m[tri[1]] + loaded.nodes_m[tri[2]]) / 3.0;
      if ((c - p).squaredNorm() < best) {
        best = (c - p).squaredNorm();
        centroid = c;
      }
    }
    if (!std::isfinite(best)) return std::nullopt;
    if (w.dot(centroid - p) < 0) w = -w;
    return f1.normal.dot(w) < 0 ? M_PI - theta : M_PI + theta;
  }
};

namespace {

// Principal curvatures (positive convex for the outward normal n) and directions from the first
// and second fundamental forms.
bool curvature_from_frame(const detail::CadFaceFrame& f, Curvature& c) {
  const Eigen::Vector3d n = f.normal;
  Eigen::Matrix2d I, II;
  I << f.xu.dot(f.xu), f.xu.dot(f.xv), f.xu.dot(f.xv), f.xv.dot(f.xv);
  // Convex with the normal outward: the surface bends away from n, x_uu·n < 0: k = -II/I.
  II << -f.xuu.dot(n), -f.xuv.dot(n), -f.xuv.dot(n), -f.xvv.dot(n);
  const double det = I.determinant();
  // Near a singular point of the parametrisation (a sphere's pole) the forms lose ~1/det of the
  // digits: refuse below 1e-8 (the caller steps away).
  if (!(det > 1e-8 * I.trace() * I.trace()) || !II.allFinite()) return false;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> es(II, I);
  if (es.info() != Eigen::Success) return false;
  c.k2_per_m = es.eigenvalues()[0];
  c.k1_per_m = es.eigenvalues()[1];
  const Eigen::Vector2d w = es.eigenvectors().col(1);
  Eigen::Vector3d d1 = w[0] * f.xu + w[1] * f.xv;
  d1 -= d1.dot(n) * n;
  if (!(d1.norm() > 0)) return false;
  c.d1 = d1.normalized();
  c.d2 = n.cross(c.d1);
  // Cross-check against Gmsh's (OpenCASCADE's) own evaluation, which is unsigned here.
  std::array<double, 2> a{std::abs(c.k1_per_m), std::abs(c.k2_per_m)}, b{std::abs(f.k1_gmsh), std::abs(f.k2_gmsh)};
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  c.error_estimate_per_m = std::max(std::abs(a[0] - b[0]), std::abs(a[1] - b[1]));
  return std::isfinite(c.k1_per_m) && std::isfinite(c.k2_per_m);
}

}  // namespace

std::shared_ptr<const CadShape> CadShape::load(const fs::path& file, LengthUnit declared, const CadShapeOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string where = file.string();
  const auto format = cad_format(file);
  if (!format) throw InputError(where, "file", "not a CAD file (.step/.stp, .iges/.igs, .brep)");
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(where, "file", "does not exist");
  if (!fs::is_regular_file(file, ec)) throw InputError(where, "file", "is not a regular file");
  if (fs::file_size(file, ec) == 0) throw InputError(where, "file", "is empty (0 bytes)");
  if (!(o.sharp_angle_deg > 0 && o.sharp_angle_deg < 180)) throw InputError(where, "sharp_angle_deg", "must lie in (0, 180)");
  if (!(o.triangulation_size_relative > 0 && o.triangulation_size_relative <= 1)) {
    throw InputError(where, "triangulation_size_relative", "must lie in (0, 1]");
  }
  if (!(o.triangulation_deadline_s > 0)) throw InputError(where, "triangulation_deadline_s", "must be > 0");

  auto impl = std::make_unique<Impl>();
  impl->file = file;
  impl->format = *format;
  impl->options = o;
  impl->unit = cad_file_length_unit(file);
  double model_unit_m = metres_per(declared);
  if (impl->unit) {
    if (!impl->unit->unit || *impl->unit->unit != declared) {
      throw InputError(where, "length unit",
                       "the file states its length unit as " + impl->unit->name +
                           (impl->unit->unit ? std::string(" (") + to_string(*impl->unit->unit) + ")" : std::string()) +
                           "; the declared length unit " + to_string(declared) +
                           " (--length-unit, or the scene's length_unit) contradicts it");
    }
    model_unit_m = 1e-3;  // OpenCASCADE converts STEP and IGES to mm (Geometry.OCCTargetUnit)
  }
  const auto& p = plugin();
  {
    std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
    impl->loaded = p.load(file, *format, model_unit_m, o.triangulation_size_relative, o.triangulation_deadline_s);
  }
  CadLoaded& L = impl->loaded;

  TriangleMesh mesh;
  mesh.vertices_m = L.nodes_m;
  mesh.triangles = L.triangles;
  const MeshMassProperties mass = compute_mass_properties(mesh, label_shells(mesh));
  impl->tess_volume_rel = (mass.volume.volume_m3 - L.volume.volume_m3) / L.volume.volume_m3;
  double longest = 0;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) longest = std::max(longest, (mesh.vertices_m[t[k]] - mesh.vertices_m[t[(k + 1) % 3]]).norm());
  }
  MeshShapeOptions mo;
  mo.sharp_angle_deg = o.sharp_angle_deg;
  impl->tess = std::make_unique<MeshShape>(std::move(mesh), mass, mo);
  impl->size = impl->tess->size_m();
  // The search's candidate margin: the triangulation's known deviation from the B-rep
  // (OpenCASCADE's fallback, whose flat faces have long triangles), else half its longest edge.
  impl->margin = (L.triangulation_deviation_m > 0 ? L.triangulation_deviation_m : 0.5 * longest) + 1e-9 * impl->size;

  int max_tag = 0;
  for (int f : L.faces) max_tag = std::max(max_tag, f);
  impl->face_index_of_tag.assign(max_tag + 1, -1);
  impl->face_box.resize(L.faces.size());
  for (std::size_t i = 0; i < L.faces.size(); ++i) impl->face_index_of_tag[L.faces[i]] = static_cast<int>(i);
  for (std::size_t t = 0; t < L.triangles.size(); ++t) {
    Box& b = impl->face_box[impl->face_index(L.triangle_face[t])];
    for (int k = 0; k < 3; ++k) b.add(L.nodes_m[L.triangles[t][k]]);
  }
  for (auto& b : impl->face_box) {
    b.lo.array() -= impl->margin;
    b.hi.array() += impl->margin;
  }
  for (const auto& e : L.edges) {
    // The polyline's box, padded by half its longest chord (the arc between two samples stays
    // within that of the chord).
    Box box;
    double seg = 0;
    for (std::size_t i = 0; i < e.polyline_m.size(); ++i) {
      box.add(e.polyline_m[i]);
      if (i) seg = std::max(seg, (e.polyline_m[i] - e.polyline_m[i - 1]).norm());
    }
    box.lo.array() -= 0.5 * seg + 1e-9 * impl->size;
    box.hi.array() += 0.5 * seg + 1e-9 * impl->size;
    impl->edge_box.push_back(box);
    if (e.dihedral_deg > o.sharp_angle_deg) impl->sharp.push_back(Impl::SharpEdge{e.tag, box, impl->edge_box.size() - 1});
  }
  impl->load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return std::shared_ptr<const CadShape>(new CadShape(std::move(impl)));
}

CadShape::CadShape(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CadShape::~CadShape() = default;

VolumeProperties CadShape::volume_properties() const { return impl_->loaded.volume; }

CadLocation CadShape::locate(const Eigen::Vector3d& q) const { return impl_->locate(q); }

SurfacePoint CadShape::closest_point(const Eigen::Vector3d& q) const { return impl_->locate(q).point; }

bool CadShape::on_sharp_feature(const SurfacePoint& at) const { return impl_->near_sharp_edge(at.point_m); }

namespace {

// A B-rep edge's sampled polyline as seen from a point on it: the direction of the segment the
// point lies on, the edge's length (from end to end when the polyline is straight within
// kSharpRunDeg, else along it: a curved edge is never laid flat on the other body), and whether
// the point is one of its ends.
struct EdgeRun {
  Eigen::Vector3d segment = Eigen::Vector3d::UnitX();
  double length_m = 0;
  bool straight = true;
  bool at_start = false, at_end = false;
};

EdgeRun edge_run(const std::vector<Eigen::Vector3d>& poly, const Eigen::Vector3d& p, double band) {
  EdgeRun r;
  if (poly.size() < 2) return r;
  double best = std::numeric_limits<double>::infinity();
  const double cos_run = std::cos(kSharpRunDeg * M_PI / 180.0);
  const Eigen::Vector3d chord = (poly.back() - poly.front()).normalized();
  for (std::size_t i = 0; i + 1 < poly.size(); ++i) {
    const Eigen::Vector3d d = poly[i + 1] - poly[i];
    r.length_m += d.norm();
    if (d.norm() > 0 && !(d.normalized().dot(chord) >= cos_run)) r.straight = false;
    const double s = d.squaredNorm() > 0 ? std::clamp((p - poly[i]).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    const double dist = (poly[i] + s * d - p).norm();
    if (dist < best && d.norm() > 0) {
      best = dist;
      r.segment = d.normalized();
    }
  }
  if (r.straight) {
    r.length_m = (poly.back() - poly.front()).norm();
    r.segment = chord;
  }
  r.at_start = (p - poly.front()).norm() <= band;
  r.at_end = (p - poly.back()).norm() <= band;
  return r;
}

}  // namespace

std::optional<SharpFeature> CadShape::sharp_feature(const SurfacePoint& at) const {
  const Impl& I = *impl_;
  const double band = I.options.sharp_band_relative * I.size;
  // A B-rep vertex has a handful of edges; more than this many sharp ones is not a corner we model.
  constexpr std::size_t kMaxCornerEdges = 16;
  const auto near = I.sharp_edges_near(at.point_m, kMaxCornerEdges + 1);
  if (near.empty() || near.size() > kMaxCornerEdges) return std::nullopt;
  const Eigen::Vector3d n = at.normal.norm() > 0.0 ? Eigen::Vector3d(at.normal.normalized()) : Eigen::Vector3d::Zero();

  struct Near {
    const CadLoaded::Edge* edge;
    Eigen::Vector3d point;
    EdgeRun run;
    Eigen::Vector3d away;  // from the vertex into the edge (an end) or zero (an interior point)
  };
  std::vector<Near> edges;
  for (const auto& [se, ep] : near) {
    const CadLoaded::Edge& e = I.loaded.edges[se->index];
    Near x{&e, ep.point_m, edge_run(e.polyline_m, ep.point_m, band), Eigen::Vector3d::Zero()};
    if (x.run.at_start && e.polyline_m.size() > 1) x.away = (e.polyline_m[1] - e.polyline_m[0]).normalized();
    else if (x.run.at_end && e.polyline_m.size() > 1)
      x.away = (e.polyline_m[e.polyline_m.size() - 2] - e.polyline_m.back()).normalized();
    // A curved edge leaves its end along its tangent, not along its first chord.
    detail::CadEdgePoint a;
    if (!x.away.isZero() && !x.run.straight && I.project_edge(e.tag, x.point + 1e-6 * I.size * x.away, a) &&
        (a.point_m - x.point).norm() > 0)
      x.away = (a.point_m - x.point).normalized();
    edges.push_back(x);
  }
  auto edge_feature = [&](const Near& x) -> std::optional<SharpFeature> {
    // The tangent at the point: a straight edge's chord; a curved edge's from the projections of
    // two points 1e-6 of the part's size either side along its segment (error ~ 1e-6 size x the
    // edge's curvature, against the segment's own up to half the angle between samples).
    Eigen::Vector3d tangent = x.run.segment;
    if (!x.run.straight) {
      const double h = 1e-6 * I.size;
      detail::CadEdgePoint a, b;
      if (I.project_edge(x.edge->tag, x.point + h * tangent, a) && I.project_edge(x.edge->tag, x.point - h * tangent, b) &&
          (a.point_m - b.point_m).norm() > 0)
        tangent = (a.point_m - b.point_m).normalized();
    }
    const auto dihedral = I.interior_dihedral_rad(*x.edge, x.point, tangent);
    if (!dihedral) return std::nullopt;
    SharpFeature sf;
    sf.kind = SharpFeature::Kind::edge;
    sf.point_m = x.point;
    sf.direction = tangent;
    sf.length_m = x.run.length_m;
    sf.dihedral_angle_rad = *dihedral;
    return sf;
  };
  // On an edge away from its ends: that edge.
  for (const auto& x : edges)
    if (x.away.isZero()) return edge_feature(x);
  // At a vertex: the rule shared with meshes (sharp_vertex.hpp).
  std::vector<Eigen::Vector3d> away;
  for (const auto& x : edges) away.push_back(x.away);
  const detail::SharpVertex sv = detail::classify_sharp_vertex(edges[0].point, away, n, [&](std::size_t i) {
    return I.interior_dihedral_rad(*edges[i].edge, edges[i].point, edges[i].away);
  });
  if (sv.kind == detail::SharpVertex::Kind::edge) return edge_feature(edges[sv.edge]);
  if (sv.kind == detail::SharpVertex::Kind::corner) return sv.feature;
  return std::nullopt;
}

Curvature CadShape::curvature(const SurfacePoint& at) const {
  const CadLocation loc = impl_->locate(at.point_m);
  Curvature c;
  if (impl_->near_sharp_edge(loc.point.point_m)) {
    c.sharp_feature = true;
    return c;
  }
  if (loc.face < 0) throw InputError(impl_->file.string(), "point", "no face found for the curvature");
  const int fi = impl_->face_index(loc.face);
  const auto& b = impl_->loaded.face_bounds[fi];
  // At a singular point of the parametrisation (a sphere's pole) the curvature is evaluated a
  // small step towards the middle of the parameter box (1e-6 of it, growing tenfold until the
  // fundamental form is regular), and again at twice the step: the difference joins the error
  // estimate. Directions are then made tangent at the point itself.
  auto at_step = [&](double step, Curvature& out) {
    const double u = loc.u + step * (0.5 * (b[0] + b[1]) - loc.u), v = loc.v + step * (0.5 * (b[2] + b[3]) - loc.v);
    detail::CadFaceFrame fr;
    return impl_->frame(loc.face, u, v, fr) && curvature_from_frame(fr, out);
  };
  if (at_step(0, c)) return c;
  for (double step = 1e-6; step < 0.02; step *= 10) {
    Curvature c2;
    if (!at_step(step, c) || !at_step(2 * step, c2)) continue;
    c.error_estimate_per_m = std::max({c.error_estimate_per_m, std::abs(c.k1_per_m - c2.k1_per_m),
                                       std::abs(c.k2_per_m - c2.k2_per_m)});
    const Eigen::Vector3d n = loc.point.normal;
    c.d1 = (c.d1 - c.d1.dot(n) * n).normalized();
    c.d2 = n.cross(c.d1);
    return c;
  }
  throw InputError(impl_->file.string(), "face " + std::to_string(loc.face),
                   "cannot evaluate the curvature (singular parametrisation)");
}

double CadShape::paper_radius_m(const SurfacePoint& at) const {
  const Curvature c = curvature(at);
  if (c.sharp_feature) {
    throw InputError("", "point", "lies on a sharp edge or corner: the Eq. 26 radius is undefined there");
  }
  // Exact normal: a cut is tangent when |n x e| <= 1e-6 (the analytic shape's s^2 <= 1e-12).
  return paper_radius_from_curvature(c, impl_->locate(at.point_m).point.normal, 1e-6);
}

std::optional<SurfacePoint> CadShape::ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& dir) const {
  const auto hit = impl_->tess->ray_exit(o, dir);
  if (!hit || !(dir.norm() > 0)) return std::nullopt;
  const Eigen::Vector3d d = dir.normalized();
  double t = (hit->point_m - o).dot(d);
  CadLocation loc;
  // Newton on the exact surface: move along the ray to the tangent plane of the nearest point.
  for (int i = 0; i < 20; ++i) {
    loc = impl_->locate(o + t * d);
    const double denom = loc.point.normal.dot(d);
    if (!(std::abs(denom) > 1e-6)) break;
    const double dt = (loc.point.point_m - (o + t * d)).dot(loc.point.normal) / denom;
    t += dt;
    if (std::abs(dt) <= 1e-13 * impl_->size) {
      loc = impl_->locate(o + t * d);
      break;
    }
  }
  SurfacePoint sp = loc.point;
  sp.distance_m = 0;
  return sp;
}

double CadShape::size_m() const { return impl_->size; }

std::optional<SurfacePoint> CadShape::support_point(const Eigen::Vector3d& direction) const {
  const double len = direction.norm();
  if (!(len > 0.0) || !direction.allFinite()) {
    throw InputError("", "direction", "must be a non-zero finite vector");
  }
  const Eigen::Vector3d d = direction / len;
  const Eigen::Vector3d c = impl_->loaded.volume.centroid_m;
  // From far out along d the closest point is (nearly) the support point; then x + s d projected
  // back onto the surface converges to the point whose outward normal is d (a fixed point).
  SurfacePoint x = closest_point(c + 4.0 * size_m() * d);
  double best = d.dot(x.point_m);
  SurfacePoint best_point = x;
  const double step = 0.5 * size_m();
  for (int k = 0; k < 60; ++k) {
    const SurfacePoint y = closest_point(x.point_m + step * d);
    const double h = d.dot(y.point_m);
    const bool moved = (y.point_m - x.point_m).norm() > 1e-14 * size_m();
    if (h > best) {
      best = h;
      best_point = y;
    }
    x = y;
    if (!moved) break;
  }
  best_point.distance_m = 0.0;
  return best_point;
}

bool CadShape::contains(const Eigen::Vector3d& p) const { return impl_->tess->contains(p); }

std::vector<SurfacePoint> CadShape::sample_surface(std::size_t count, std::uint64_t seed) const {
  std::vector<SurfacePoint> out = impl_->tess->sample_surface(count, seed);
  for (auto& p : out) {
    p = impl_->locate(p.point_m).point;
    p.distance_m = 0;
  }
  return out;
}

const fs::path& CadShape::file() const { return impl_->file; }
CadFormat CadShape::format() const { return impl_->format; }
const std::optional<CadFileUnit>& CadShape::file_unit() const { return impl_->unit; }
int CadShape::solid_count() const { return impl_->loaded.solids; }
std::size_t CadShape::face_count() const { return impl_->loaded.faces.size(); }
std::size_t CadShape::edge_count() const { return impl_->loaded.edges.size(); }
std::size_t CadShape::sharp_edge_count() const { return impl_->sharp.size(); }
const MeshShape& CadShape::triangulation() const { return *impl_->tess; }
double CadShape::mass_relative_error_estimate() const { return impl_->loaded.mass_relative_error_estimate; }
double CadShape::triangulation_volume_relative_difference() const { return impl_->tess_volume_rel; }
const std::vector<std::string>& CadShape::warnings() const { return impl_->loaded.warnings; }
double CadShape::load_seconds() const { return impl_->load_seconds; }

}  // namespace impactdeck::geometry
