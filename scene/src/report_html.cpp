// `run`'s report page (see report_html.hpp).
#include "impactdeck/scene/report_html.hpp"
#include "sequence_files.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <system_error>

#include <nettle/sha2.h>

#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/fem_export/stress.hpp"
#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/scene/failed_checks.hpp"
#include "impactdeck/plot/force_plot.hpp"
#include "impactdeck/plot/html.hpp"
#include "impactdeck/plot/part_drawing.hpp"
#include "impactdeck/scene/report.hpp"

namespace impactdeck::scene {
namespace {

constexpr std::size_t kSceneTextLimit = 1 << 20;  // bytes of the scene's text shown

std::string g(double v, int digits = 6) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string vec3(const Eigen::Vector3d& v, double scale = 1.0, int digits = 6) {
  return "(" + g(v.x() * scale + 0.0, digits) + ", " + g(v.y() * scale + 0.0, digits) + ", " + g(v.z() * scale + 0.0, digits) + ")";
}

std::string outcome(bool ok, const std::string& text) {
  return std::string(ok ? plot::HtmlPage::kPass : plot::HtmlPage::kFail) + text;
}

std::string check_row_value(double error, double tolerance) {
  return outcome(error <= tolerance, g(error, 3) + (error <= tolerance ? " <= " : " > ") + g(tolerance, 3));
}

std::string scene_text(const Scene& scene) {
  if (scene.file.empty()) return "(scene given as text, not a file)";
  if (scene.file == kStdinScene) return "(scene read from stdin: not kept)";
  std::ifstream in(scene.file, std::ios::binary);
  if (!in) return "(the scene file can no longer be read)";
  std::string t(kSceneTextLimit, '\0');
  in.read(t.data(), static_cast<std::streamsize>(t.size()));
  t.resize(static_cast<std::size_t>(in.gcount()));
  if (in.peek() != EOF) t += "\n... (shown up to " + std::to_string(kSceneTextLimit) + " bytes)";
  return t;
}


// ---------------------------------------------------------------------------------------------
// Provenance: the inputs' SHA-256 (nettle) and modification date.

constexpr std::uintmax_t kHashLimit = std::uintmax_t{4} << 30;  // bytes: larger inputs are not hashed

std::string sha256_file(const std::filesystem::path& p) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) return "(not a regular file: not hashed)";
  const std::uintmax_t size = std::filesystem::file_size(p, ec);
  if (ec) return "(cannot be read: not hashed)";
  if (size > kHashLimit) return "(larger than 4 GiB: not hashed)";
  std::ifstream in(p, std::ios::binary);
  if (!in) return "(cannot be read: not hashed)";
  sha256_ctx ctx;
  sha256_init(&ctx);
  std::vector<char> buf(1 << 16);
  std::uintmax_t total = 0;
  while (in && total <= kHashLimit) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got == 0) break;
    sha256_update(&ctx, got, reinterpret_cast<const std::uint8_t*>(buf.data()));
    total += got;
  }
  std::uint8_t digest[SHA256_DIGEST_SIZE];
  sha256_digest(&ctx, SHA256_DIGEST_SIZE, digest);
  static const char* const hex = "0123456789abcdef";
  std::string o;
  for (std::uint8_t b : digest) o += hex[b >> 4], o += hex[b & 15];
  return o;
}

// The file's modification time as a UTC date and time, or "" when unknown.
std::string modified_utc(const std::filesystem::path& p) {
  std::error_code ec;
  const auto t = std::filesystem::last_write_time(p, ec);
  if (ec) return "";
  const auto sys = std::chrono::time_point_cast<std::chrono::seconds>(
      t - std::filesystem::file_time_type::clock::now() + std::chrono::system_clock::now());
  const std::time_t tt = std::chrono::system_clock::to_time_t(sys);
  std::tm tm{};
  if (!gmtime_r(&tt, &tm)) return "";
  char buf[32];
  return std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm) ? std::string(buf) : "";
}

// A relative link to an output (percent-encoded; the page and the files share --out).
std::string href(const std::filesystem::path& file, const std::filesystem::path& page_dir) {
  const std::filesystem::path rel = page_dir.empty() ? file.filename() : file.lexically_relative(page_dir);
  std::string o;
  for (unsigned char c : rel.generic_string()) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~' || c == '/') {
      o += static_cast<char>(c);
    } else {
      static const char* const hex = "0123456789ABCDEF";
      o += '%';
      o += hex[c >> 4];
      o += hex[c & 15];
    }
  }
  return o;
}

// ---------------------------------------------------------------------------------------------
// The part's picture.

// A bounded body's surface in its own frame (metres); nullopt for a plane.
std::optional<geometry::TriangleMesh> own_surface(const geometry::Shape& shape) {
  if (const auto* m = shape.triangle_mesh()) return m->mesh();
  if (const auto* c = dynamic_cast<const geometry::CadShape*>(&shape)) return c->triangulation().mesh();
  if (const auto* e = shape.analytic_ellipsoid()) {
    const Eigen::Vector3d& a = e->semi_axes_m();
    return geometry::make_ellipsoid_mesh(a.x(), a.y(), a.z(), 3);
  }
  return std::nullopt;
}

