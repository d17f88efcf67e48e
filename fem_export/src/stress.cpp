// Stresses of a solver run, from its nodal results (see stress.hpp).
#include "impactdeck/fem_export/stress.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <map>
#include <iomanip>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/plot/stress_plot.hpp"
#include "impactdeck/common/json_number.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {


double von_mises(const double s[6]) {
  const double a = s[0] - s[1], b = s[1] - s[2], c = s[2] - s[0];
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

std::string mm_text(const Eigen::Vector3d& p_m) {
  std::ostringstream s;
  s << std::setprecision(4) << "(" << p_m.x() * 1e3 + 0.0 << ", " << p_m.y() * 1e3 + 0.0 << ", "
    << p_m.z() * 1e3 + 0.0 << ") mm";
  return s.str();
}

// A point in `unit` (the deck's length unit), rounded to 3 significant digits: a picture's legend,
// the CSV sidecar's notes.
std::string legend_point(const Eigen::Vector3d& p_m, LengthUnit unit) {
  const Eigen::Vector3d p = p_m / metres_per(unit);
  return "(" + plot::format_number(p.x(), 3) + ", " + plot::format_number(p.y(), 3) + ", " +
         plot::format_number(p.z(), 3) + ") " + to_string(unit);
}

// The end of a VTK XML UnstructuredGrid piece (written by hand: we do not link VTK): the mesh's
// points (times `per_m`, the deck's length unit), its tetrahedra (VTK type 10), the closing tags.
void vtu_mesh_and_end(std::ostream& o, const TetMesh& m, double per_m) {
  o << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : m.nodes_m) {
    const Eigen::Vector3d x = p * per_m;
    o << x.x() << " " << x.y() << " " << x.z() << "\n";
  }
  o << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : m.tets) o << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
  o << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < m.tets.size(); ++e) o << 4 * (e + 1) << "\n";
  o << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < m.tets.size(); ++e) o << "10\n";
  o << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

// The FieldData of every .vtu of the deck folder: its unit system (the deck's) as strings
// unit_system, length_unit, stress_unit (VTK String arrays: each value's bytes, 0-terminated) and as
// factors metres_per_length_unit, pascals_per_stress_unit. The caller closes the FieldData.
void vtu_unit_fields(std::ostream& o, const DeckUnits& u) {
  auto text = [&](const char* key, const std::string& value) {
    o << "<DataArray type=\"String\" Name=\"" << key << "\" NumberOfTuples=\"1\" format=\"ascii\">";
    for (unsigned char ch : value) o << static_cast<int>(ch) << " ";
    o << "0</DataArray>\n";
  };
  o << "<FieldData>\n";
  text("unit_system", u.name());
  text("length_unit", to_string(u.length));
  text("stress_unit", u.stress_unit());
  o << "<DataArray type=\"Float64\" Name=\"metres_per_length_unit\" NumberOfTuples=\"1\" format=\"ascii\">"
    << metres_per(u.length) << "</DataArray>\n"
    << "<DataArray type=\"Float64\" Name=\"pascals_per_stress_unit\" NumberOfTuples=\"1\" format=\"ascii\">"
    << 1.0 / u.per_Pa() << "</DataArray>\n";
}

}  // namespace

const char* to_string(VerdictKind k) {
  switch (k) {
    case VerdictKind::survives: return "survives";
    case VerdictKind::yields: return "yields";
    case VerdictKind::no_yield_strength: return "no yield strength given";
    case VerdictKind::survives_elastically: return "survives elastically";
    case VerdictKind::local_plastic_strain: return "survives with local plastic strain";
    case VerdictKind::yields_beyond_contact: return "yields beyond the contact zone";
  }
  return "?";
}

