// Code_Aster and CalculiX decks (DECKS.md), written into a staging folder renamed at the end.
#include "impactdeck/fem_export/decks.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/fem_export/force_table.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;

namespace {

// SI -> mm-N-s-tonne.
constexpr double kMm = 1000.0;          // mm per m
constexpr double kMPa = 1e-6;           // MPa per Pa
constexpr double kTonnePerMm3 = 1e-12;  // (t/mm^3) per (kg/m^3)
constexpr const char* kMedMesh = "BODYMESH";

std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(12) << v + 0.0;  // + 0.0: no "-0"
  std::string t = s.str();
  if (t.find_first_of(".eE") == std::string::npos && t != "inf" && t != "nan") t += ".0";
  return t;
}

std::size_t increments(const DeckOptions& o) {
  return static_cast<std::size_t>(std::ceil(o.end_time_s / o.time_step_s - 1e-9));
}

void validate(const DeckRequest& r, const std::string& where) {
  const DeckOptions& o = r.options;
  if (!(o.time_step_s > 0) || !std::isfinite(o.time_step_s)) throw InputError(where, "time_step_s", "must be > 0");
  if (!(o.end_time_s > o.time_step_s) || !std::isfinite(o.end_time_s)) {
    throw InputError(where, "end_time_s", "must exceed time_step_s");
  }
  if (increments(o) > 2000000) throw InputError(where, "time_step_s", "more than 2e6 increments");
  if (r.force.time_s.size() < 2 || r.force.time_s.size() != r.force.force_N.size()) {
    throw InputError(where, "force table", "needs at least two samples");
  }
  if (r.force.time_s.back() > o.end_time_s) {
    std::ostringstream m;
    m << "end_time_s " << o.end_time_s << " s ends before the contact (" << r.force.time_s.back() << " s)";
    throw InputError(where, "end_time_s", m.str());
  }
  if (std::abs(r.direction.norm() - 1.0) > 1e-9) throw InputError(where, "direction", "must be a unit vector");
  if (!(r.material.youngs_modulus_Pa > 0) || !(r.material.density_kg_m3 > 0)) {
    throw InputError(where, "material", "modulus and density must be > 0");
  }
  if (!(r.impulse_Ns > 0)) throw InputError(where, "impulse", "must be > 0");
}

std::string header_lines(const std::string& c, const DeckRequest& r, const std::string& what) {
  std::ostringstream h;
  h << c << " impactdeck " << kVersion << ": " << what << "\n"
    << c << " Hybrid approach: the impactor is replaced by its Hertz force history at node group LOAD.\n"
    << c << " Units: mm, N, s, tonne (E in MPa, density in t/mm3, velocity in mm/s).\n"
    << c << " Scene: " << (r.source.empty() ? "(none)" : r.source) << "; impact: " << r.impact << "\n"
    << c << " Impulse " << num(r.impulse_Ns) << " N s along (" << num(r.direction.x()) << ", "
    << num(r.direction.y()) << ", " << num(r.direction.z()) << "); contact ends at "
    << num(r.force.time_s.back()) << " s.\n";
  return h.str();
}

std::vector<std::string> probe_groups(const TetMesh& m) {
  std::vector<std::string> p;
  for (const auto& [g, n] : m.node_groups)
    if (g.rfind("PROBE", 0) == 0) p.push_back(g);
  return p;
}

}  // namespace

const char* to_string(CcxSolver s) {
  switch (s) {
    case CcxSolver::automatic: return "auto";
    case CcxSolver::spooles: return "spooles";
    case CcxSolver::iterative: return "iterative";
  }
  return "?";
}

CcxSolver ccx_solver_for(CcxSolver requested, std::size_t nodes) {
  if (requested != CcxSolver::automatic) return requested;
  return nodes >= kIterativeSolverMinNodes ? CcxSolver::iterative : CcxSolver::spooles;
}

TimeSchedule time_schedule(const DeckOptions& o, double contact_end_s) {
  TimeSchedule t;
  double start = 0;
  if (o.pulse_increments > 0 && contact_end_s > 0 && contact_end_s / o.pulse_increments < o.time_step_s &&
      contact_end_s < o.end_time_s) {
    t.pulse_increments = static_cast<std::size_t>(o.pulse_increments);
    t.pulse_step_s = contact_end_s / o.pulse_increments;
    t.pulse_end_s = contact_end_s;
    start = contact_end_s;
  }
  const double rest = o.end_time_s - start;
  t.main_increments = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(rest / o.time_step_s - 1e-9)));
  t.main_step_s = rest / static_cast<double>(t.main_increments);
  return t;
}