void append(plot::PartSurface& s, const geometry::TriangleMesh& m, const geometry::Pose& pose, const Eigen::Vector3d& shift) {
  const int base = static_cast<int>(s.vertices.size());
  for (const auto& v : m.vertices_m) s.vertices.push_back(pose.to_world(v) + shift);
  for (const auto& t : m.triangles) s.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

std::string rotation_text(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  if (std::abs(aa.angle()) < 1e-9) return "not rotated (own axes = world axes)";
  return "rotated " + plot::format_number(aa.angle() * 180.0 / M_PI, 3) + " deg about (" +
         plot::format_number(aa.axis().x(), 3) + ", " + plot::format_number(aa.axis().y(), 3) + ", " +
         plot::format_number(aa.axis().z(), 3) + ")";
}

// The part drawing of impact `ir` (both bounded bodies as they touch; a plane as the floor), or
// empty when no body can be drawn. `caption` gets what it shows.
std::string part_picture(const ImpactSpec& spec, const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal,
                         const Eigen::Vector3d& impactor_translation_m,
                         const std::map<std::string, contact::PreparedBody>& bodies, LengthUnit unit, std::string& caption) {
  const auto t = bodies.find(spec.target);
  const auto i = bodies.find(spec.impactor);
  if (t == bodies.end() || i == bodies.end() || !t->second.shape || !i->second.shape) return "";
  const auto ts = own_surface(*t->second.shape);
  const auto is = own_surface(*i->second.shape);
  if (!ts && !is) return "";
  plot::PartSurface surface;
  if (ts) append(surface, *ts, t->second.pose, Eigen::Vector3d::Zero());
  if (is) append(surface, *is, i->second.pose, impactor_translation_m);
  plot::PartMarkers mk;
  const Eigen::Vector3d n = normal;  // the target's outward normal
  mk.contact_point = point_m;
  // The drawn part: the target, unless it is the plane (then the impactor; the normal and the
  // force are the part's own).
  const bool part_is_target = ts.has_value();
  const contact::PreparedBody& part = part_is_target ? t->second : i->second;
  mk.normal = part_is_target ? n : Eigen::Vector3d(-n);
  mk.force = -*mk.normal;  // the other body pushes the part inwards along its normal
  if (!ts || !is) mk.floor_normal = -*mk.normal;
  mk.frame = part.pose.rotation;
  mk.frame_origin = part.centroid_world_m() + (part_is_target ? Eigen::Vector3d::Zero() : impactor_translation_m);
  plot::PartDrawingOptions o;
  o.title = "Impact '" + spec.name + "': " + part.name + (ts && is ? " and " + (part_is_target ? i : t)->second.name : std::string()) +
            " as they touch";
  o.length_unit = to_string(unit);
  o.length_unit_size = metres_per(unit);
  caption = "'" + part.name + "' as it touches " + (ts && is ? "'" : "the plane '") +
            (part_is_target ? i : t)->second.name + "' (world frame; " + rotation_text(part.pose.rotation) +
            "): contact point at " + vec3(point_m, 1.0 / metres_per(unit), 3) + " " + to_string(unit) +
            ", the part's outward normal n, the force on the part along -n" +
            (mk.floor_normal ? ", the floor through the contact point" : "") +
            ". Drawn from the part's triangles (flat shading; decimated above " + std::to_string(o.max_triangles) +
            " triangles).";
  return plot::to_svg(plot::part_drawing(surface, mk, o));
}

// The boundary of a tetrahedral mesh: faces of one tetrahedron only, turned away from its fourth node.
plot::PartSurface boundary(const fem_export::TetMesh& m) {
  std::vector<std::pair<std::array<int, 3>, std::array<int, 3>>> faces;  // sorted key, oriented face
  faces.reserve(m.tets.size() * 4);
  for (const auto& t : m.tets) {
    static constexpr int kFace[4][4] = {{1, 2, 3, 0}, {0, 3, 2, 1}, {0, 1, 3, 2}, {0, 2, 1, 3}};
    for (const auto& f : kFace) {
      std::array<int, 3> tri{t[f[0]], t[f[1]], t[f[2]]};
      const Eigen::Vector3d& a = m.nodes_m[static_cast<std::size_t>(tri[0])];
      const Eigen::Vector3d nrm = (m.nodes_m[static_cast<std::size_t>(tri[1])] - a).cross(m.nodes_m[static_cast<std::size_t>(tri[2])] - a);
      if (nrm.dot(m.nodes_m[static_cast<std::size_t>(t[f[3]])] - a) > 0) std::swap(tri[1], tri[2]);
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      faces.push_back({key, tri});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  plot::PartSurface s;
  s.vertices = m.nodes_m;
  for (std::size_t k = 0; k < faces.size();) {
    std::size_t e = k + 1;
    while (e < faces.size() && faces[e].first == faces[k].first) ++e;
    if (e == k + 1) s.triangles.push_back(faces[k].second);
    k = e;
  }
  return s;
}

// The von Mises field at the governing peak's time on the FE mesh's surface.
// What the stress picture's caption says about plastic strain (the picture shows von Mises).
std::string plastic_caption(const fem_export::StressResult& st) {
  if (!st.plastic) return "Plastic strain: none (the deck's material is linear elastic).";
  const fem_export::PlasticResult& p = *st.plastic;
  if (p.yielded_nodes == 0)
    return "Plastic strain: none above " + g(p.threshold, 3) + " (the deck's material is elastic-plastic).";
  return "Plastic strain: up to " + g(p.max.plastic_strain, 3) + " at " + g(p.max.distance_m * 1e3, 3) +
         " mm from the contact, " + std::to_string(p.yielded_nodes) + " node(s) above " + g(p.threshold, 3) +
         " (the deck's material is elastic-plastic; results.pvd carries PE per increment).";
}

std::string stress_picture(const ImpactReport& ir, std::string& caption) {
  const fem_export::TetMesh& m = ir.fem_deck->mesh;
  const fem_export::StressResult& st = *ir.fem_check->stress;
  if (st.von_mises_at_peak_Pa.size() != m.nodes_m.size() || m.tets.empty()) return "";
  plot::PartSurface s = boundary(m);
  std::vector<double> values = st.von_mises_at_peak_Pa;
  // Under a point load the contact node's stress is not meaningful and dwarfs the rest: the colour
  // scale ends at the verdict's peak, higher values take the top colour.
  const double cap = st.verdict.governing.von_mises_Pa;
  const bool capped = !st.inside_zone_meaningful && cap > 0;
  if (capped)
    for (double& v : values) v = std::min(v, cap);
  plot::PartMarkers mk;
  const auto load = std::find_if(m.node_groups.begin(), m.node_groups.end(), [](const auto& g) { return g.first == "LOAD"; });
  if (load != m.node_groups.end() && load->second >= 0 && static_cast<std::size_t>(load->second) < m.nodes_m.size())
    mk.contact_point = m.nodes_m[static_cast<std::size_t>(load->second)];
  if (st.verdict.governing.node >= 0) {
    mk.peak_point = st.verdict.governing.point_m;
    mk.peak_label = "peak " + plot::format_number(st.verdict.governing.von_mises_Pa * 1e-6, 3) + " MPa";
  }
  // The deck's axes (the target's own frame, the coordinates of mesh.inp and the .vtu files),
  // drawn from the mesh's lowest corner, and the scale bar in the deck's length unit.
  Eigen::Vector3d lo = m.nodes_m.front();
  for (const auto& p : m.nodes_m) lo = lo.cwiseMin(p);
  const LengthUnit unit = st.length_unit;
  mk.frame = Eigen::Matrix3d::Identity();
  mk.frame_origin = lo;
  mk.frame_names = {"x", "y", "z"};
  mk.frame_label = std::string("deck axes x y z (") + to_string(unit) + ")";
  plot::PartDrawingOptions o;
  o.title = "Von Mises stress at t = " + plot::format_number(st.peak_field_time_s * 1e6, 3) + " \xC2\xB5s, impact '" +
            ir.spec->name + "'";
  o.vertex_values = std::move(values);
  o.value_label = "MPa";
  o.value_scale = 1e-6;
  o.length_unit = to_string(unit);
  o.length_unit_size = metres_per(unit);
  caption = "Von Mises stress (MPa) on the FE mesh's surface at the time of the governing peak (t = " +
            plot::format_number(st.peak_field_time_s, 4) + " s), in the deck's frame (the target's own axes x y z, " +
            "as in mesh.inp, lengths in " + to_string(unit) + "), from ccx's .frd" +
            (capped ? "; the colour scale ends at the verdict's peak (" +
                          plot::format_number(cap * 1e-6, 3) +
                          " MPa, outside the contact zone): higher values (the point load's node and its neighbours) take the top colour"
                    : "") +
            ". " + plastic_caption(st);
  return plot::to_svg(plot::part_drawing(s, mk, o));
}

}  // namespace

std::string impact_part_svg(const Scene& scene, const std::string& impact, const Eigen::Vector3d& point_m,
                            const Eigen::Vector3d& normal, std::string& caption) {
  const auto s = std::find_if(scene.impacts.begin(), scene.impacts.end(), [&](const ImpactSpec& i) { return i.name == impact; });
  if (s == scene.impacts.end()) return "";
  const BodySpec& target = scene.body(s->target);
  const BodySpec& impactor = scene.body(s->impactor);
  // The impactor is drawn where it touches only when it is the plane (a floor: a line through the
  // contact point); a moving part would need its travel, which the caller does not have.
  if (!impactor.shape->half_space() || target.shape->half_space()) return "";
  std::map<std::string, contact::PreparedBody> bodies;
  for (const BodySpec* b : {&target, &impactor}) bodies.emplace(b->name, prepare_body(*b, scene));
  return part_picture(*s, point_m, normal, Eigen::Vector3d::Zero(), bodies, scene.length_unit, caption);
}

namespace {

// A plastic deck's verdict: the equivalent plastic strain read back (fem_export's three verdicts).
ImpactVerdict plastic_verdict(const fem_export::Verdict& fv, const fem_export::PlasticResult& pr) {
  ImpactVerdict v;
  v.word = fem_export::to_string(fv.kind);
  const std::string dent = "; dent " + g(pr.residual_indentation_m * 1e3, 3) + " mm deep, radius " +
                           g(pr.dent_radius_m * 1e3, 3) + " mm (" + pr.contact_law + " law)";
  const auto at = [](const fem_export::PlasticStrainPeak& p) {
    return " at " + vec3(p.point_m, 1e3, 3) + " mm (the deck's frame), " + g(p.distance_m * 1e3, 3) +
           " mm from the contact, t = " + g(p.time_s * 1e6, 3) + " \xC2\xB5s";
  };
  const std::string head = "FEM (CalculiX, elastic-plastic): ";
  if (fv.kind == fem_export::VerdictKind::survives_elastically) {
    v.kind = ImpactVerdict::Kind::survives;
    if (fv.safety_factor > 0) v.safety_factor = fv.safety_factor;
    v.basis = head + "no equivalent plastic strain above " + g(pr.threshold, 3) + "; peak von Mises " +
              g(fv.governing.von_mises_Pa / 1e6, 3) + " MPa " + fv.governing_region + dent;
    // The law dents the part where the FE model shows no plastic strain: the mesh does not
    // resolve the dent (a point load, elements larger than it), which the reader must know.
    if (pr.residual_indentation_m > 0)
      v.basis += ": the law's contact is plastic where the FE mesh shows none (elements larger than the dent; refine "
                 "the mesh at the contact to resolve it)";
  } else if (fv.kind == fem_export::VerdictKind::local_plastic_strain) {
    v.kind = ImpactVerdict::Kind::survives;
    v.basis = head + "max equivalent plastic strain " + g(pr.max.plastic_strain, 3) + at(pr.max) + ", within the " +
              g(pr.plastic_zone_radius_m * 1e3, 3) + " mm plastic zone; " + std::to_string(pr.yielded_nodes) +
              " node(s) above " + g(pr.threshold, 3) + dent;
  } else {
    v.kind = ImpactVerdict::Kind::yields;
    v.basis = head + "equivalent plastic strain " + g(pr.beyond_zone.plastic_strain, 3) + at(pr.beyond_zone) +
              ", beyond the " + g(pr.plastic_zone_radius_m * 1e3, 3) + " mm plastic zone (max " +
              g(pr.max.plastic_strain, 3) + ")" + dent;
  }
  return v;
}

}  // namespace

// The FEM verdict's mesh convergence line (ImpactVerdict::convergence).
void state_convergence(const fem_export::CheckResult& check, ImpactVerdict& v) {
  if (!check.convergence) {
    v.convergence = "Mesh convergence: not checked (one mesh; [outputs.fem] convergence = \"two-meshes\" checks it)";
    return;
  }
  const fem_export::MeshConvergence& c = *check.convergence;
  v.convergence = "Mesh convergence: " + fem_export::format_convergence(c);
  if (!c.established) {
    v.word += " (convergence not established)";
  } else if (!c.holds) {
    v.word += " (moves with the mesh)";
  }
}

ImpactVerdict impact_verdict(const ImpactReport& ir) {
  ImpactVerdict v;
  if (ir.fem_check && ir.fem_check->stress && ir.fem_check->stress->verdict.yield_strength_Pa) {
    const fem_export::StressResult& st = *ir.fem_check->stress;
    const fem_export::Verdict& fv = st.verdict;
    if (st.plastic) {
      v = plastic_verdict(fv, *st.plastic);
      state_convergence(*ir.fem_check, v);
      return v;
    }
    v.kind = fv.kind == fem_export::VerdictKind::yields ? ImpactVerdict::Kind::yields : ImpactVerdict::Kind::survives;
    v.word = fem_export::to_string(fv.kind);
    v.safety_factor = fv.safety_factor;
    v.basis = "FEM (CalculiX): yield strength " + g(*fv.yield_strength_Pa / 1e6, 3) + " MPa over the peak von Mises " +
              g(fv.governing.von_mises_Pa / 1e6, 3) + " MPa " + fv.governing_region + ", at " +
              vec3(fv.governing.point_m, 1e3, 3) + " mm (the deck's frame), t = " + g(fv.governing.time_s * 1e6, 3) +
              " \xC2\xB5s";
    state_convergence(*ir.fem_check, v);
    return v;
  }
  const collision::ValidityReport& r = ir.validity;
  if (r.peak_pressure_over_yield_onset && *r.peak_pressure_over_yield_onset > 0) {
    const double ratio = *r.peak_pressure_over_yield_onset;
    v.kind = ratio > 1.0 ? ImpactVerdict::Kind::yields : ImpactVerdict::Kind::survives;
    v.word = ratio > 1.0 ? "yields" : "survives";
    v.safety_factor = 1.0 / ratio;
    v.basis = "Hertz: yield onset 1.60 sigma_y = " + g(r.yield_onset_pressure_Pa.value_or(0) / 1e6, 3) +
              " MPa of the " + r.yielding_body + " over the peak contact pressure p0 = " + g(r.peak_pressure_Pa / 1e6, 3) +
              " MPa (Johnson; no FEM stresses)";
    return v;
  }
  v.basis = "no yield strength given: no verdict";
  return v;
}

std::string report_html(const Scene& scene, const RunReport& rep, const std::vector<std::vector<ReportPicture>>& pictures,
                        const std::map<std::string, contact::PreparedBody>* bodies) {
  const std::string name = scene.file.empty() ? std::string("(scene text)") : scene.file.filename().string();
  plot::HtmlPage page("impactdeck run: " + name);

  // A failed self-check first, each named: the page and the files beside it are its evidence.
  if (const auto failed = failed_checks(rep); !failed.empty()) {
    page.html("<p id=\"failed\" class=\"verdict fail\">" +
              plot::html_escape("FAILED: " + std::to_string(failed.size()) +
                                " self-check(s) failed (exit 4); the outputs of this run are the evidence") +
              "</p>");
    std::vector<std::vector<std::string>> rows;
    for (const auto& f : failed) {
      rows.push_back({f.impact, f.name, f.value ? g(*f.value, 3) : "-", f.limit ? g(*f.limit, 3) : "-", f.reason});
    }
    page.table({"impact", "failed check", "value", "limit", "reason"}, rows);
  }

  // Then the verdict, over the impacts and the sequences' impacts with an FEM deck: the worst
  // impact's words (yielding before surviving, plastic strain before none), with the smallest
  // safety factor where one exists.
  std::vector<const ImpactReport*> judged;
  for (const auto& ir : rep.impacts) judged.push_back(&ir);
  for (const auto& sr : rep.sequences)
    for (std::size_t i : sr.fem_impacts) judged.push_back(&sr.impacts[i]);
  ImpactVerdict::Kind overall = ImpactVerdict::Kind::none;
  std::string overall_word;
  int overall_rank = -1;
  std::optional<double> worst;
  std::vector<std::vector<std::string>> verdict_rows;
  std::string governing, convergence;
  for (const ImpactReport* p : judged) {
    const ImpactReport& ir = *p;
    const ImpactVerdict v = impact_verdict(ir);
    std::string word = v.word;
    if (v.kind != ImpactVerdict::Kind::none) {
      const int rank = (v.kind == ImpactVerdict::Kind::yields ? 2 : 0) + (v.safety_factor ? 0 : 1);
      const bool smaller = v.safety_factor && (!worst || *v.safety_factor < *worst);
      if (rank > overall_rank || (rank == overall_rank && smaller)) {
        overall_rank = rank;
        overall = v.kind;
        overall_word = v.word;
        governing = "impact '" + ir.spec->name + "': " + v.basis;
        convergence = v.convergence;
      }
      if (smaller) worst = v.safety_factor;
      word = outcome(v.kind == ImpactVerdict::Kind::survives, word);
    }
    verdict_rows.push_back({ir.spec->name, word, v.safety_factor ? g(*v.safety_factor, 4) : "", v.basis});
  }
  std::string verdict = overall == ImpactVerdict::Kind::none ? "Verdict: none (no yield strength given)"
                                                              : "Verdict: " + overall_word;
  if (worst) verdict += " (smallest safety factor " + g(*worst, 4) + ")";
  page.html("<p id=\"verdict\" class=\"verdict " +
            std::string(overall == ImpactVerdict::Kind::yields ? "fail" : overall == ImpactVerdict::Kind::survives ? "pass" : "") +
            "\">" + plot::html_escape(verdict) + "</p>");
  if (!governing.empty()) page.html("<p id=\"governing\" class=\"governing\">" + plot::html_escape(governing) + "</p>");
  if (!convergence.empty()) {
    page.html("<p id=\"convergence\" class=\"governing\">" + plot::html_escape(convergence) + "</p>");
  }
  page.paragraph(rep.all_checks_passed() ? "Every self-check passed." : "A self-check failed (see below).",
                 rep.all_checks_passed() ? "pass" : "fail");
  page.table({"impact", "verdict", "safety factor", "basis"}, verdict_rows);

  // Warnings, each once: the run's list already holds every impact's validity warnings.
  std::vector<std::string> warnings;
  std::set<std::string> seen;
  for (const auto& w : rep.warnings)
    if (seen.insert(w).second) warnings.push_back(w);
  page.heading("Validity warnings");
  page.html("<div id=\"warnings\">");
  if (warnings.empty()) page.paragraph("None: every quantity within the Hertz model's limits.");
  for (const auto& w : warnings) page.paragraph(w, "warning");
  page.html("</div>");

  // The part as it is hit, and the stresses on it.
  bool part_heading = false;
  for (std::size_t k = 0; k < rep.impacts.size(); ++k) {
    const ImpactReport& ir = rep.impacts[k];
    std::string caption, svg;
    if (bodies)
      svg = part_picture(*ir.spec, ir.contact.point_m, ir.contact.normal, ir.contact.impactor_translation_m, *bodies,
                         rep.output_length_unit, caption);
    std::string field_caption, field;
    if (ir.fem_deck && ir.fem_check && ir.fem_check->stress) field = stress_picture(ir, field_caption);
    if ((svg.empty() && field.empty())) continue;
    if (!part_heading) page.heading("The part");
    part_heading = true;
    if (!svg.empty())
      page.html("<figure class=\"part-drawing\" id=\"part-drawing-" + std::to_string(k) + "\">" + plot::inline_svg(svg) +
                "<figcaption>" + plot::html_escape(caption) + "</figcaption></figure>");
    if (!field.empty())
      page.html("<figure class=\"stress-field\" id=\"stress-field-" + std::to_string(k) + "\">" + plot::inline_svg(field) +
                "<figcaption>" + plot::html_escape(field_caption) + "</figcaption></figure>");
  }

  // Inputs.
  page.heading("Inputs");
  page.table({"scene", "length unit (input)", "output length unit", "modulus convention"},
             {{scene.file.string(), to_string(scene.length_unit), to_string(rep.output_length_unit),
               scene.modulus_convention == collision::ModulusConvention::hertz ? "hertz" : "paper"}});
  std::vector<std::vector<std::string>> mats;
  for (const auto& [key, m] : scene.materials) {
    mats.push_back({key, g(m.elastic.youngs_modulus_Pa / 1e9) + " GPa", g(m.elastic.poisson_ratio),
                    m.density_kg_m3 ? g(*m.density_kg_m3) + " kg/m3" : "-",
                    m.yield_strength_Pa ? g(*m.yield_strength_Pa / 1e6) + " MPa" : "-"});
  }
  page.heading("Materials", 3);
  page.table({"material", "E", "Poisson ratio", "density", "yield strength"}, mats);
  std::vector<std::vector<std::string>> body_rows;
  for (const auto& b : scene.bodies) {
    const std::string shape = b.shape->kind() + b.shape->describe([](double v) { return g(v); });
    body_rows.push_back({b.name, shape, b.material, b.fixed ? "fixed" : b.mass_kg ? g(*b.mass_kg) + " kg" : "density x volume",
                      vec3(b.position_m) + " m", vec3(b.velocity_m_s) + " m/s"});
  }
  page.heading("Bodies", 3);
  page.table({"body", "shape", "material", "mass", "position", "velocity"}, body_rows);
  page.preformatted("Scene file", scene_text(scene));

  // Results per impact.
  for (std::size_t k = 0; k < rep.impacts.size(); ++k) {
    const ImpactReport& ir = rep.impacts[k];
    const collision::ImpactResult& r = ir.result;
    const auto& c = r.history.compression;
    page.heading("Impact '" + ir.spec->name + "': " + ir.spec->impactor + " hits " + ir.spec->target);
    page.table({"quantity", "value"},
               {{"contact point (world)", vec3(ir.contact.point_m) + " m"},
                {"contact normal", vec3(ir.contact.normal)},
                {"approach velocity", g(r.approach_velocity_m_s) + " m/s"},
                {"reduced mass", g(r.reduced_mass_kg) + " kg"},
                {"effective radius R*", g(r.effective_radius_m) + " m"},
                {"effective modulus E*", g(r.effective_modulus_Pa / 1e9) + " GPa"},
                {"contact law", ir.contact_law},
                {"restitution R", g(r.restitution.coefficient)},
                {"max indentation", g(c.max_indentation_m) + " m"},
                {"dent (both bodies)", g(r.history.law_result.residual_indentation_m) + " m"},
                {"max force", g(c.max_force_N) + " N"},
                {"compression time", g(c.compression_time_s) + " s"},
                {"contact time", g(r.history.contact_time_s()) + " s"},
                {"impulse", g(r.history.impulse_total_Ns()) + " N s"},
                {"peak contact pressure p0", g(ir.validity.peak_pressure_Pa / 1e6) + " MPa"}});
    const auto& ch = r.checks;
    std::vector<std::vector<std::string>> checks = {
        {"impulse, Eq. 31: |numerical Pi1 - m_w v_w| / (m_w v_w)",
         check_row_value(ch.impulse_relative_error, ch.thresholds.impulse_relative)},
        {"energy, Eq. 32: |kinetic loss - Carnot loss| / Carnot loss",
         check_row_value(ch.energy_relative_error, ch.thresholds.energy_relative)},
        {"validity: indentation / R*", outcome(ir.validity.indentation_over_radius <= ir.validity.limits.max_indentation_over_radius,
                                               g(ir.validity.indentation_over_radius, 3) + " (limit " +
                                                   g(ir.validity.limits.max_indentation_over_radius, 3) + ")")},
        {"validity: contact size / R_min",
         outcome(ir.validity.contact_size_over_radius <= ir.validity.limits.max_contact_size_over_radius,
                 g(ir.validity.contact_size_over_radius, 3) + " (limit " +
                     g(ir.validity.limits.max_contact_size_over_radius, 3) + ")")}};
    if (ir.table) {
      checks.push_back({"force table impulse (trapezoids) vs exact",
                        check_row_value(ir.table->impulse_relative_error, ir.table->impulse_tolerance)});
    }
    if (ir.fem_deck) {
      const auto& bc = ir.fem_deck->body_check;
      checks.push_back({"FEM body: volume", check_row_value(std::abs(bc.volume_relative_error), bc.tolerances.volume)});
      checks.push_back({"FEM body: mass", check_row_value(std::abs(bc.mass_relative_error), bc.tolerances.mass)});
      checks.push_back({"FEM body: inertia", check_row_value(bc.inertia_relative_error, bc.tolerances.inertia)});
      checks.push_back({"FEM mesh: min gamma", outcome(bc.min_gamma >= bc.tolerances.min_gamma,
                                                       g(bc.min_gamma, 3) + " (floor " + g(bc.tolerances.min_gamma, 3) + ")")});
    }
    if (ir.fem_check) {
      const auto& fc = *ir.fem_check;
      checks.push_back({"FEM (ccx): linear momentum vs impulse",
                        check_row_value(fc.linear_momentum_relative_error, fc.linear_tolerance)});
      if (fc.angular_momentum_relative_error)
        checks.push_back({"FEM (ccx): angular momentum", check_row_value(*fc.angular_momentum_relative_error, fc.angular_tolerance)});
      if (fc.model_linear_velocity_relative_error)
        checks.push_back({"FEM vs rigid model: velocity jump",
                          check_row_value(*fc.model_linear_velocity_relative_error, fc.model_linear_velocity_tolerance)});
      if (fc.model_angular_velocity_relative_error)
        checks.push_back({"FEM vs rigid model: spin jump",
                          check_row_value(*fc.model_angular_velocity_relative_error, fc.model_angular_velocity_tolerance)});
    }
    if (ir.compare) {
      if (const ContactLevel* f = ir.compare->finest()) {
        checks.push_back({"full contact (ccx): F_max vs analytic",
                          check_row_value(std::abs(f->max_force_relative_difference), ir.compare->threshold)});
      }
    }
    page.heading("Checks", 3);
    page.table({"check", "relative error vs tolerance"}, checks);
    if (ir.fem_deck) {
      page.paragraph("FEM deck: " + ir.fem_deck->folder.string() + " (" + std::to_string(ir.fem_deck->quality.node_count) +
                     " nodes, " + std::to_string(ir.fem_deck->quality.tet_count) + " tetrahedra; units " +
                     ir.fem_deck->units.description() + ")");
    }
    if (ir.fem_check && ir.fem_check->stress) page.preformatted("FEM stresses", fem_export::format_stress(*ir.fem_check->stress));
    if (ir.compare) page.preformatted("Full-contact comparison (compare_contact)", format_compare(*ir.compare));

    page.heading("Pictures", 3);
    plot::ForcePlotOptions po;
    po.title = "Contact force, impact '" + ir.spec->name + "': " + ir.spec->impactor + " hits " + ir.spec->target;
    page.figure(plot::inline_svg(plot::to_svg(plot::force_time_drawing(r.history, po))),
                "Contact force F(t) (the paper's Fig. 5 / 11)");
    if (k < pictures.size()) {
      for (const ReportPicture& p : pictures[k]) {
        page.figure(p.svg.empty() ? plot::png_img(p.png, p.caption) : plot::inline_svg(p.svg), p.caption);
      }
    }
  }

  // Everything else, as `run --json` gives it.
  // Provenance: the version, the inputs' date and hashes. The page holds no clock time (the same
  // inputs give the same bytes, docs/reliability.md): its date is the newest input's.
  page.heading("Provenance");
  // A part file is read once, by its loader (docs/architecture.md, one_read_test): its hash is not
  // taken here; the scene's text is (the page shows it too).
  std::vector<std::filesystem::path> inputs;
  if (!scene.file.empty()) inputs.push_back(scene.file);
  for (const auto& b : scene.bodies)
    for (const auto& f : b.shape->input_files())
      if (std::find(inputs.begin(), inputs.end(), f) == inputs.end()) inputs.push_back(f);
  std::string newest;
  std::vector<std::vector<std::string>> hashes;
  for (const auto& f : inputs) {
    const std::string when = modified_utc(f);
    newest = std::max(newest, when);
    hashes.push_back({f.string(), when.empty() ? "-" : when,
                      f == scene.file ? sha256_file(f) : "(not hashed: a part file is read once, by its loader)"});
  }
  page.html("<p id=\"provenance\">impactdeck " + plot::html_escape(kVersion) + "; inputs dated " +
            plot::html_escape(newest.empty() ? std::string("(unknown)") : newest) +
            " (the newest input file's modification time)</p>");
  page.table({"input file", "modified", "SHA-256"}, hashes);

  // Drop sequences: the picture of height and F_max against time, and every impact.
  for (const auto& sr : rep.sequences) {
    const auto& res = sr.result;
    page.heading("Drop sequence '" + sr.spec->name + "'");
    std::string summary = std::to_string(res.bounces.size()) + " impact(s) of '" + sr.spec->body + "' on '" +
                          sr.spec->floor + "', stopped: " + sequence::to_string(res.stop);
    if (res.worst_impact_index >= 0) {
      summary += "; worst impact " + std::to_string(res.worst_impact_index) + " (" + res.worst_impact_reason + ")";
    }
    page.paragraph(summary);
    page.figure(detail::sequence_svg(sr, rep.output_length_unit),
                "Height of the lowest point above the floor and F_max of each impact against time");
    std::vector<std::vector<std::string>> rows;
    for (std::size_t i = 0; i < res.bounces.size(); ++i) {
      const auto& b = res.bounces[i];
      const double f = b.max_force_N();
      rows.push_back({std::to_string(i), g(b.time_s, 6), g(b.approach_velocity_m_s, 5),
                      std::isfinite(f) ? g(f, 5) : "not applicable", g(b.normal_impulse_Ns, 5), g(b.restitution, 4),
                      vec3(b.point_own_m)});
    }
    page.table({"impact", "time (s)", "approach speed (m/s)", "F_max (N)", "normal impulse (N s)", "restitution",
                "point, body frame (m)"},
               rows);
    // Its FEM decks (fem = "worst" or "all"): the worst impact's verdict first, as a single impact's.
    if (sr.fem_requested) {
      std::vector<std::vector<std::string>> fem_rows;
      for (std::size_t i : sr.fem_impacts) {
        const ImpactReport& ir = sr.impacts[i];
        const ImpactVerdict v = impact_verdict(ir);
        const bool worst = static_cast<int>(i) == res.worst_impact_index;
        if (worst) {
          page.html("<p class=\"sequence-verdict\" id=\"sequence-verdict-" + std::to_string(&sr - rep.sequences.data()) +
                    "\">" + plot::html_escape("Worst impact " + std::to_string(i) + ": " + v.word +
                                               (v.safety_factor ? " (safety factor " + g(*v.safety_factor, 4) + ")" : "") +
                                               "; " + v.basis) +
                    "</p>");
        }
        fem_rows.push_back({std::to_string(i) + (worst ? " (worst)" : ""),
                            ir.fem_deck ? ir.fem_deck->folder.string() : "-",
                            v.kind == ImpactVerdict::Kind::none ? v.word
                                                                : outcome(v.kind == ImpactVerdict::Kind::survives, v.word),
                            v.safety_factor ? g(*v.safety_factor, 4) : "", v.basis});
      }
      for (const auto& n : sr.fem_not_meshed) fem_rows.push_back({std::to_string(n.index), "none", "no deck", "", n.reason});
      page.table({"impact", "FEM deck", "verdict", "safety factor", "basis"}, fem_rows);
    }
  }

  page.heading("Files written");
  std::filesystem::path page_dir;
  for (const auto& f : rep.files_written)
    if (f.filename() == "report.html") page_dir = f.parent_path();
  // Every file of the output folder: the run's list, the force tables' JSON sidecars, and the
  // solver's results in the deck folders.
  std::vector<std::filesystem::path> outputs = rep.files_written;
  for (const ImpactReport* p : judged) {
    const ImpactReport& ir = *p;
    if (ir.table_path && std::find(outputs.begin(), outputs.end(), csv_sidecar_path(*ir.table_path)) == outputs.end())
      outputs.push_back(csv_sidecar_path(*ir.table_path));
    if (!ir.fem_check) continue;
    std::vector<std::filesystem::path> more = ir.fem_check->solver_files;
    if (ir.fem_check->stress) more.insert(more.end(), ir.fem_check->stress->files.begin(), ir.fem_check->stress->files.end());
    for (const auto& f : more)
      if (std::find(outputs.begin(), outputs.end(), f) == outputs.end()) outputs.push_back(f);
  }
  std::string links = "<ul id=\"files\">\n";
  for (const auto& f : outputs)
    links += "<li><a href=\"" + href(f, page_dir) + "\">" + plot::html_escape(f.string()) + "</a></li>\n";
  page.html(links + "</ul>");
  // The page is the same bytes for the same inputs (a killed run's page is old or new, never a
  // third version; docs/reliability.md): wall times stay in `run --json`.
  nlohmann::json doc = to_json(scene, rep);
  doc.erase("stage_times_s");
  auto drop_wall_time = [](nlohmann::json& i) {
    if (i.contains("fem") && i["fem"].contains("check") && i["fem"]["check"].is_object())
      i["fem"]["check"].erase("solver_wall_time_s");
  };
  for (auto& i : doc["impacts"]) drop_wall_time(i);
  if (doc.contains("sequences"))
    for (auto& q : doc["sequences"])
      for (auto& i : q["impacts"]) drop_wall_time(i);
  page.preformatted("The run's JSON document (run --json, without the wall times)", doc.dump(2));
  return page.str();
}

}  // namespace impactdeck::scene