StressResult read_stresses(std::shared_ptr<const NodalResults> results, const TetMesh& mesh, const StressInputs& in) {
  const std::string where = results->file().string();
  const std::size_t n = mesh.nodes_m.size();
  if (in.load_node < 0 || static_cast<std::size_t>(in.load_node) >= n) {
    throw InputError(where, "LOAD", "load node is not a node of the mesh");
  }
  StressResult r;
  r.results = results;
  r.end_time_s = in.end_time_s;
  r.length_unit = in.length_unit;
  const DeckUnits units{in.length_unit};
  r.contact_zone_radius_m = in.contact_zone_radius_m;
  r.inside_zone_meaningful = in.patch_load;
  const Eigen::Vector3d c = mesh.nodes_m[in.load_node];
  std::vector<char> inside(n, 0);
  for (std::size_t i = 0; i < n; ++i) inside[i] = (mesh.nodes_m[i] - c).norm() <= in.contact_zone_radius_m;
  r.node_peak_Pa.assign(n, 0.0);
  r.node_peak_time_s.assign(n, 0.0);
  r.von_mises_at_peak_Pa.assign(n, 0.0);
  r.displacement_at_peak_m.assign(n, Eigen::Vector3d::Zero());
  for (const auto& [name, node] : in.probes) r.probes.push_back({name, node, mesh.nodes_m.at(node), 0, 0, {}});
  r.load = {"LOAD", in.load_node, c, 0, 0, {}};

  // One pass: each output time has a DISP block then a STRESS block (ccx 2.20); the displacement
  // of the current time is kept until its stresses are read.
  std::vector<Eigen::Vector3d> disp(n, Eigen::Vector3d::Zero());
  std::vector<double> vm(n, 0.0);
  std::vector<char> seen(n, 0);
  std::optional<NodalField> block;
  double t = 0, governing_best = -1;
  // Plastic decks: each output time's PE block (after its STRESS block) updates the peaks.
  std::vector<double> pe(n, 0.0);
  bool pe_seen = false;
  PlasticResult plastic;
  plastic.plastic_zone_radius_m = in.plastic_zone_radius_m;
  if (in.plastic) r.node_peak_plastic_strain.assign(n, 0.0);
  auto finish_pe = [&] {
    pe_seen = true;
    for (std::size_t i = 0; i < n; ++i) {
      if (pe[i] <= r.node_peak_plastic_strain[i]) continue;
      r.node_peak_plastic_strain[i] = pe[i];
      const double dist = (mesh.nodes_m[i] - c).norm();
      PlasticStrainPeak now{pe[i], t, static_cast<int>(i), mesh.nodes_m[i], dist};
      if (pe[i] > plastic.max.plastic_strain) plastic.max = now;
      if (dist > in.plastic_zone_radius_m && pe[i] > plastic.beyond_zone.plastic_strain) plastic.beyond_zone = now;
    }
  };
  bool skip = false;
  auto finish_stress = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      if (!seen[i]) throw InputError(where, "time " + std::to_string(t), "stress block misses node " + std::to_string(i + 1));
    }
    r.time_s.push_back(t);
    for (auto& p : r.probes) p.von_mises_Pa.push_back(vm[p.node]);
    r.load.von_mises_Pa.push_back(vm[in.load_node]);
    double out_max = -1, in_max = -1;
    int out_node = -1, in_node = -1;
    for (std::size_t i = 0; i < n; ++i) {
      if (vm[i] > r.node_peak_Pa[i]) r.node_peak_Pa[i] = vm[i], r.node_peak_time_s[i] = t;
      if (inside[i]) {
        if (vm[i] > in_max) in_max = vm[i], in_node = static_cast<int>(i);
      } else if (vm[i] > out_max) {
        out_max = vm[i], out_node = static_cast<int>(i);
      }
    }
    auto update = [&](VonMisesPeak& p, double v, int node) {
      if (node >= 0 && v > p.von_mises_Pa) p = {v, t, node, mesh.nodes_m[node]};
    };
    update(r.outside_zone, out_max, out_node);
    r.outside_zone_history_Pa.push_back(std::max(out_max, 0.0));
    r.inside_zone_history_Pa.push_back(std::max(in_max, 0.0));
    update(r.inside_zone, in_max, in_node);
    const double governing = in.patch_load ? std::max(out_max, in_max) : out_max;
    if (in.yield_strength_Pa && governing > *in.yield_strength_Pa && !r.verdict.first_yield_time_s) {
      r.verdict.first_yield_time_s = t;
    }
    if (governing > governing_best) {
      governing_best = governing;
      r.peak_field_time_s = t;
      r.von_mises_at_peak_Pa = vm;
      r.displacement_at_peak_m = disp;
    }
  };
  NodalResultsVisitor visit;
  visit.time = [&](double time_s) {
    t = time_s;
    skip = t > in.end_time_s * (1 + 1e-6);  // the momentum step's increment
  };
  visit.field = [&](NodalField f) {
    block.reset();
    if (skip || (f == NodalField::plastic_strain && !in.plastic)) return false;
    block = f;
    if (f == NodalField::stress) std::fill(seen.begin(), seen.end(), 0);
    if (f == NodalField::plastic_strain) std::fill(pe.begin(), pe.end(), 0.0);
    return true;
  };
  visit.value = [&](std::size_t node, const double* v) {
    if (block == NodalField::displacement) {
      disp[node] = Eigen::Vector3d(v[0], v[1], v[2]) / units.per_m();
    } else if (block == NodalField::plastic_strain) {
      pe[node] = v[0];  // dimensionless
    } else {
      vm[node] = von_mises(v) / units.per_Pa();
      seen[node] = 1;
    }
  };
  visit.end = [&] {
    if (block == NodalField::stress) finish_stress();
    if (block == NodalField::plastic_strain) finish_pe();
    block.reset();
  };
  r.frd_bytes = results->read(visit, n);
  if (r.time_s.empty()) {
    throw InputError(where, "STRESS", "no stress output (the deck requests *EL FILE S; did ccx finish?)");
  }
  auto peak_of = [&](ProbeStress& p) {
    for (std::size_t k = 0; k < r.time_s.size(); ++k) {
      if (p.von_mises_Pa[k] > p.max_von_mises_Pa) p.max_von_mises_Pa = p.von_mises_Pa[k], p.max_von_mises_time_s = r.time_s[k];
    }
  };
  for (auto& p : r.probes) peak_of(p);
  peak_of(r.load);

  Verdict& v = r.verdict;
  v.yield_strength_Pa = in.yield_strength_Pa;
  const bool inside_governs = in.patch_load && r.inside_zone.von_mises_Pa > r.outside_zone.von_mises_Pa;
  v.governing = inside_governs ? r.inside_zone : r.outside_zone;
  v.governing_region = inside_governs ? "inside the contact zone" : "outside the contact zone";
  if (in.yield_strength_Pa) {
    v.safety_factor = v.governing.von_mises_Pa > 0 ? *in.yield_strength_Pa / v.governing.von_mises_Pa : 0.0;
    v.kind = v.governing.von_mises_Pa > *in.yield_strength_Pa ? VerdictKind::yields : VerdictKind::survives;
    if (v.kind == VerdictKind::survives) v.first_yield_time_s.reset();
  }
  if (in.plastic) {
    if (!pe_seen) {
      throw InputError(where, "PE", "no equivalent plastic strain output (a plastic deck requests *EL FILE PEEQ; did ccx finish?)");
    }
    plastic.contact_law = in.contact_law;
    plastic.residual_indentation_m = in.residual_indentation_m;
    plastic.dent_radius_m = in.dent_radius_m;
    for (double e : r.node_peak_plastic_strain) plastic.yielded_nodes += e > plastic.threshold;
    // The verdict rests on the plastic strain: the von Mises of a yielded body is capped by its
    // hardening and says nothing more (its peaks stay reported above).
    v.kind = plastic.beyond_zone.plastic_strain > plastic.threshold ? VerdictKind::yields_beyond_contact
             : plastic.max.plastic_strain > plastic.threshold      ? VerdictKind::local_plastic_strain
                                                                   : VerdictKind::survives_elastically;
    v.first_yield_time_s.reset();
    r.plastic = plastic;
  }
  return r;
}