std::string calculix_mesh_inp(const TetMesh& m) {
  std::ostringstream s;
  s << "** impactdeck " << kVersion << ": mesh of the target body (mm), included by impact.inp\n";
  s << "*NODE, NSET=BODYN\n" << std::setprecision(15);
  for (std::size_t i = 0; i < m.nodes_m.size(); ++i) {
    const Eigen::Vector3d x = m.nodes_m[i] * kMm;
    s << i + 1 << ", " << num(x.x()) << ", " << num(x.y()) << ", " << num(x.z()) << "\n";
  }
  s << "*ELEMENT, TYPE=C3D4, ELSET=BODY\n";
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    const auto& t = m.tets[e];
    s << e + 1 << ", " << t[0] + 1 << ", " << t[1] + 1 << ", " << t[2] + 1 << ", " << t[3] + 1 << "\n";
  }
  for (const auto& [g, n] : m.node_groups) s << "*NSET, NSET=" << g << "\n" << n + 1 << "\n";
  return s.str();
}

std::string calculix_inp(const DeckRequest& r, const TetMesh& m) {
  const DeckOptions& o = r.options;
  std::ostringstream s;
  s << header_lines("**", r, "CalculiX deck (ccx 2.20), run: ccx -i impact");
  s << "** Step 1: implicit direct dynamics (fixed steps; refined while the force acts) through\n"
       "** end_time_s, probe velocities every increment. Step 2: one increment printing every node's\n"
       "** velocity and the total mass (the momentum check). The amplitude uses TOTAL TIME and stays\n"
       "** at its closing zero.\n";
  s << "*HEADING\nimpactdeck hybrid impact " << r.impact << "\n";
  s << "*INCLUDE, INPUT=mesh.inp\n";
  s << "*MATERIAL, NAME=BODYMAT\n*ELASTIC\n" << num(r.material.youngs_modulus_Pa * kMPa) << ", "
    << num(r.material.poisson_ratio) << "\n*DENSITY\n" << num(r.material.density_kg_m3 * kTonnePerMm3) << "\n";
  s << "*SOLID SECTION, ELSET=BODY, MATERIAL=BODYMAT\n";
  s << "*AMPLITUDE, NAME=HERTZ, TIME=TOTAL TIME\n" << std::setprecision(15);
  for (std::size_t i = 0; i < r.force.time_s.size(); ++i) {
    s << num(r.force.time_s[i]) << ", " << num(r.force.force_N[i]) << "\n";
  }
  const TimeSchedule ts = time_schedule(o, r.force.time_s.back());
  // The equation solver by deck size (CcxSolver; bench/bench_ccx.cpp measured the choice).
  const char* dynamic = ccx_solver_for(o.solver, m.nodes_m.size()) == CcxSolver::iterative
                            ? "*DYNAMIC, DIRECT, SOLVER=ITERATIVE SCALING\n"
                            : "*DYNAMIC, DIRECT\n";
  auto step = [&](std::size_t incs, double dt, double period, const std::string& what) {
    s << "** " << what << "\n*STEP, INC=" << incs + 10 << "\n" << dynamic << num(dt) << ", " << num(period) << "\n";
  };
  if (ts.pulse_increments > 0) {
    step(ts.pulse_increments, ts.pulse_step_s, ts.pulse_end_s, "Step 1a: through the end of the contact, refined");
    s << "*CLOAD, AMPLITUDE=HERTZ\n";
    for (int k = 0; k < 3; ++k) s << "LOAD, " << k + 1 << ", " << num(r.direction[k]) << "\n";
    for (const auto& p : probe_groups(m)) s << "*NODE PRINT, NSET=" << p << ", FREQUENCY=1\nV\n";
    s << "*END STEP\n";
    step(ts.main_increments, ts.main_step_s, o.end_time_s - ts.pulse_end_s, "Step 1b: free vibration through end_time_s");
  } else {
    step(ts.main_increments, ts.main_step_s, o.end_time_s, "Step 1: through end_time_s");
  }
  s << "*CLOAD, AMPLITUDE=HERTZ\n";
  for (int k = 0; k < 3; ++k) s << "LOAD, " << k + 1 << ", " << num(r.direction[k]) << "\n";
  for (const auto& p : probe_groups(m)) s << "*NODE PRINT, NSET=" << p << ", FREQUENCY=1\nV\n";
  s << "*END STEP\n";
  s << "** Step 2: one increment printing all velocities and the mass (momentum check)\n";
  s << "*STEP, INC=10\n" << dynamic << num(ts.main_step_s) << ", " << num(ts.main_step_s) << "\n";
  s << "*NODE PRINT, NSET=BODYN, FREQUENCY=1\nV\n";
  s << "*EL PRINT, ELSET=BODY, TOTALS=ONLY, FREQUENCY=1\nEMAS\n";
  s << "*END STEP\n";
  return s.str();
}

