#pragma once
// The pipeline a scene drives: bodies -> contact geometry -> impact -> force table -> outputs.
// Stages run only when the scene needs them; the report says which ran, which were skipped and
// how long each took.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/collision/impact.hpp"
#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/contact/impact.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/sequence/sequence.hpp"

namespace impactdeck::scene {

/// One impact of a run: the impact computed once (contact::Impact: the contact, the kernel's result
/// completed with the force history and checks, the validity) and what the run made of it.
struct ImpactReport : contact::Impact {
  /// A copy of the scene's impact: the report stays valid after the Scene it came from is gone.
  std::shared_ptr<const ImpactSpec> spec;
  /// The contact law (impact_law) and what it did (docs/plastic.md).
  ImpactLaw law;
  /// The law that ran, said in every output: law.name, except "hertz" where "auto" chose a plastic
  /// law and V <= V_y (the plastic law is then exactly Hertz with R = 1).
  std::string contact_law;
  std::optional<double> yield_velocity_m_s;  ///< V_y at this impact's m*, E*, R* and p_y (unset: no p_y)
  double dent_radius_m = 0;       ///< sqrt(R* d*) when the law leaves a dent, else 0
  /// R_p of the unloading curve F = 4/3 E* sqrt(R_p) (d - d_p)^1.5 through (d*, F*): R* for Hertz.
  double unloading_radius_m = 0;
  bool plastic() const { return contact_law != "hertz"; }
  std::optional<collision::ForceTable> table;
  std::optional<std::filesystem::path> table_path;  ///< where the CSV was written
  std::optional<std::filesystem::path> plot_path;   ///< where the F(t) SVG was written
  std::optional<fem_export::DeckResult> fem_deck;    ///< [outputs.fem]: the deck folder
  std::optional<fem_export::CheckResult> fem_check;  ///< [outputs.fem] run = "calculix"
  /// [outputs.fem] compare_contact = true: the full-contact model against the analytic force
  std::optional<CompareReport> compare;
  /// An impact of a sequence where no Hertz force exists (a sharp corner, a flat face): why. Its
  /// jumps are the rigid impulse's; the force, the law's figures and the checks are not applicable
  /// (null in JSON). Empty for every Hertzian impact.
  std::string force_not_applicable;
};

/// One [[sequences]] entry as run (docs/sequences.md): the sequence and one ImpactReport per
/// impact (the Hertzian ones as `run` solves a single impact; the others with their rigid jumps).
struct SequenceReport {
  std::shared_ptr<const SequenceSpec> spec;
  sequence::SequenceResult result;
  std::vector<ImpactReport> impacts;  ///< impacts[i] is result.bounces[i]
  std::optional<std::filesystem::path> trajectory_csv, trajectory_pvd, plot_svg;  ///< where written
  std::size_t vtk_frames = 0;
  /// With [outputs.fem] and spec->fem not "none": the impacts that got an FEM deck (impacts[i].fem_deck,
  /// fem_check), in order, and those asked for that got none, each with why (no force applies).
  std::vector<std::size_t> fem_impacts;
  struct NoDeck {
    std::size_t index = 0;
    std::string reason;
  };
  std::vector<NoDeck> fem_not_meshed;
  bool fem_requested = false;  ///< the scene has [outputs.fem] and spec->fem is not "none"
};

/// The FEM deck folder of impact `index` of sequence `name` (docs/sequences.md).
std::string sequence_fem_folder(const std::string& name, std::size_t index);

struct StageTiming {
  std::string name;
  double seconds = 0;
};

struct RunReport {
  std::vector<ImpactReport> impacts;
  std::vector<SequenceReport> sequences;
  std::vector<StageTiming> stages_run;
  std::vector<std::string> stages_skipped;
  std::vector<std::string> warnings;
  std::vector<std::filesystem::path> files_written;
  /// The length unit of every geometric output (the FEM decks' unit system, DeckUnits).
  LengthUnit output_length_unit = LengthUnit::m;
  bool all_checks_passed() const;
};

struct RunOptions {
  std::filesystem::path out_dir = ".";  ///< outputs are written here (created if missing)
  std::ostream* progress = nullptr;     ///< solver progress lines (e.g. &std::cerr)
  /// ccx wall-time limit per deck (--solver-timeout-s); 0: derived from the deck's size.
  double solver_timeout_s = 0;
  int solver_threads = 0;               ///< threads for ccx ([outputs.fem] run); 0: all cores
  /// Length unit of every geometric output (--output-length-unit); unset: the scene's length_unit.
  std::optional<LengthUnit> output_length_unit;
  /// Called with the complete report after every output is staged, just before the commit
  /// publishes them (files_written and the stages final). The CLI prints stdout here: when that
  /// fails it throws, and the run is rolled back (nothing published).
  std::function<void(const RunReport&)> before_commit;
};

/// Builds the shape of a body (analytic or mesh). Throws InputError.
/// For a mesh body, the stages mesh_load, mesh_validation and curvature_index, and the part's
/// warnings, are recorded in `report` when given.
std::shared_ptr<const geometry::Shape> make_shape(const BodySpec& body, const Scene& scene,
                                                  RunReport* report = nullptr);

/// Mass, inertia, material and placement of a body from its spec.
contact::PreparedBody prepare_body(const BodySpec& body, const Scene& scene, RunReport* report = nullptr);

/// Runs everything the scene asks for. Throws InputError on bad input; a failed self-check is
/// reported (see all_checks_passed, failed_checks.hpp), not thrown. One transaction
/// (common/run_transaction.hpp): every output, deck folders and solver results included, is staged
/// inside `out_dir` and published at once when every stage has run, even when a self-check failed
/// (the outputs are the evidence); after an error (an exception) nothing is visible.
RunReport run_scene(const Scene& scene, const RunOptions& options = {});

/// The names of every output `scene` writes, checked as `run` checks them before any work
/// (RunTransaction::check_name: relative, no '..', no control character, ...), without writing:
/// `campaign plan` validates each case with it. Throws InputError naming the scene key (the
/// override that set it), inside `context` (the campaign file and case) when it names a file.
void check_output_names(const Scene& scene, const InputContext& context = {});

/// Where the bodies of impact `s` touch, as `run` finds it (point mode: the projected point, else
/// the first contact); a point where Hertz does not apply comes back flagged. Throws InputError.
contact::ContactEvaluation locate_impact_contact(const Scene& scene, const ImpactSpec& s, const contact::ContactModel& model);

/// `run`'s impact `s` at a located contact `contact` (flag none) of `model`: its numbers checked
/// against double precision's range (naming the scene keys), the kernel's result completed
/// (contact::complete_impact: the kernel is not solved again) and the validity assessed; its
/// warnings appended to `warnings`. Throws InputError.
/// `law` is impact_law(scene, s, ...), the law `model` holds.
ImpactReport solve_located_impact(const Scene& scene, const ImpactSpec& s, const ImpactLaw& law,
                                  const contact::ContactModel& model, contact::ContactEvaluation contact,
                                  std::vector<std::string>& warnings);

/// The scene's force-table options for impact `s`, their errors naming the [outputs] keys' lines
/// and the impact (ForceTableOptions' contexts).
collision::ForceTableOptions force_table_options(const Scene& scene, const ImpactSpec& s);

/// The hybrid deck request `run` builds for an impact (scene.outputs.fem must be set; `ir.table`
/// sampled): the body `body` alone in its own frame with the force on the target; its context
/// names the scene's [outputs.fem] key and the impact. Throws InputError.
fem_export::DeckRequest hybrid_deck_request(const Scene& scene, const ImpactReport& ir, const contact::PreparedBody& body);

/// The stage of [[sequences]] (stages_run): every impact of every sequence.
inline constexpr const char* kSequenceStage = "sequence";

/// Every stage the tool knows, in pipeline order (for stages_run / stages_skipped).
const std::vector<std::string>& all_stages();

}  // namespace impactdeck::scene