std::vector<double> read_node_stresses(const NodalResults& results, const DeckUnits& units,
                                       std::vector<ProbeStress>& probes, double end_time_s) {
  const std::string where = results.file().string();
  std::map<std::size_t, std::size_t> wanted;  // 0-based node -> probe
  for (std::size_t k = 0; k < probes.size(); ++k) {
    wanted[static_cast<std::size_t>(probes[k].node) - 1] = k;  // ProbeStress::node is 1-based
    probes[k].von_mises_Pa.clear();
    probes[k].max_von_mises_Pa = probes[k].max_von_mises_time_s = 0;
  }
  std::vector<double> times, vm(probes.size(), 0.0);
  std::vector<char> seen(probes.size(), 0);
  double t = 0;
  bool skip = false;
  NodalResultsVisitor visit;
  visit.time = [&](double time_s) {
    t = time_s;
    skip = t > end_time_s * (1 + 1e-6);
  };
  visit.field = [&](NodalField f) {
    const bool stress = !skip && f == NodalField::stress;
    if (stress) std::fill(seen.begin(), seen.end(), 0);
    return stress;
  };
  visit.node_wanted = [&](std::size_t node) { return wanted.count(node) > 0; };
  visit.value = [&](std::size_t node, const double* sv) {
    const std::size_t k = wanted.at(node);
    vm[k] = von_mises(sv) / units.per_Pa();
    seen[k] = 1;
  };
  visit.end = [&] {
    for (std::size_t k = 0; k < probes.size(); ++k) {
      if (!seen[k]) throw InputError(where, "time " + std::to_string(t), "no stress at " + probes[k].name + "'s node");
      probes[k].von_mises_Pa.push_back(vm[k]);
      if (vm[k] > probes[k].max_von_mises_Pa) probes[k].max_von_mises_Pa = vm[k], probes[k].max_von_mises_time_s = t;
    }
    times.push_back(t);
  };
  results.read(visit, 0);
  if (times.empty() && !probes.empty()) {
    throw InputError(where, "STRESS", "no stress output (the deck requests *EL FILE S; did ccx finish?)");
  }
  return times;
}

