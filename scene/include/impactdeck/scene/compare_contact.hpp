#pragma once
// `impactdeck compare-contact`: one impact of a scene run twice in CalculiX, as the hybrid deck
// (the target alone, loaded by the analytic Hertz force: decks.hpp) and as a full-contact model
// (both bodies meshed, penalty contact: contact_model.hpp), both compared with the analytic force
// (docs/contact-vs-hybrid.md). An elastic full-contact model's reference is the elastic Hertz
// impact (R = 1): F_max and t_m are the analytic model's, the duration 2 t_m, the impulse 2 m_w v_w,
// the jumps the model's times 2 / (1 + R). With material_model plastic both bodies (those whose
// material has a yield strength) are elastic-plastic in ccx, the reference is the impact's own law
// (its F_max, t_c, restitution and dent), and every plastic law's figures are compared too.
// A plane floor becomes a block under the contact, its bottom held; a fixed body is held by its
// far side (contact_model.hpp); its mass is infinite in the impact as in the kernel.
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/contact_model.hpp"
#include "impactdeck/contact/impact.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::scene {

struct CompareOptions {
  std::string impact;                    ///< empty: the scene's only (or first) impact
  std::filesystem::path out_dir = ".";   ///< must exist; folders hybrid/, contact_L<k>/ and files go here
  double threshold = 0.03;               ///< |F_max contact / analytic - 1| above it: exit 4
  int refine = 0;                        ///< extra contact runs, each with sqrt(2) x contact_elements
  fem_export::ContactModelOptions contact;
  bool run_hybrid = true;                ///< false: the contact model only (tests)
  /// false (`--decks-only`): write the hybrid and full-contact decks (meshes, contact.json) and run
  /// nothing; the report's verdict is decks_only, with no force or check figures.
  bool run_solvers = true;
  double solver_timeout_s = 0;           ///< per ccx run; 0: derived from each deck's size
  /// plastic: both bodies elastic-plastic (`--material-model plastic`); the scene's [outputs.fem]
  /// material_model = "plastic" does the same.
  fem_export::MaterialModel material_model = fem_export::MaterialModel::elastic;
  int solver_threads = 0;                ///< ccx threads; 0: all cores
  std::ostream* progress = nullptr;
  /// Where each output goes: `name` is "hybrid", "contact", "contact_L<k>" (folders) or
  /// "compare_force.svg" (file). Unset: out_dir / name. `compare-contact` reserves the names in its
  /// run transaction (staged, published only when the comparison completed).
  std::function<std::filesystem::path(const std::string& name, bool is_folder)> place_output;
  /// Where the comparison was asked for (`run`: the scene file, its [outputs.fem] compare_contact
  /// key and the impact): every error about the scene and the decks comes after it. Empty: the
  /// errors name the scene file and their own places (the compare-contact command).
  InputContext context;
};

/// One rung of the refinement ladder.
struct ContactLevel {
  double contact_elements = 0;
  fem_export::ContactDeck deck;
  fem_export::ContactRunResult run;
  double max_force_relative_difference = 0;  ///< F_max / analytic - 1
};

/// decks_only: the decks were written and no solver ran (CompareOptions::run_solvers false).
enum class CompareVerdict { agree, disagree, non_hertzian, decks_only };

/// The laws compared with a plastic full-contact run (docs/plastic.md, "The ladder").
inline const std::vector<std::string> kComparedLaws = {"hertz", "thornton", "jackson-green", "jackson-green-sneddon"};
/// The plastic (quasi-static) comparison's first run pushes to this times the largest x_max of the
/// compared laws: past the FE contact's own turning point unless it is softer than every law (then
/// the run is repeated at twice the approach, contact_model.hpp).
inline constexpr double kProbeApproachFactor = 1.5;

/// One law's figures at the compared impact's point (the kernel solved again with that law; Hertz
/// with R = 1). `problem` says why there are none (e.g. a sharp point for Hertz).
struct LawFigures {
  std::string name;
  std::optional<double> limiting_pressure_Pa;
  double max_force_N = 0, contact_time_s = 0, restitution = 0, residual_indentation_m = 0;
  double max_indentation_m = 0;
  std::string problem;
};
const char* to_string(CompareVerdict v);

