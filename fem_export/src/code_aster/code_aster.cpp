// Code_Aster's deck: mesh.med, impact.comm (DYNA_VIBRA) and impact.export (docs/fem.md).
#include "code_aster.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "../deck_text.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export::code_aster {
using detail::header_lines;
using detail::increments;
using detail::num;
using detail::probe_groups;

namespace {
constexpr const char* kMedMesh = "BODYMESH";
}  // namespace

std::string code_aster_comm(const DeckRequest& r, const TetMesh& m, const PatchLoad* patch) {
  const DeckOptions& o = r.options;
  std::ostringstream s;
  const bool plastic = r.material.model == MaterialModel::plastic;
  s << header_lines("#", r, std::string("Code_Aster command file (") + (plastic ? "DYNA_NON_LINE" : "DYNA_VIBRA") +
                                ", versions 15.x and later)");
  s << "# Files (units): mesh.med (20), probe velocity tables (38), von Mises at the probes and LOAD (39),\n"
       "# results MED (80); see impact.export.\n";
  s << "DEBUT()\n\n";
  s << "MAIL = LIRE_MAILLAGE(FORMAT='MED', UNITE=20)\n\n";
  s << "MODELE = AFFE_MODELE(MAILLAGE=MAIL,\n"
       "                     AFFE=_F(GROUP_MA=('BODY',), PHENOMENE='MECANIQUE', MODELISATION='3D'))\n\n";
  if (plastic) {
    s << "# Elastic-plastic: von Mises with linear isotropic hardening (ECRO_LINE: D_SIGM_EPSI = the tangent\n"
         "# modulus E_t, 0 = perfectly plastic; SY = the yield strength), run by DYNA_NON_LINE with VMIS_ISOT_LINE\n"
         "# in large strains (GDEF_LOG); V1 of VARI_NOEU is the cumulated plastic strain.\n";
  }
  s << "MATER = DEFI_MATERIAU(ELAS=_F(E=" << num(r.material.youngs_modulus_Pa * r.options.units.per_Pa())
    << ", NU=" << num(r.material.poisson_ratio) << ", RHO=" << num(r.material.density_kg_m3 * r.options.units.per_kg_m3())
    << ")";
  if (plastic) {
    s << ",\n                      ECRO_LINE=_F(D_SIGM_EPSI="
      << num(r.material.tangent_modulus_Pa.value_or(0.0) * r.options.units.per_Pa())
      << ", SY=" << num(r.yield_strength_Pa.value_or(0.0) * r.options.units.per_Pa()) << ")";
  }
  s << ")\n\n";
  s << "CHMAT = AFFE_MATERIAU(MAILLAGE=MAIL, AFFE=_F(GROUP_MA=('BODY',), MATER=MATER))\n\n";
  auto function = [&](const std::string& name, const std::vector<double>& t, const std::vector<double>& f) {
    s << name << " = DEFI_FONCTION(NOM_PARA='INST',\n                      VALE=(\n";
    for (std::size_t i = 0; i < t.size(); ++i) s << "                          " << num(t[i]) << ", " << num(f[i]) << ",\n";
    s << "                      ),\n"
         "                      INTERPOL=('LIN', 'LIN'),\n"
         "                      PROL_GAUCHE='CONSTANT',\n"
         "                      PROL_DROITE='CONSTANT')\n";
  };
  auto force_on = [&](const std::string& name, const std::string& group) {
    s << name << " = AFFE_CHAR_MECA(MODELE=MODELE,\n                        FORCE_NODALE=_F(GROUP_NO=('" << group
      << "',), FX=" << num(r.direction.x()) << ", FY=" << num(r.direction.y()) << ", FZ=" << num(r.direction.z())
      << "))\n";
  };
  std::string excit;
  if (patch) {
    s << "# Hertz-patch load: one force history (N) per surface node LPk, along the unit direction of the\n"
         "# force; at every time the forces sum to F(t) and have no moment about the contact point.\n";
    for (std::size_t k = 0; k < patch->nodes.size(); ++k) {
      const std::string id = std::to_string(k + 1);
      function("FP" + id, patch->time_s, patch->force_N[k]);
      force_on("CP" + id, "LP" + id);
      excit += std::string(excit.empty() ? "" : ",\n                         ") + "_F(CHARGE=CP" + id + ", FONC_MULT=FP" + id + ")";
    }
    s << "\n";
  } else {
    s << "# Hertz force history F(t) in N; constant extrapolation on both sides, closing zero.\n";
    function("FHERTZ", r.force.time_s, r.force.force_N);
    s << "\n# Unit direction of the force on the target (times FHERTZ).\n";
    force_on("CHARGE", "LOAD");
    s << "\n";
    excit = "_F(CHARGE=CHARGE, FONC_MULT=FHERTZ)";
  }
  const TimeSchedule ts = deck_schedule(r);
  s << "# Time steps: refined through the end of the contact, then the main step.\n";
  s << "LINST = DEFI_LIST_REEL(DEBUT=0.0,\n                       INTERVALLE=(";
  for (const TimeSegment& g : ts.pulse_segments) {
    s << "_F(JUSQU_A=" << num(g.end_s) << ", PAS=" << num(g.step_s) << "),\n                                   ";
  }
  s << "_F(JUSQU_A=" << num(o.end_time_s) << ", PAS=" << num(ts.main_step_s) << ")))\n\n";
  if (plastic) {
    s << "# Implicit Newmark (average acceleration, as the elastic deck) with Newton on the tangent matrix.\n";
    s << "RESU = DYNA_NON_LINE(MODELE=MODELE,\n"
         "                     CHAM_MATER=CHMAT,\n"
         "                     EXCIT=(" << excit << "),\n"
         "                     COMPORTEMENT=_F(RELATION='VMIS_ISOT_LINE', DEFORMATION='GDEF_LOG', GROUP_MA=('BODY',)),\n"
         "                     INCREMENT=_F(LIST_INST=LINST),\n"
         "                     SCHEMA_TEMPS=_F(SCHEMA='NEWMARK', BETA=0.25, GAMMA=0.5, FORMULATION='DEPLACEMENT'),\n"
         "                     NEWTON=_F(MATRICE='TANGENTE', REAC_INCR=1, REAC_ITER=1),\n"
         "                     CONVERGENCE=_F(RESI_GLOB_RELA=1.0e-06, ITER_GLOB_MAXI=20))\n\n";
  } else {
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
         "                  EXCIT=(" << excit << "))\n\n";
  }
  s << "# Von Mises stress (component VMIS)" << (patch ? "" : "; singular at the load node itself (point force)") << ".\n";
  s << "RESU = CALC_CHAMP(reuse=RESU,\n"
       "                  RESULTAT=RESU,\n"
       "                  CONTRAINTE=('SIGM_ELNO',),\n"
       "                  CRITERES=('SIEQ_ELNO', 'SIEQ_NOEU')" << (plastic ? ",\n                  VARI_INTERNE=('VARI_ELNO', 'VARI_NOEU')" : "") << ")\n\n";
  const auto probes = probe_groups(m);
  if (!probes.empty()) s << "# Velocity of each probe node, " << to_string(r.options.units.length) << "/s, one table per component (unit 38).\n";
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
  s << "# Von Mises (" << r.options.units.stress_unit() << ") against time at each probe and at LOAD (unit 39).\n";
  std::vector<std::string> at = probes;
  at.push_back("LOAD");
  for (std::size_t i = 0; i < at.size(); ++i) {
    const std::string f = i + 1 == at.size() ? "VMLOAD" : "VM" + std::to_string(i + 1);
    s << f << " = RECU_FONCTION(RESULTAT=RESU, NOM_CHAM='SIEQ_NOEU', NOM_CMP='VMIS', GROUP_NO=('" << at[i] << "',))\n";
  }
  s << "IMPR_FONCTION(FORMAT='TABLEAU', UNITE=39,\n              COURBE=(";
  for (std::size_t i = 0; i < at.size(); ++i) {
    s << (i ? ", " : "") << "_F(FONCTION=" << (i + 1 == at.size() ? std::string("VMLOAD") : "VM" + std::to_string(i + 1)) << ")";
  }
  s << "))\n\n";
  s << "IMPR_RESU(FORMAT='MED', UNITE=80,\n"
       "          RESU=_F(RESULTAT=RESU, NOM_CHAM=('DEPL', 'VITE', 'SIEQ_NOEU'" << (plastic ? ", 'VARI_NOEU'" : "") << ")))\n\n";
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
    << "P ncpus " << r.options.aster_cpus << "\n"
    << "P mpi_nbcpu " << r.options.aster_mpi_processes << "\n"
    << "P mpi_nbnoeud 1\n"
    << "F comm " << kJobName << ".comm D 1\n"
    << "F mmed mesh.med D 20\n"
    << "F mess " << kJobName << ".mess R 6\n"
    << "F resu " << kJobName << ".resu R 8\n"
    << "F libr " << kJobName << "_probes.txt R 38\n"
    << "F libr " << kJobName << "_von_mises.txt R 39\n"
    << "F rmed " << kJobName << "_results.rmed R 80\n";
  return s.str();
}

std::vector<std::string> CodeAsterSolver::write_deck(const DeckInput& in, const std::filesystem::path& folder) const {
  const DeckRequest& r = in.request;
  write_med(in.mesh, folder / "mesh.med", kMedMesh, r.options.units.length);
  write_file_atomically(folder / (std::string(kJobName) + ".comm"), code_aster_comm(r, in.mesh, in.patch));
  write_file_atomically(folder / (std::string(kJobName) + ".export"), code_aster_export(r, in.mesh));
  return {"mesh.med", std::string(kJobName) + ".comm", std::string(kJobName) + ".export"};
}

}  // namespace impactdeck::fem_export::code_aster