void write_stress_files(const fs::path& dir, const TetMesh& m, StressResult& r, const std::string& title) {
  std::vector<const ProbeStress*> series;
  for (const auto& p : r.probes) series.push_back(&p);
  series.push_back(&r.load);

  // Every file in the deck's unit system (DeckUnits): stresses in its stress unit, positions and
  // displacements in its length unit; times in s.
  const DeckUnits units{r.length_unit};
  const double per_m = units.per_m(), per_Pa = units.per_Pa();
  const std::string unit = to_string(r.length_unit), su = units.stress_unit();

  // 1. History CSV.
  const fs::path csv = dir / "von_mises_history.csv";
  write_file_atomically(csv, [&](std::ostream& o) {
    o << "time_s";
    for (const auto* p : series) o << "," << p->name << "_von_mises_" << su;
    o << "\n" << std::setprecision(9);
    for (std::size_t k = 0; k < r.time_s.size(); ++k) {
      o << r.time_s[k];
      for (const auto* p : series) o << "," << p->von_mises_Pa[k] * per_Pa;
      o << "\n";
    }
  });
  {  // Its JSON sidecar: what used to be `#` lines (common/csv_sidecar.hpp).
    std::vector<std::string> columns = {"time_s"};
    std::vector<std::pair<std::string, std::string>> meta = {
        {"title", "von Mises stress (" + su + ") against time (s) at each probe and at the contact node LOAD (impactdeck)"},
        {"unit_system", units.name()}};
    for (const auto* p : series) {
      columns.push_back(p->name + "_von_mises_" + su);
      meta.push_back({p->name, "at " + legend_point(p->point_m, r.length_unit)});
    }
    write_csv_sidecar(csv, columns, meta);
  }

  // 2. VTK XML unstructured grid (ASCII): positions in the deck's length unit, tetrahedra (VTK type 10).
  const fs::path vtu = dir / "von_mises_peak.vtu";
  const std::string peak_name = "von_mises_peak_" + su, at_peak_name = "von_mises_at_peak_" + su,
                    disp_name = "displacement_at_peak_" + unit;
  write_file_atomically(vtu, [&](std::ostream& o) {
    o << std::setprecision(9);
    o << "<?xml version=\"1.0\"?>\n<!-- impactdeck: peak von Mises over time and the fields at the time of the "
         "governing peak, t = " << r.peak_field_time_s << " s, in the deck's units (" << units.name() << "): positions and "
         "displacement in " << unit << ", stresses in " << su << " -->\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n";
    vtu_unit_fields(o, units);
    o << "</FieldData>\n"
      << "<Piece NumberOfPoints=\"" << m.nodes_m.size() << "\" NumberOfCells=\"" << m.tets.size() << "\">\n"
      << "<PointData Scalars=\"" << peak_name << "\" Vectors=\"" << disp_name << "\">\n";
    auto scalars = [&](const std::string& name, const std::vector<double>& v, double scale) {
      o << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (double x : v) o << x * scale << "\n";
      o << "</DataArray>\n";
    };
    scalars(peak_name, r.node_peak_Pa, per_Pa);
    scalars("von_mises_peak_time_s", r.node_peak_time_s, 1.0);
    scalars(at_peak_name, r.von_mises_at_peak_Pa, per_Pa);
    o << "<DataArray type=\"Float64\" Name=\"" << disp_name << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const auto& u : r.displacement_at_peak_m) {
      const Eigen::Vector3d x = u * per_m;
      o << x.x() << " " << x.y() << " " << x.z() << "\n";
    }
    o << "</DataArray>\n</PointData>\n";
    vtu_mesh_and_end(o, m, per_m);
  });

  // 3. Gmsh MSH 2.2 with $NodeData views (open with gmsh; positions in the deck's unit like the .vtu,
  // said in each view's name).
  const fs::path msh = dir / "von_mises_peak.msh";
  write_file_atomically(msh, [&](std::ostream& o) {
    o << std::setprecision(9);
    o << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << m.nodes_m.size() << "\n";
    for (std::size_t i = 0; i < m.nodes_m.size(); ++i) {
      const Eigen::Vector3d x = m.nodes_m[i] * per_m;
      o << i + 1 << " " << x.x() << " " << x.y() << " " << x.z() << "\n";
    }
    o << "$EndNodes\n$Elements\n" << m.tets.size() << "\n";
    for (std::size_t e = 0; e < m.tets.size(); ++e) {
      const auto& t = m.tets[e];
      o << e + 1 << " 4 2 1 1 " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << " " << t[3] + 1 << "\n";
    }
    o << "$EndElements\n";
    auto view = [&](const std::string& name, int comps, const auto& value) {
      o << "$NodeData\n1\n\"" << name << ", positions in " << unit << " (" << units.name() << ")\"\n1\n" << r.peak_field_time_s << "\n3\n0\n" << comps << "\n"
        << m.nodes_m.size() << "\n";
      for (std::size_t i = 0; i < m.nodes_m.size(); ++i) {
        o << i + 1;
        value(o, i);
        o << "\n";
      }
      o << "$EndNodeData\n";
    };
    view("peak von Mises over time (" + su + ")", 1, [&](std::ostream& s, std::size_t i) { s << " " << r.node_peak_Pa[i] * per_Pa; });
    view("time of the peak von Mises (s)", 1, [&](std::ostream& s, std::size_t i) { s << " " << r.node_peak_time_s[i]; });
    view("von Mises at the governing peak's time (" + su + ")", 1,
         [&](std::ostream& s, std::size_t i) { s << " " << r.von_mises_at_peak_Pa[i] * per_Pa; });
    view("displacement at the governing peak's time (" + unit + ")", 3, [&](std::ostream& s, std::size_t i) {
      const Eigen::Vector3d u = r.displacement_at_peak_m[i] * per_m;
      s << " " << u.x() << " " << u.y() << " " << u.z();
    });
  });

  // 4. The paper's Fig. 15.
  const fs::path svg = dir / "von_mises.svg";
  if (r.time_s.size() >= 2) {
    std::vector<plot::StressSeries> ps;
    double lo = 1e300, hi = 0;
    // The curve the verdict is taken from first (blue, bold in the legend's first line), then the
    // probes, then the contact node in vermilion: a point load's node may climb far above the
    // verdict's curve, which judges the stresses outside the contact zone.
    const Verdict& v = r.verdict;
    const bool inside_governs = v.governing_region == "inside the contact zone";
    const std::vector<double>& governing = inside_governs ? r.inside_zone_history_Pa : r.outside_zone_history_Pa;
    if (governing.size() == r.time_s.size()) {
      ps.push_back({std::string("verdict: max ") + (inside_governs ? "inside" : "outside") +
                        " the contact zone, peak " + plot::format_number(v.governing.von_mises_Pa * 1e-6, 3) +
                        " MPa at " + legend_point(v.governing.point_m, r.length_unit),
                    r.time_s, governing, 0});
      lo = std::min(lo, v.governing.von_mises_Pa);
      hi = std::max(hi, v.governing.von_mises_Pa);
    }
    for (const auto* p : series) {
      ps.push_back({p->name + " at " + legend_point(p->point_m, r.length_unit) + (p == &r.load ? " (contact node)" : ""), r.time_s,
                    p->von_mises_Pa, p == &r.load ? plot::kVermilion : 1 + static_cast<int>(ps.size()) % 4});
      lo = std::min(lo, p->max_von_mises_Pa);
      hi = std::max(hi, p->max_von_mises_Pa);
    }
    plot::StressPlotOptions po;
    po.title = title;
    po.yield_strength_Pa = r.verdict.yield_strength_Pa;
    po.log_scale = lo > 0 && hi / lo > 30;  // a point load's node dwarfs the probes
    r.von_mises_svg = plot::to_svg(plot::stress_time_drawing(ps, po));
    write_file_atomically(svg, r.von_mises_svg);
    r.files.push_back(svg);
  }
  r.files.insert(r.files.begin(), {csv, csv_sidecar_path(csv), vtu, msh});
  // 5. The results as a VTK time series (ParaView animates the wave).
  for (const auto& f : write_results_series(dir, m, r)) r.files.push_back(f);
}