struct CompareReport {
  std::string impact, target, impactor;
  CompareVerdict verdict = CompareVerdict::agree;
  std::string non_hertzian_reason;  ///< the kernel's flag explained
  std::string in_doubt;             ///< disagree: "contact mesh" or "hybrid assumptions"
  std::string explanation;          ///< one sentence saying why
  double threshold = 0.03;          ///< the options' threshold the verdict used
  // The analytic (elastic) impact.
  double analytic_max_force_N = 0, analytic_compression_time_s = 0, analytic_duration_s = 0;
  double analytic_impulse_Ns = 0, impact_energy_J = 0;  ///< 2 m_w v_w, 1/2 m_w v_w^2
  double restitution = 1, assumed_loss_fraction = 0;    ///< the scene's R and 1 - R^2
  double semi_axis_a_m = 0, semi_axis_b_m = 0;
  bool plastic = false;           ///< material_model plastic: the analytic figures are the law's
  std::string law;                ///< the law the analytic figures are of ("hertz" when elastic)
  bool law_automatic = false;     ///< chosen by contact_law = "auto"
  std::optional<double> limiting_pressure_Pa, yield_velocity_m_s;
  double approach_velocity_m_s = 0;
  double analytic_residual_indentation_m = 0;  ///< the law's dent (plastic)
  std::vector<LawFigures> laws;   ///< plastic: each of kComparedLaws
  /// A fixed body (a plane floor as a block, or a fixed body held by its far side): its name and
  /// the block's half-width and depth (0 for a fixed body).
  std::string fixed_body, fixed_kind;
  double floor_block_size_m = 0;
  Eigen::Vector3d analytic_target_dv = Eigen::Vector3d::Zero(), analytic_target_dw = Eigen::Vector3d::Zero();
  Eigen::Vector3d analytic_impactor_dv = Eigen::Vector3d::Zero(), analytic_impactor_dw = Eigen::Vector3d::Zero();
  std::vector<ContactLevel> ladder;  ///< coarse to fine; the last one is compared
  std::optional<fem_export::DeckResult> hybrid_deck;
  std::optional<fem_export::CheckResult> hybrid_check;
  double hybrid_max_force_N = 0;  ///< the applied table's maximum
  std::size_t hybrid_increments = 0;
  /// The hybrid FE target's rigid-body jumps (momentum / FE mass, I_FE^-1 L_FE), world frame.
  Eigen::Vector3d hybrid_target_dv = Eigen::Vector3d::Zero(), hybrid_target_dw = Eigen::Vector3d::Zero();
  std::vector<std::string> warnings;
  std::vector<std::filesystem::path> files;
  std::vector<double> analytic_time_s, analytic_force_N;  ///< elastic curve sampled for the plot

  const ContactLevel* finest() const { return ladder.empty() ? nullptr : &ladder.back(); }
};

struct ImpactReport;

/// What the comparison takes of one impact, computed once by its caller: the impact itself (never
/// solved again), both prepared bodies and both bodies' deck requests.
struct CompareInput {
  std::string source;       ///< the scene file (errors name it when CompareOptions::context is empty)
  std::string impact_name;
  const contact::Impact* impact = nullptr;  ///< must outlive the call, as the bodies
  const contact::PreparedBody* target = nullptr;
  const contact::PreparedBody* impactor = nullptr;
  fem_export::DeckRequest target_deck;    ///< the target's hybrid deck request, its force table included
  fem_export::DeckRequest impactor_deck;  ///< the impactor's body and material (its load is unused)
  double impactor_mesh_size_m = 0;        ///< the impactor's far-field element size in the contact model
  std::vector<std::string> warnings;      ///< the report's first warnings
  /// A fixed body: target_fixed / impactor_fixed, and whether it is an infinite plane (meshed as a
  /// block under the contact). Its deck request holds its body (not for a plane) and material.
  bool target_fixed = false, impactor_fixed = false, target_plane = false, impactor_plane = false;
  bool plastic = false;  ///< material_model plastic ([outputs.fem] or CompareOptions)
  std::vector<LawFigures> laws;  ///< plastic: each of kComparedLaws at this impact
  std::optional<double> yield_velocity_m_s;
  std::string law = "hertz";  ///< the impact's law (the analytic figures' when plastic)
  bool law_automatic = false;
  std::optional<double> limiting_pressure_Pa;
};

/// The comparison's input for impact `ir` of `scene` (its force table sampled) between the run's
/// prepared bodies. Throws ctx.error(...) when both bodies are fixed, for a plastic comparison
/// without a yield strength, and the deck requests' InputErrors.
CompareInput compare_input(const Scene& scene, const ImpactReport& ir, const contact::PreparedBody& target,
                           const contact::PreparedBody& impactor, const InputContext& ctx);

/// Runs the comparison of an impact already computed (`run`'s stage compare_contact).
CompareReport compare_contact(const CompareInput& input, const CompareOptions& options);

/// `compare-contact`: impact `options.impact` of `scene`, its bodies prepared and the impact solved
/// as `run` does, then compared. Throws InputError (exit 3) on bad input: an unknown impact, two
/// fixed bodies, an elastic comparison with a plastic law. A contact where Hertz does not apply
/// gives the verdict non_hertzian.
CompareReport compare_contact(const Scene& scene, const CompareOptions& options);

/// Replaces every path of the report (deck folders, solver files, the plot) by `map(path)`: the
/// staged paths of a run transaction by their published ones.
void map_paths(CompareReport& r, const std::function<std::filesystem::path(const std::filesystem::path&)>& map);

nlohmann::json to_json(const CompareReport& r);
std::string format_compare(const CompareReport& r);

}  // namespace impactdeck::scene
