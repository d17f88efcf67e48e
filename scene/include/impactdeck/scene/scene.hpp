#pragma once
// Scene files (TOML): what to compute. Format documented in docs/scene-format.md.
// Every length in a scene is in its declared `length_unit`; the parsed Scene is SI.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/collision/validity.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/scene/body_shape.hpp"
#include "impactdeck/scene/overrides.hpp"

namespace impactdeck::scene {

/// Where a value came from in the scene file (for error messages).
struct Place {
  int line = 0;          ///< 1-based; 0 when unknown
  std::string key;       ///< dotted key path, e.g. "bodies[0].radius"
  /// The `--set` override that gave the value ("--set KEY"), empty when the file did: named instead
  /// of the line (an overridden value's line is the override's own text's).
  std::string override_place;
  std::string describe() const;  ///< "line 12, key 'bodies[0].radius'", or the override_place
};

struct Material {
  std::string name;
  collision::ElasticMaterial elastic;
  std::optional<double> density_kg_m3;
  /// Optional yield strength sigma_y (Pa): the validity report compares the peak Hertz pressure
  /// with the onset of yield, and the FEM verdict compares stresses with it.
  std::optional<double> yield_strength_Pa;
  /// Optional tangent (hardening) modulus E_t of a bilinear elastic-plastic material, in [0, E)
  /// (`tangent_modulus_Pa`; docs/plastic.md).
  std::optional<double> tangent_modulus_Pa;
  /// Optional Cowper - Symonds rate dependence of the flow stress, Y (1 + (rate/D)^(1/q)): D in 1/s
  /// and q, both or neither, with yield_strength_Pa (docs/plastic.md, "Rate effects").
  std::optional<double> cowper_symonds_D_per_s, cowper_symonds_q;
  Place place;
};

struct BodySpec {
  std::string name;
  /// The shape and its keys (`shape = "NAME"` and that shape's keys: body_shape.hpp). Never null
  /// in a parsed scene.
  std::shared_ptr<const ShapeSpec> shape;
  std::string material;
  std::optional<double> mass_kg;  ///< overrides density x volume; inertia scales with it
  bool fixed = false;             ///< infinite mass (always for a plane)
  /// Placement: world position of the body's own origin (`position`, length unit) and the rotation
  /// from its own frame into the world (`orientation_axis`, `orientation_angle_deg`, right hand).
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  bool placed = false;  ///< position or orientation given
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();            ///< world frame
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  ///< world frame
  /// `edge_radius` (length unit, > 0): the part's edge break. A contact on a sharp corner is a
  /// sphere of this radius, on a sharp edge a cylinder along the edge (docs/sharp-contacts.md).
  std::optional<double> edge_radius_m;
  Place place;
};

/// Which local radius the Hertz constant uses (the physics kernel's rule).
using ContactRadiusRule = collision::ContactRule;

struct ImpactSpec {
  std::string name;
  std::string target;
  std::string impactor;
  /// `point = [x, y, z]`: the target's own frame, projected on its surface; the impactor is placed
  /// to touch there. `point = "first-contact"`: both bodies as placed, the impactor moving along
  /// the relative velocity until they touch.
  bool first_contact = false;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  collision::RestitutionModel restitution;            ///< unit and policy from the scene top level
  bool restitution_given = false;  ///< `restitution` set in the scene (Hertz's, docs/plastic.md)
  /// `contact_law`: "auto" (the default) or a registered law's name (collision::contact_law_names);
  /// impact_law() turns it into the law that runs (docs/plastic.md).
  std::string contact_law = "auto";
  bool contact_law_given = false;  ///< `contact_law` set in the scene
  Place contact_law_place;         ///< where (errors about the law name it)
  std::optional<double> limiting_pressure_Pa;  ///< `limiting_pressure_Pa`: p_y of a plastic law
  /// `friction_coefficient`: Coulomb's mu at the point (>= 0, default 0: frictionless); > 0 gives
  /// the jumps of collision::solve_frictional_impact (docs/friction.md).
  double friction_coefficient = 0;
  ContactRadiusRule contact_radius = ContactRadiusRule::elliptical;
  std::optional<double> approach_speed_m_s;  ///< if set: impactor velocity = -speed * n
  std::optional<double> max_projection_distance_m;  ///< default: 1 % of the target's size
  Place place;
};

/// `[[sequences]]`: a free body dropped onto a plane, every bounce until it stops
/// (docs/sequences.md).
struct SequenceSpec {
  std::string name;
  std::string body;   ///< the free body that falls
  std::string floor;  ///< a plane body
  int max_impacts = 20;
  double min_approach_speed_m_s = 0.05;  ///< sequence::kDefaultMinApproachSpeed
  double friction_coefficient = 0;
  Place friction_place;  ///< where friction_coefficient was given (the key alone when it was not)
  /// The law keys (`restitution`, `contact_law`, `limiting_pressure_Pa`, `contact_radius`), read by
  /// the reader of [[impacts]]: target = body, impactor = floor, name = the sequence's.
  ImpactSpec impact;
  /// `fem` (docs/sequences.md): which impacts get the FEM deck, the ccx check and the verdict of a
  /// single impact when the scene has [outputs.fem]: the worst one (default), every one with a
  /// force, or none.
  enum class Fem { worst, all, none };
  Fem fem = Fem::worst;
  bool fem_given = false;
  Place fem_place;  ///< where `fem` was given (the key alone when it was not)
  Place place;
};

/// `fem = "all"` on a sequence is refused beyond this many impacts (`max_impacts`): each deck is a
/// Gmsh mesh and, with run = "calculix", a ccx run.
inline constexpr int kMaxSequenceFemDecks = 20;

/// `[outputs.fem]`: FEM decks of the hybrid approach (docs/fem.md). Present = requested.
struct FemOutputs {
  std::optional<double> mesh_size_m;       ///< default: smallest semi-axis / 2 (ellipsoid)
  std::optional<double> load_mesh_size_m;  ///< default: mesh size / 3
  double end_time_s = 0.02;                ///< the paper's 0.02 s
  double time_step_s = 1e-5;               ///< the paper's 1e-5 s
  /// Increments across the contact: unset ("auto"): at the force table's samples
  /// (fem_export::auto_pulse_schedule); N: N equal steps; 0: no refined phase.
  std::optional<int> pulse_increments;
  std::vector<Eigen::Vector3d> probes_m;   ///< in the target's frame
  bool code_aster = true;
  bool calculix = true;
  int aster_cpus = 1;           ///< Code_Aster .export `P ncpus`
  int aster_mpi_processes = 1;  ///< Code_Aster .export `P mpi_nbcpu`
  enum class Run { none, calculix } run = Run::none;  ///< "calculix": run ccx and the check
  /// `convergence`: "none" (one mesh) or "two-meshes": the deck again at half the element size,
  /// run and judged at the first mesh's distance from the load (fem_export/convergence.hpp);
  /// needs run = "calculix".
  enum class Convergence { none, two_meshes } convergence = Convergence::none;
  /// "point": F(t) on the contact node; "hertz-patch": the Hertz pressure of each instant's
  /// contact ellipse as nodal forces (docs/fem.md).
  enum class Load { point, hertz_patch } load = Load::point;
  int contact_elements = 4;          ///< hertz-patch: elements across the largest ellipse (short axis)
  double contact_zone_factor = 3.0;  ///< contact zone radius in contact semi-axes a_max
  /// Check thresholds; unset: fem_export::FemTolerances' defaults (docs/fem.md).
  struct Tolerances {
    std::optional<double> linear_momentum, angular_momentum, model_linear_velocity, model_angular_velocity,
        volume, mass, inertia, min_gamma;
  } tolerances;
  /// `max_elements`: most tetrahedra a deck may have (estimated before meshing); default
  /// fem_export::DeckOptions::max_elements.
  std::optional<std::size_t> max_elements;
  /// ccx's equation solver: "auto" (by deck size), "spooles", "iterative" (docs/fem.md).
  enum class Solver { automatic, spooles, iterative } solver = Solver::automatic;
  /// `compare_contact = true`: each impact is also run as a full-contact CalculiX model beside a
  /// hybrid deck with the same time steps (compare_contact.hpp, docs/contact-vs-hybrid.md); a
  /// contact F_max beyond `compare_contact_threshold` of the analytic one fails the run (exit 4).
  struct CompareContact {
    double threshold = 0.03;      ///< compare_contact_threshold
    int refine = 0;               ///< compare_contact_refine: extra rungs of the ladder
    double contact_elements = 3;  ///< compare_contact_elements: across the contact semi-axis b
    int contact_increments = 40;  ///< compare_contact_increments: across the contact duration
    double penalty_factor = 20;   ///< compare_contact_penalty_factor
  };
  std::optional<CompareContact> compare_contact;
  /// `material_model`: "elastic" (the default) or "plastic" (bilinear from the target material's
  /// yield_strength_Pa and tangent_modulus_Pa; docs/fem.md, "Plastic decks").
  enum class MaterialModel { elastic, plastic } material_model = MaterialModel::elastic;
  Place material_model_place;  ///< where the key is (errors about it name it)
  /// `deck_units`: the unit system of every file of the deck folder, "mm-t-s" or "SI"; unset:
  /// fem_export::default_deck_units of the run's output length unit (docs/fem.md, "Units").
  std::optional<LengthUnit> deck_length_unit;
  Place place;
};

struct Outputs {
  std::optional<std::filesystem::path> force_table_csv;  ///< relative to the output folder
  std::optional<std::filesystem::path> force_plot_svg;   ///< F(t) picture, relative to the output folder
  collision::ForceTableOptions force_table;
  std::optional<FemOutputs> fem;
  std::map<std::string, Place> places;  ///< line and key of the [outputs] keys given (messages)
};

struct Scene {
  std::filesystem::path file;  ///< as given (for messages); empty for in-memory text
  LengthUnit length_unit = LengthUnit::m;
  collision::ModulusConvention modulus_convention = collision::ModulusConvention::hertz;
  collision::CheckThresholds thresholds;
  collision::ValidityLimits validity;  ///< `[validity]`
  std::map<std::string, Material> materials;
  std::vector<BodySpec> bodies;
  std::vector<ImpactSpec> impacts;
  std::vector<SequenceSpec> sequences;
  /// `gravity_m_s2` (required with [[sequences]]).
  std::optional<Eigen::Vector3d> gravity_m_s2;
  Outputs outputs;