// VTK's XML formats written by hand (we do not link VTK): ASCII UnstructuredGrid pieces and a
// ParaView collection (.pvd) naming them with their times.
std::vector<fs::path> write_results_series(const fs::path& dir, const TetMesh& m, const StressResult& r) {
  if (!r.results || r.time_s.empty()) return {};
  const std::size_t n = m.nodes_m.size(), times = r.time_s.size();
  const double by_budget = std::floor(kSeriesNodeFileBudget / static_cast<double>(std::max<std::size_t>(n, 1)));
  const std::size_t most = std::max<std::size_t>(2, std::min<std::size_t>(kMaxSeriesFiles, static_cast<std::size_t>(by_budget)));
  const std::size_t stride = (times + most - 1) / most;
  std::vector<char> keep(times, 0);
  for (std::size_t k = 0; k < times; k += stride) keep[k] = 1;
  keep[times - 1] = 1;
  for (std::size_t k = 0; k < times; ++k) {
    if (r.time_s[k] == r.peak_field_time_s) keep[k] = 1;
  }
  // Thinning the stride's picks next to the two forced ones keeps the count within `most`.
  std::size_t kept = 0;
  for (char c : keep) kept += c;
  for (std::size_t k = times - 1; kept > most && k > 0; --k) {
    if (keep[k] && k != times - 1 && r.time_s[k] != r.peak_field_time_s) keep[k] = 0, --kept;
  }

  const DeckUnits units{r.length_unit};
  const std::string length = to_string(r.length_unit), stress_unit = units.stress_unit();
  std::vector<Eigen::Vector3d> disp(n, Eigen::Vector3d::Zero());
  std::vector<std::array<double, 6>> stress(n, std::array<double, 6>{});
  std::vector<double> pe(n, 0.0);
  bool has_pe = false, pending = false;
  std::optional<NodalField> block;
  double t = 0, pending_t = 0;
  std::size_t index = 0;  // stress blocks read: the index into r.time_s
  std::vector<std::pair<double, std::string>> written;
  std::vector<fs::path> files;
  auto flush = [&] {
    if (!pending) return;
    pending = false;
    char name[32];
    std::snprintf(name, sizeof name, "results_%04zu.vtu", written.size());
    const fs::path vtu = dir / name;
    write_file_atomically(vtu, [&](std::ostream& o) {
      o << std::setprecision(9);
      o << "<?xml version=\"1.0\"?>\n<!-- impactdeck: CalculiX results at t = " << pending_t
        << " s in the deck's units: positions and displacement in " << length << ", stresses in " << stress_unit
        << " (" << units.name() << ") -->\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n";
      vtu_unit_fields(o, units);
      o << "<DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">" << pending_t
        << "</DataArray>\n</FieldData>\n"
        << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << m.tets.size() << "\">\n"
        << "<PointData Scalars=\"von_mises\" Vectors=\"displacement\" Tensors=\"stress\">\n"
        << "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
      for (const auto& u : disp) o << u.x() << " " << u.y() << " " << u.z() << "\n";
      o << "</DataArray>\n<DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"6\" format=\"ascii\">\n";
      for (const auto& v : stress) o << v[0] << " " << v[1] << " " << v[2] << " " << v[3] << " " << v[4] << " " << v[5] << "\n";
      o << "</DataArray>\n<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">\n";
      for (const auto& v : stress) o << von_mises(v.data()) << "\n";
      o << "</DataArray>\n";
      if (has_pe) {
        o << "<DataArray type=\"Float64\" Name=\"equivalent_plastic_strain\" format=\"ascii\">\n";
        for (double e : pe) o << e << "\n";
        o << "</DataArray>\n";
      }
      o << "</PointData>\n";
      vtu_mesh_and_end(o, m, units.per_m());
    });
    written.emplace_back(pending_t, name);
    files.push_back(vtu);
  };
  bool skip = false;
  NodalResultsVisitor visit;
  visit.time = [&](double time_s) {
    if (time_s != t) flush();  // the blocks of one output time share its header's time
    t = time_s;
    skip = t > r.end_time_s * (1 + 1e-6);
  };
  visit.field = [&](NodalField f) {
    block.reset();
    if (skip) return false;
    block = f;
    if (f == NodalField::plastic_strain) std::fill(pe.begin(), pe.end(), 0.0), has_pe = true;
    return true;
  };
  visit.value = [&](std::size_t node, const double* v) {
    if (block == NodalField::displacement) {
      disp[node] = Eigen::Vector3d(v[0], v[1], v[2]);  // the deck's length unit, as the positions
    } else if (block == NodalField::stress) {
      std::copy(v, v + 6, stress[node].begin());
    } else {
      pe[node] = v[0];
    }
  };
  visit.end = [&] {
    if (block == NodalField::stress) {
      if (index < times && keep[index]) pending = true, pending_t = t;
      ++index;
    }
    block.reset();
  };
  r.results->read(visit, n);
  flush();
  const fs::path pvd = dir / "results.pvd";
  write_file_atomically(pvd, [&](std::ostream& o) {
    o << std::setprecision(12);
    o << "<?xml version=\"1.0\"?>\n<!-- impactdeck: the CalculiX results as a time series (" << written.size() << " of "
      << times << " output times); unit system " << units.name() << ": lengths and displacements in " << length
      << ", stresses in " << stress_unit << " -->\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n";
    for (const auto& [time, file] : written) {
      o << "<DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
    }
    o << "</Collection>\n</VTKFile>\n";
  });
  files.insert(files.begin(), pvd);
  return files;
}

