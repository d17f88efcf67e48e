// CalculiX's deck dialect: impact.inp and mesh.inp (docs/fem.md).
#include <iomanip>
#include <sstream>

#include "calculix.hpp"
#include "../deck_text.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/version.hpp"

namespace impactdeck::fem_export {

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


}  // namespace impactdeck::fem_export

namespace impactdeck::fem_export::calculix {
using detail::num;
using detail::header_lines;
using detail::output_every;
using detail::probe_groups;

namespace {

// Pairs (t, f) four to a line, as ccx's *AMPLITUDE reads them.
void amplitude_rows(std::ostream& s, const std::vector<double>& t, const std::vector<double>& f) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    s << num(t[i]) << ", " << num(f[i]) << ((i % 4 == 3 || i + 1 == t.size()) ? "\n" : ", ");
  }
}

}  // namespace

std::string calculix_mesh_inp(const TetMesh& m, const DeckUnits& u) {
  std::ostringstream s;
  s << "** impactdeck " << kVersion << ": mesh of the target body (" << to_string(u.length)
    << "), included by impact.inp\n** Units: " << u.description() << ".\n";
  s << "*NODE, NSET=BODYN\n" << std::setprecision(15);
  for (std::size_t i = 0; i < m.nodes_m.size(); ++i) {
    const Eigen::Vector3d x = m.nodes_m[i] * u.per_m();
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

std::string material_cards(const std::string& name, const DeckMaterial& m, double yield_Pa, double per_Pa,
                           double per_kg_m3) {
  std::ostringstream s;
  s << "*MATERIAL, NAME=" << name << "\n*ELASTIC\n" << num(m.youngs_modulus_Pa * per_Pa) << ", " << num(m.poisson_ratio)
    << "\n";
  if (m.model == MaterialModel::plastic) {
    s << "*PLASTIC\n";
    for (const HardeningRow& h : hardening_table(m, yield_Pa)) {
      s << num(h.stress_Pa * per_Pa) << ", " << num(h.plastic_strain) << "\n";
    }
  }
  s << "*DENSITY\n" << num(m.density_kg_m3 * per_kg_m3) << "\n";
  return s.str();
}

std::string calculix_inp(const DeckRequest& r, const TetMesh& m, const PatchLoad* patch) {
  const DeckOptions& o = r.options;
  const TimeSchedule ts = deck_schedule(r);
  const std::size_t every = output_every(o, ts, m.nodes_m.size());
  std::ostringstream s;
  s << header_lines("**", r, "CalculiX deck (ccx 2.20), run: ccx -i impact");
  s << "** Step 1: implicit direct dynamics (fixed steps; refined while the force acts) through\n"
       "** end_time_s, probe velocities, nodal stresses S and displacements U (impact.frd) every\n"
       "** increment" << (every > 1 ? " (every " + std::to_string(every) + "th after the contact)" : std::string()) << ".\n"
       "** Step 2: one increment printing every node's velocity and the total mass (the momentum check).\n"
       "** The amplitudes use TOTAL TIME and stay at their closing zero.\n";
  {
    const ForceSampling fs = force_sampling(r.force, ts);
    s << "** Increments: " << ts.pulse_increments << " across the contact ("
      << (o.pulse_increments == kAutoPulseIncrements ? "at the force table's samples" : "as asked") << "), then "
      << ts.main_increments << "; at them the force's impulse and peak\n** differ from the table's by "
      << std::setprecision(3) << fs.impulse_relative_error << " and " << fs.peak_force_relative_error << ".\n";
  }
  if (patch) {
    s << "** Load: the Hertz pressure of each instant's contact ellipse as nodal forces on "
      << patch->nodes.size() << " surface nodes,\n** one amplitude per node (N), sum F(t), zero moment about the contact point.\n";
  }
  s << "*HEADING\nimpactdeck hybrid impact " << r.impact << "\n";
  s << "*INCLUDE, INPUT=mesh.inp\n";
  const bool plastic = r.material.model == MaterialModel::plastic;
  if (plastic) {
    s << "** Material: elastic-plastic, von Mises with isotropic bilinear hardening (*PLASTIC rows: yield stress,\n"
         "** equivalent plastic strain; linear between them, constant past the last). NLGEOM on every step:\n"
         "** a dent's strains are not small. PEEQ (the .frd's PE) is written with the stresses.\n";
  }
  s << material_cards("BODYMAT", r.material, r.yield_strength_Pa.value_or(0.0), o.units.per_Pa(), o.units.per_kg_m3());
  s << "*SOLID SECTION, ELSET=BODY, MATERIAL=BODYMAT\n" << std::setprecision(15);
  if (patch) {
    for (std::size_t k = 0; k < patch->nodes.size(); ++k) {
      s << "*AMPLITUDE, NAME=P" << k + 1 << ", TIME=TOTAL TIME\n";
      amplitude_rows(s, patch->time_s, patch->force_N[k]);
    }
  } else {
    s << "*AMPLITUDE, NAME=HERTZ, TIME=TOTAL TIME\n";
    for (std::size_t i = 0; i < r.force.time_s.size(); ++i) {
      s << num(r.force.time_s[i]) << ", " << num(r.force.force_N[i]) << "\n";
    }
  }
  // The equation solver by deck size (CcxSolver; bench/bench_ccx.cpp measured the choice).
  const char* dynamic = ccx_solver_for(o.solver, m.nodes_m.size()) == CcxSolver::iterative
                            ? "*DYNAMIC, DIRECT, SOLVER=ITERATIVE SCALING\n"
                            : "*DYNAMIC, DIRECT\n";
  // Plastic decks: the steps after the contact let ccx cut its increment (automatic incrementation,
  // down to kPlasticMinIncrementFraction of the step, never above it). Measured on a dented steel
  // block (tests/test_fem_plastic_ccx.cpp): with fixed increments Newton's residual alternates
  // between two values in the yielded elements during the free vibration and ccx stops ("solution
  // seems to diverge"); cut to a fifth it converges. The steps across the contact keep the fixed
  // increments at the force table's samples (docs/fem.md, "The time step the accuracy needs").
  auto step = [&](std::size_t incs, double dt, double period, const std::string& what, bool may_cut) {
    const bool cut = plastic && may_cut;
    s << "** " << what << "\n*STEP, " << (plastic ? "NLGEOM, " : "")
      << "INC=" << (cut ? (incs + 10) * kPlasticIncrementHeadroom : incs + 10) << "\n";
    if (cut) {
      s << (ccx_solver_for(o.solver, m.nodes_m.size()) == CcxSolver::iterative ? "*DYNAMIC, SOLVER=ITERATIVE SCALING\n"
                                                                              : "*DYNAMIC\n")
        << num(dt) << ", " << num(period) << ", " << num(dt * kPlasticMinIncrementFraction) << ", " << num(dt) << "\n";
    } else {
      s << dynamic << num(dt) << ", " << num(period) << "\n";
    }
  };
  auto loads_and_output = [&](std::size_t frequency) {
    if (patch) {
      for (std::size_t k = 0; k < patch->nodes.size(); ++k) {
        s << "*CLOAD, AMPLITUDE=P" << k + 1 << "\n";
        for (int c = 0; c < 3; ++c) s << patch->nodes[k] + 1 << ", " << c + 1 << ", " << num(r.direction[c]) << "\n";
      }
    } else {
      s << "*CLOAD, AMPLITUDE=HERTZ\n";
      for (int k = 0; k < 3; ++k) s << "LOAD, " << k + 1 << ", " << num(r.direction[k]) << "\n";
    }
    for (const auto& p : probe_groups(m)) s << "*NODE PRINT, NSET=" << p << ", FREQUENCY=" << frequency << "\nV\n";
    s << "*NODE FILE, FREQUENCY=" << frequency << "\nU\n*EL FILE, FREQUENCY=" << frequency << (plastic ? "\nS, PEEQ\n" : "\nS\n");
    s << "*END STEP\n";
  };
  if (!ts.pulse_segments.empty()) {
    double begin = 0;
    for (std::size_t i = 0; i < ts.pulse_segments.size(); ++i) {
      const TimeSegment& g = ts.pulse_segments[i];
      const bool last = i + 1 == ts.pulse_segments.size();
      step(g.increments, g.step_s, g.end_s - begin,
           std::string("Step 1a") + (ts.pulse_segments.size() > 1 ? "." + std::to_string(i + 1) : std::string()) +
               (last ? ": through the end of the contact, refined" : ": refined, while the force acts"),
           false);
      loads_and_output(1);
      begin = g.end_s;
    }
    step(ts.main_increments, ts.main_step_s, o.end_time_s - ts.pulse_end_s, "Step 1b: free vibration through end_time_s",
         true);
  } else {
    step(ts.main_increments, ts.main_step_s, o.end_time_s, "Step 1: through end_time_s", false);
  }
  loads_and_output(every);
  step(0, ts.main_step_s, ts.main_step_s,
       "Step 2: one increment printing all velocities and the mass (momentum check)", true);
  s << "*NODE PRINT, NSET=BODYN, FREQUENCY=1\nV\n";
  s << "*EL PRINT, ELSET=BODY, TOTALS=ONLY, FREQUENCY=1\nEMAS\n";
  s << "*END STEP\n";
  return s.str();
}

std::vector<std::string> CalculixSolver::write_deck(const DeckInput& in, const std::filesystem::path& folder) const {
  write_file_atomically(folder / "mesh.inp", calculix_mesh_inp(in.mesh, in.request.options.units));
  write_file_atomically(folder / (std::string(kJobName) + ".inp"), calculix_inp(in.request, in.mesh, in.patch));
  return {"mesh.inp", std::string(kJobName) + ".inp"};
}

void CalculixSolver::describe(const DeckInput& in, bool selected, nlohmann::json& deck) const {
  Solver::describe(in, selected, deck);
  deck["ccx_solver"] = to_string(ccx_solver_for(in.request.options.solver, in.mesh.nodes_m.size()));
}

}  // namespace impactdeck::fem_export::calculix