  const BodySpec& body(const std::string& name) const;  ///< throws InputError if unknown
};

/// Reads and validates a scene file. Throws InputError naming file, line, key and reason.
/// `overrides` (`--set`) change the TOML document before validation; an error in an overridden
/// value names the override ("--set KEY") as its place. `context`, when it names a file (a
/// campaign file and "case 7"), comes first in every error, with the scene file after it.
Scene load_scene(const std::filesystem::path& file, const std::vector<Override>& overrides = {},
                 const InputContext& context = {});

/// The file name `-`: the scene is read from standard input (`impactdeck run -`).
inline constexpr const char* kStdinScene = "-";
/// load_scene of `-`: standard input read whole (bounded as a scene file, kMaxSceneBytes); messages
/// name it `-`, and relative paths in it (parts) resolve against the current folder.
Scene load_scene_from_stdin(const std::vector<Override>& overrides = {});

/// Same from text; `name` is used in messages and relative mesh paths resolve against `base_dir`.
Scene parse_scene(const std::string& text, const std::string& name,
                  const std::filesystem::path& base_dir = ".", const std::vector<Override>& overrides = {},
                  const InputContext& context = {});

/// d*/R* beyond which a plastic law's small-strain assumption is flagged (docs/plastic.md).
inline constexpr double kPlasticMaxIndentationOverRadius = 0.1;

/// The contact law an impact runs, chosen from its keys (docs/plastic.md):
/// `contact_law` named: that law; "auto" (the default): "hertz" when `restitution` is set, when
/// neither body's material has a yield strength, or when [outputs.fem] compare_contact = true (its
/// full-contact model is elastic); else "jackson-green-sneddon" (Hertz with R = 1 up to 1.9 d_c).
struct ImpactLaw {
  std::string name;       ///< the registered law built ("hertz", "thornton", ...)
  bool automatic = false; ///< chosen by "auto"
  /// p_y: `limiting_pressure_Pa`, else collision::kThorntonYieldFactor x the weaker yield strength;
  /// unset when neither is known.
  std::optional<double> limiting_pressure_Pa;
  /// The plastic law "auto" runs when a yield strength is known and no restitution is set (empty
  /// when no yield strength is known): named by the warning of a scene that sets `restitution`.
  std::string plastic_law;
  /// The options `law` was built from (the sharp and line laws derived from it start from them).
  collision::LawOptions options;
  std::shared_ptr<const collision::ContactLaw> law;
};

/// The law of impact `s`. Throws InputError (ctx) for a law the registry refuses. `tabulated`:
/// a law that can read its impacts from a table (collision::LawOptions::tabulated) does (sweeps).
ImpactLaw impact_law(const Scene& scene, const ImpactSpec& s, const InputContext& ctx, bool tabulated = false);

/// The law at a point where one body is sharp (in.target/impactor.curvature.sharp with its feature;
/// no edge_radius rounded it): "wedge" on an edge, "cone" on a corner, at the hardness
/// limiting_pressure_Pa or collision::kTaborHardnessFactor x the yield strength, where `law` (of
/// impact_law) is a plastic one; nullopt where it is Hertz, which refuses the point
/// (docs/sharp-contacts.md).
std::optional<ImpactLaw> sharp_impact_law(const ImpactSpec& s, const ImpactLaw& law, const collision::KernelInput& in,
                                          const InputContext& ctx);

/// `law` with the line contact of an edge rounded by edge_radius in its place ("line" under Hertz, else
/// "line-plastic" at its p_y): where the rounding lies on a surface flat along the edge, or where the
/// elliptical contact's length reaches the edge's length (docs/sharp-contacts.md).
ImpactLaw line_impact_law(const ImpactLaw& law, const InputContext& ctx);

}  // namespace impactdeck::scene