std::string format_stress(const StressResult& r) {
  std::ostringstream s;
  s << std::setprecision(4);
  auto mpa = [](double pa) { return pa * 1e-6; };
  for (const auto& p : r.probes) {
    s << p.name << " " << mm_text(p.point_m) << ": max von Mises " << mpa(p.max_von_mises_Pa) << " MPa at "
      << p.max_von_mises_time_s << " s\n";
  }
  s << "contact zone (radius " << r.contact_zone_radius_m * 1e3 << " mm): ";
  if (r.inside_zone.node >= 0) {
    s << "max von Mises " << mpa(r.inside_zone.von_mises_Pa) << " MPa at " << mm_text(r.inside_zone.point_m) << ", "
      << r.inside_zone.time_s << " s" << (r.inside_zone_meaningful ? "" : " (not meaningful under a point load)");
  } else {
    s << "no node";
  }
  s << "\noutside the contact zone: max von Mises " << mpa(r.outside_zone.von_mises_Pa) << " MPa at "
    << mm_text(r.outside_zone.point_m) << ", " << r.outside_zone.time_s << " s\n";
  const Verdict& v = r.verdict;
  s << "verdict: " << to_string(v.kind);
  if (v.kind == VerdictKind::survives) {
    s << ", safety factor " << v.safety_factor << " against yield " << mpa(*v.yield_strength_Pa) << " MPa ("
      << v.governing_region << ")";
  } else if (r.plastic) {
    const PlasticResult& p = *r.plastic;
    const PlasticStrainPeak& at = v.kind == VerdictKind::yields_beyond_contact ? p.beyond_zone : p.max;
    if (at.node >= 0 && v.kind != VerdictKind::survives_elastically) {
      s << ": equivalent plastic strain " << at.plastic_strain << " at " << mm_text(at.point_m) << ", "
        << at.distance_m * 1e3 << " mm from the contact point, " << at.time_s << " s";
    } else {
      s << ": no equivalent plastic strain above " << p.threshold;
    }
    s << " (threshold " << p.threshold << "; local within " << p.plastic_zone_radius_m * 1e3 << " mm); dent "
      << p.residual_indentation_m * 1e3 << " mm of radius " << p.dent_radius_m * 1e3 << " mm (" << p.contact_law << " law)";
  } else if (v.kind == VerdictKind::yields) {
    s << ": " << mpa(v.governing.von_mises_Pa) << " MPa > yield " << mpa(*v.yield_strength_Pa) << " MPa at "
      << mm_text(v.governing.point_m) << ", " << v.governing.time_s << " s (" << v.governing_region
      << "; first above yield at " << v.first_yield_time_s.value_or(v.governing.time_s) << " s)";
  }
  s << "\n";
  return s.str();
}