std::string code_aster_comm(const DeckRequest& r, const TetMesh& m) {
  const DeckOptions& o = r.options;
  std::ostringstream s;
  s << header_lines("#", r, "Code_Aster command file (DYNA_VIBRA, versions 15.x and later)");
  s << "# Files (units): mesh.med (20), probe velocity tables (38), results MED (80); see impact.export.\n";
  s << "DEBUT()\n\n";
  s << "MAIL = LIRE_MAILLAGE(FORMAT='MED', UNITE=20)\n\n";
  s << "MODELE = AFFE_MODELE(MAILLAGE=MAIL,\n"
       "                     AFFE=_F(GROUP_MA=('BODY',), PHENOMENE='MECANIQUE', MODELISATION='3D'))\n\n";
  s << "MATER = DEFI_MATERIAU(ELAS=_F(E=" << num(r.material.youngs_modulus_Pa * kMPa)
    << ", NU=" << num(r.material.poisson_ratio) << ", RHO=" << num(r.material.density_kg_m3 * kTonnePerMm3)
    << "))\n\n";
  s << "CHMAT = AFFE_MATERIAU(MAILLAGE=MAIL, AFFE=_F(GROUP_MA=('BODY',), MATER=MATER))\n\n";
  s << "# Hertz force history F(t) in N; constant extrapolation on both sides, closing zero.\n";
  s << "FHERTZ = DEFI_FONCTION(NOM_PARA='INST',\n                      VALE=(\n";
  for (std::size_t i = 0; i < r.force.time_s.size(); ++i) {
    s << "                          " << num(r.force.time_s[i]) << ", " << num(r.force.force_N[i]) << ",\n";
  }
  s << "                      ),\n"
       "                      INTERPOL=('LIN', 'LIN'),\n"
       "                      PROL_GAUCHE='CONSTANT',\n"
       "                      PROL_DROITE='CONSTANT')\n\n";
  s << "# Unit direction of the force on the target (times FHERTZ).\n";
  s << "CHARGE = AFFE_CHAR_MECA(MODELE=MODELE,\n                        FORCE_NODALE=_F(GROUP_NO=('LOAD',), FX="
    << num(r.direction.x()) << ", FY=" << num(r.direction.y()) << ", FZ=" << num(r.direction.z()) << "))\n\n";
  const TimeSchedule ts = time_schedule(o, r.force.time_s.back());
  s << "# Time steps: refined through the end of the contact, then the main step.\n";
  s << "LINST = DEFI_LIST_REEL(DEBUT=0.0,\n                       INTERVALLE=(";
  if (ts.pulse_increments > 0) {
    s << "_F(JUSQU_A=" << num(ts.pulse_end_s) << ", PAS=" << num(ts.pulse_step_s) << "),\n                                   ";
  }
  s << "_F(JUSQU_A=" << num(o.end_time_s) << ", PAS=" << num(ts.main_step_s) << ")))\n\n";
  s << "ASSEMBLAGE(MODELE=MODELE,\n"
       "           CHAM_MATER=CHMAT,\n"
       "           NUME_DDL=CO('NUMEDDL'),\n"
       "           MATR_ASSE=(_F(MATRICE=CO('RIGI'), OPTION='RIGI_MECA'),\n"
       "                      _F(MATRICE=CO('MASS'), OPTION='MASS_MECA')))\n\n";
  s << "# Free body: K + a0 M is positive definite. SCHEMA written explicitly (15.x defaults to DIFF_CENTRE).\n";
  s << "RESU = DYNA_VIBRA(TYPE_CALCUL='TRAN',\n"
       "                  BASE_CALCUL='PHYS',\n"
       "                  MODELE=MODELE,\n"
       "                  CHAM_MATER=CHMAT,\n"
       "                  MATR_MASS=MASS,\n"
       "                  MATR_RIGI=RIGI,\n"
       "                  SCHEMA_TEMPS=_F(SCHEMA='NEWMARK', BETA=0.25, GAMMA=0.5),\n"
       "                  INCREMENT=_F(LIST_INST=LINST),\n"
       "                  EXCIT=_F(CHARGE=CHARGE, FONC_MULT=FHERTZ))\n\n";
  s << "# Von Mises stress (component VMIS); singular at the load node itself (point force).\n";
  s << "RESU = CALC_CHAMP(reuse=RESU,\n"
       "                  RESULTAT=RESU,\n"
       "                  CONTRAINTE=('SIGM_ELNO',),\n"
       "                  CRITERES=('SIEQ_ELNO', 'SIEQ_NOEU'))\n\n";
  const auto probes = probe_groups(m);
  if (!probes.empty()) s << "# Velocity of each probe node, mm/s, one table per component (unit 38).\n";
  const char* comps[3] = {"DX", "DY", "DZ"};
  for (std::size_t i = 0; i < probes.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const std::string f = "V" + std::to_string(i + 1) + std::string(1, "XYZ"[k]);
      s << f << " = RECU_FONCTION(RESULTAT=RESU, NOM_CHAM='VITE', NOM_CMP='" << comps[k]
        << "', GROUP_NO=('" << probes[i] << "',))\n";
    }
    s << "IMPR_FONCTION(FORMAT='TABLEAU', UNITE=38,\n              COURBE=(";
    for (int k = 0; k < 3; ++k) {
      s << (k ? ", " : "") << "_F(FONCTION=V" << i + 1 << "XYZ"[k] << ")";
    }
    s << "))\n\n";
  }
  s << "IMPR_RESU(FORMAT='MED', UNITE=80,\n"
       "          RESU=_F(RESULTAT=RESU, NOM_CHAM=('DEPL', 'VITE', 'SIEQ_NOEU')))\n\n";
  s << "FIN()\n";
  return s.str();
}