json to_json(const StressResult& r) {
  auto peak = [&](const VonMisesPeak& p) {
    if (p.node < 0) return json(nullptr);
    return json{{"max_von_mises_Pa", p.von_mises_Pa}, {"time_s", p.time_s}, {"node", p.node + 1}, {"point_m", json_vector(p.point_m)}};
  };
  auto probe = [&](const ProbeStress& p) {
    return json{{"name", p.name},
                {"node", p.node + 1},
                {"point_m", json_vector(p.point_m)},
                {"max_von_mises_Pa", p.max_von_mises_Pa},
                {"max_von_mises_time_s", p.max_von_mises_time_s}};
  };
  json probes = json::array();
  for (const auto& p : r.probes) probes.push_back(probe(p));
  json load = probe(r.load);
  load["meaningful"] = r.inside_zone_meaningful;
  json inside = peak(r.inside_zone);
  if (!inside.is_null()) {
    inside["meaningful"] = r.inside_zone_meaningful;
    if (!r.inside_zone_meaningful) {
      inside["note"] = "not meaningful: a point load's stress near its node grows without bound as the mesh is "
                       "refined (use load = \"hertz-patch\")";
    }
  }
  const Verdict& v = r.verdict;
  json verdict = {{"result", to_string(v.kind)},
                  {"yield_strength_Pa", v.yield_strength_Pa ? json(*v.yield_strength_Pa) : json(nullptr)},
                  {"governing_region", v.governing_region},
                  {"governing", peak(v.governing)},
                  {"safety_factor", v.yield_strength_Pa && v.governing.von_mises_Pa > 0 ? json(v.safety_factor) : json(nullptr)},
                  {"first_yield_time_s", v.first_yield_time_s ? json(*v.first_yield_time_s) : json(nullptr)}};
  json extra = json::object();
  if (r.plastic) {
    const PlasticResult& p = *r.plastic;
    const double per = DeckUnits{r.length_unit}.per_m();
    auto pe_peak = [&](const PlasticStrainPeak& k) {
      if (k.node < 0) return json(nullptr);
      return json{{"value", k.plastic_strain},
                  {"node", k.node + 1},
                  {"point", json_vector(Eigen::Vector3d(k.point_m * per))},
                  {"length_unit", to_string(r.length_unit)},
                  {"point_m", json_vector(k.point_m)},
                  {"distance_from_contact_m", k.distance_m},
                  {"time_s", k.time_s}};
    };
    verdict["safety_factor"] = nullptr;  // a yielded body's von Mises is capped by its hardening
    verdict["max_equivalent_plastic_strain"] = p.max.plastic_strain;
    verdict["governing_plastic_strain"] =
        pe_peak(v.kind == VerdictKind::yields_beyond_contact ? p.beyond_zone : p.max);
    verdict["plastic_strain_threshold"] = p.threshold;
    verdict["plastic_zone_radius_m"] = p.plastic_zone_radius_m;
    verdict["contact_law"] = p.contact_law;
    verdict["residual_indentation_m"] = p.residual_indentation_m;
    verdict["dent_radius_m"] = p.dent_radius_m;
    json out = pe_peak(p.max);
    if (out.is_null()) out = {{"value", 0.0}, {"node", nullptr}, {"point", nullptr}, {"length_unit", to_string(r.length_unit)},
                              {"point_m", nullptr}, {"distance_from_contact_m", nullptr}, {"time_s", nullptr}};
    json plastic = {{"beyond_plastic_zone", pe_peak(p.beyond_zone)},
                    {"plastic_strain_threshold", p.threshold},
                    {"plastic_zone_radius_m", p.plastic_zone_radius_m},
                    {"yielded_nodes", p.yielded_nodes},
                    {"contact_law", p.contact_law},
                    {"residual_indentation_m", p.residual_indentation_m},
                    {"dent_radius_m", p.dent_radius_m}};
    extra = {{"max_equivalent_plastic_strain", out}, {"plastic", plastic}};
  }
  json files = json::array();
  for (const auto& f : r.files) files.push_back(f.string());
  json j = {{"material_model", r.plastic ? "plastic" : "elastic"},
          {"probes", probes},
          {"load_node", load},
          {"contact_zone_radius_m", r.contact_zone_radius_m},
          {"outside_contact_zone", peak(r.outside_zone)},
          {"inside_contact_zone", inside},
          {"verdict", verdict},
          {"output_times", r.time_s.size()},
          {"peak_field_time_s", r.peak_field_time_s},
          {"frd_bytes", r.frd_bytes},
          {"files", files}};
  j.update(extra);
  return j;
}

}  // namespace impactdeck::fem_export