std::string code_aster_export(const DeckRequest& r, const TetMesh& m) {
  std::ostringstream s;
  (void)m;
  s << "P actions make_etude\n"
    << "P version stable\n"
    << "P time_limit " << std::max<long>(600, static_cast<long>(increments(r.options) / 10)) << "\n"
    << "P memory_limit 2048\n"
    << "P ncpus 1\n"
    << "P mpi_nbcpu 1\n"
    << "P mpi_nbnoeud 1\n"
    << "F comm " << kJobName << ".comm D 1\n"
    << "F mmed mesh.med D 20\n"
    << "F mess " << kJobName << ".mess R 6\n"
    << "F resu " << kJobName << ".resu R 8\n"
    << "F libr " << kJobName << "_probes.txt R 38\n"
    << "F rmed " << kJobName << "_results.rmed R 80\n";
  return s.str();
}

DeckResult write_decks(const DeckRequest& r, const fs::path& folder) {
  const std::string where = folder.string();
  validate(r, where);
  const fs::path parent = folder.has_parent_path() ? folder.parent_path() : fs::path(".");
  if (!fs::is_directory(parent)) throw InputError(where, "output folder", "parent folder does not exist");
  const fs::path stage = parent / ("." + folder.filename().string() + ".partial-" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(stage, ec);
  if (!fs::create_directory(stage, ec)) throw InputError(where, "output folder", "cannot create " + stage.string());

  DeckResult out;
  try {
    const auto t_mesh = std::chrono::steady_clock::now();
    MeshResult mr = r.body.kind == BodyKind::ellipsoid
                        ? mesh_ellipsoid(r.body.semi_axes_m, r.load_point_m, r.options.mesh, stage, "mesh")
                        : mesh_stl(r.body.stl, r.body.stl_unit_m, r.load_point_m, r.options.mesh, stage, "mesh");
    out.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_mesh).count();
    const TetMesh& m = mr.mesh;
    std::vector<std::string> names = {"mesh.geo", "mesh.msh", "mesh_v22.msh"};
    if (r.body.kind == BodyKind::stl) names.push_back("mesh_part.stl");
    if (r.options.calculix) {
      write_file_atomically(stage / "mesh.inp", calculix_mesh_inp(m));
      write_file_atomically(stage / (std::string(kJobName) + ".inp"), calculix_inp(r, m));
      names.insert(names.end(), {"mesh.inp", std::string(kJobName) + ".inp"});
    }
    if (r.options.code_aster) {
      write_med(m, stage / "mesh.med", kMedMesh);
      write_file_atomically(stage / (std::string(kJobName) + ".comm"), code_aster_comm(r, m));
      write_file_atomically(stage / (std::string(kJobName) + ".export"), code_aster_export(r, m));
      names.insert(names.end(), {"mesh.med", std::string(kJobName) + ".comm", std::string(kJobName) + ".export"});
    }
    ForceTableHeader fh;
    fh.source = r.source;
    fh.impact = r.impact;
    fh.direction = r.direction;
    write_file_atomically(stage / "force.csv", [&](std::ostream& out) { write_force_table_csv(out, r.force, fh); });
    names.push_back("force.csv");

    using nlohmann::json;
    auto v3 = [](const Eigen::Vector3d& v) { return json::array({v.x() + 0.0, v.y() + 0.0, v.z() + 0.0}); };
    const MeshQuality& q = mr.quality;
    json quality = {{"node_count", q.node_count},
                    {"tet_count", q.tet_count},
                    {"min_quality", q.min_quality},
                    {"mean_quality", q.mean_quality},
                    {"quality_measure", "radius ratio 3 r_in / r_circ (1 = regular tetrahedron)"},
                    {"fe_volume_m3", q.fe_volume_m3},
                    {"part_volume_m3", q.part_volume_m3},
                    {"volume_relative_difference", q.volume_relative_difference},
                    {"load_node_distance_m", q.load_node_distance_m},
                    {"probe_node_distance_m", q.probe_node_distance_m},
                    {"mesh_size_m", r.options.mesh.mesh_size_m},
                    {"load_mesh_size_m", r.options.mesh.load_mesh_size_m > 0 ? r.options.mesh.load_mesh_size_m
                                                                             : r.options.mesh.mesh_size_m / 3}};
    write_file_atomically(stage / "mesh_quality.json", quality.dump(2) + "\n");
    names.push_back("mesh_quality.json");

    json probes = json::array();
    for (const auto& [g, n] : m.node_groups) {
      if (g.rfind("PROBE", 0) == 0) probes.push_back({{"name", g}, {"node", n + 1}, {"point_m", v3(m.nodes_m[n])}});
    }
    names.push_back("deck.json");
    json deck = {{"impactdeck_version", kVersion},
                 {"source", r.source},
                 {"impact", r.impact},
                 {"job", kJobName},
                 {"deck_units", "mm-N-s-tonne"},
                 {"impulse_Ns", r.impulse_Ns},
                 {"direction", v3(r.direction)},
                 {"load_point_m", v3(r.load_point_m)},
                 {"load_node", m.node_of("LOAD") + 1},
                 {"load_node_point_m", v3(m.nodes_m[m.node_of("LOAD")])},
                 {"contact_end_s", r.force.time_s.back()},
                 {"end_time_s", r.options.end_time_s},
                 {"time_step_s", r.options.time_step_s},
                 {"pulse_increments", time_schedule(r.options, r.force.time_s.back()).pulse_increments},
                 {"youngs_modulus_Pa", r.material.youngs_modulus_Pa},
                 {"poisson_ratio", r.material.poisson_ratio},
                 {"density_kg_m3", r.material.density_kg_m3},
                 {"probes", probes},
                 {"calculix", r.options.calculix},
                 {"ccx_solver", to_string(ccx_solver_for(r.options.solver, m.nodes_m.size()))},
                 {"code_aster", r.options.code_aster},
                 {"mesh", quality},
                 {"files", names}};
    write_file_atomically(stage / "deck.json", deck.dump(2) + "\n");

    // Publish: move an old folder aside, rename the stage, drop the old one.
    const fs::path old = parent / ("." + folder.filename().string() + ".old-" + std::to_string(::getpid()));
    fs::remove_all(old, ec);
    if (fs::exists(folder)) fs::rename(folder, old);
    fs::rename(stage, folder);
    fs::remove_all(old, ec);

    out.folder = folder;
    for (const auto& n : names) out.files.push_back(folder / n);
    out.quality = q;
    out.node_count = q.node_count;
    out.tet_count = q.tet_count;
  } catch (const InputError& e) {
    fs::remove_all(stage, ec);
    // Name the deck folder, not the hidden staging folder that no longer exists.
    std::string w = e.where();
    if (w.rfind(stage.string(), 0) == 0) w = (folder / fs::path(w).lexically_relative(stage)).string();
    throw InputError(w, e.place(), e.reason());
  } catch (...) {
    fs::remove_all(stage, ec);
    throw;
  }
  return out;
}

}  // namespace impactdeck::fem_export
