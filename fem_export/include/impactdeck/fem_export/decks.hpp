#pragma once
// FEM decks of the hybrid approach: the target body alone, meshed, with the impactor replaced by
// the Hertz force history at the contact node (or spread over the Hertz contact patch). One folder
// per impact holds everything a solver needs (files listed in docs/fem.md); it appears complete or
// not at all.
//
// Frames: every position and direction of a DeckRequest is in the TARGET's own frame (the
// coordinates of its part file, or the ellipsoid's axes): load point, force direction, probes,
// patch axis, and the rigid model's reference (centroid, inertia, velocity jumps). A caller that
// places bodies in a world frame transforms these into the target's frame first.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/fem_export/mesh.hpp"
#include "impactdeck/fem_export/patch_load.hpp"

namespace impactdeck::fem_export {

/// The job name of every deck: impact.inp (CalculiX), impact.comm / impact.export (Code_Aster);
/// each solver's files (solver.hpp) are named after it.
inline constexpr const char* kJobName = "impact";

/// The solver's unit system of a deck (`[outputs.fem] deck_units`): lengths in `length`, forces in
/// N, times in s, so masses in N s^2 / length unit and stresses in N / length unit^2. Two systems
/// are written: "mm-t-s" (mm, N, s, tonne; MPa; length mm) and "SI" (m, N, s, kg; Pa; length m).
/// Every file of the deck folder uses it and states it (docs/fem.md, "Units"). A cm or inch length
/// is only read back from decks written before deck_units (fem-check): never written.
struct DeckUnits {
  LengthUnit length = LengthUnit::mm;
  double per_m() const { return 1.0 / metres_per(length); }          ///< deck lengths per metre
  double per_kg() const { return metres_per(length); }               ///< deck masses per kg
  double per_Pa() const { return metres_per(length) * metres_per(length); }  ///< deck stresses per Pa
  double per_kg_m3() const { return per_Pa() * per_Pa(); }           ///< deck densities per kg/m^3
  double per_J() const { return per_m(); }                           ///< deck energies (N x length) per J
  /// "mm-t-s", "SI" (the key's values; deck.json deck_units); older decks' cm and inch systems:
  /// "cm-N-s-(100 kg)", "in-N-s-(N s^2/in)".
  std::string name() const;
  /// One line for the header comments: lengths, forces, times, masses, E, density, velocity.
  std::string description() const;
  std::string stress_unit() const;  ///< "MPa", "Pa" (older decks: "N/cm2", "N/in2")
  std::string mass_unit() const;    ///< "tonne", "kg"
  /// Whether a deck may be written in it (mm-t-s or SI).
  bool writable() const { return length == LengthUnit::mm || length == LengthUnit::m; }
};
inline constexpr const char* kDeckUnitsMmTS = "mm-t-s";
inline constexpr const char* kDeckUnitsSI = "SI";
/// "mm-t-s" or "SI" (exact spelling); nullopt for anything else.
std::optional<DeckUnits> parse_deck_units(std::string_view text);
/// The system of a scene that does not set deck_units: SI when the run's output length unit is m,
/// else mm-t-s (a mm, cm or inch scene: never a cm- or inch-based mass unit).
DeckUnits default_deck_units(LengthUnit output_length_unit);

/// The target's constitutive model in the decks (`[outputs.fem] material_model`).
enum class MaterialModel {
  elastic,  ///< linear elastic (the paper's): *ELASTIC / ELAS, DYNA_VIBRA
  /// elastic-plastic, von Mises with bilinear isotropic hardening from DeckRequest::yield_strength_Pa
  /// and DeckMaterial::tangent_modulus_Pa: ccx *PLASTIC with NLGEOM, Code_Aster ECRO_LINE with
  /// VMIS_ISOT_LINE in DYNA_NON_LINE; the equivalent plastic strain is read back (stress.hpp).
  plastic,
};
const char* to_string(MaterialModel m);

struct DeckMaterial {
  double youngs_modulus_Pa = 0;
  double poisson_ratio = 0;
  double density_kg_m3 = 0;
  MaterialModel model = MaterialModel::elastic;
  /// plastic: E_t in [0, E), the slope of the bilinear stress-strain curve past yield; unset:
  /// perfectly plastic (E_t = 0).
  std::optional<double> tangent_modulus_Pa;
};

/// The plastic strain up to which the hardening table is written (ccx's *PLASTIC holds the last
/// stress beyond its last row): 1, far past the strains of a dent (d/a ~ 0.1, strains ~ 0.2 a/R).
inline constexpr double kHardeningTableMaxStrain = 1.0;

/// One row of a hardening table: the yield stress after `plastic_strain` of equivalent plastic strain.
struct HardeningRow {
  double stress_Pa = 0;
  double plastic_strain = 0;
};
/// The bilinear (isotropic) hardening of `m` with yield strength `yield_Pa`: (Y, 0) and, when
/// E_t > 0, (Y + H eps, eps) at eps = kHardeningTableMaxStrain with the plastic modulus
/// H = E E_t / (E - E_t) (the slope against plastic strain of a line of slope E_t against total
/// strain). Linear between the rows, so two rows are exact; E_t = 0: the single row (Y, 0),
/// perfectly plastic.
std::vector<HardeningRow> hardening_table(const DeckMaterial& m, double yield_Pa);

/// part: a triangulated part from memory (mesh_part); cad: a STEP/IGES/BREP file meshed from its
/// B-rep (mesh_cad).
enum class BodyKind { ellipsoid, part, cad };

struct DeckBody {
  BodyKind kind = BodyKind::ellipsoid;
  Eigen::Vector3d semi_axes_m = Eigen::Vector3d::Zero();  ///< ellipsoid, centred at the origin
  std::filesystem::path cad;  ///< cad: the part file
  double cad_unit_m = 1e-3;   ///< cad: metres per file coordinate unit (a BREP; STEP/IGES state theirs)
  PartSurface surface;  ///< part: the loaded, validated (and repaired) triangulation, target frame
  std::string name;     ///< part: its file, named in messages
  /// Volume of the body, m^3, for the element-count estimate; 0: from the semi-axes (ellipsoid).
  double volume_m3 = 0;
};

/// How the force enters the deck.
enum class LoadKind {
  point,        ///< F(t) on the contact node (the paper's way; stresses near it are not meaningful)
  hertz_patch,  ///< the Hertz pressure of each instant's contact ellipse (patch_load.hpp)
};
const char* to_string(LoadKind k);

/// The rigid model's numbers the FE result is compared with (target frame, SI).
struct RigidReference {
  double mass_kg = 0;                                     ///< the part's exact mass
  double volume_m3 = 0;                                   ///< the part's exact volume
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  ///< about the centroid
  Eigen::Vector3d delta_velocity_m_s = Eigen::Vector3d::Zero();          ///< the target's jump
  Eigen::Vector3d delta_angular_velocity_rad_s = Eigen::Vector3d::Zero();
};

/// Whether the hit makes the part spin enough for its spin to be compared: the lever arm
/// |(p - c) x d| of the force about the part's centroid exceeds a tenth of its radius of gyration
/// sqrt(trace(I) / (2 m)). Below that the spin's share of the motion is under 1 % (its term in
/// 1/m_w is (lever / r_g)^2 of the linear one) and a relative error on it measures round-off of a
/// small difference (a faceted sphere's normal misses the centre by a few % of the radius).
bool spin_is_significant(const RigidReference& part, const Eigen::Vector3d& load_point_m,
                         const Eigen::Vector3d& direction);

/// Thresholds of the deck's checks; a miss fails the run (exit 4). Defaults: docs/fem.md.
struct FemTolerances {
  double linear_momentum = 1e-3;   ///< FE momentum vs the impulse (solver self-check)
  double angular_momentum = 1e-2;  ///< FE angular momentum vs (p - c) x Pi (solver self-check)
  /// FE rigid-body velocity (momentum / FE mass) vs the rigid model's delta v of the part: also
  /// carries the mesh's mass error.
  double model_linear_velocity = 0.05;
  /// FE spin (I_FE^-1 L_FE) vs the rigid model's delta omega (when spin_is_significant).
  double model_angular_velocity = 0.05;
  double volume = 0.05;    ///< |V_FE - V_part| / V_part
  double mass = 0.05;      ///< |M_FE - M_part| / M_part
  double inertia = 0.05;   ///< ||I_FE - I_part||_F / ||I_part||_F (about each one's centroid)
  double min_gamma = 0.01; ///< floor of Gmsh's gamma over the tetrahedra, after optimisation
};

/// CalculiX's equation solver for the implicit dynamic steps (`*DYNAMIC, DIRECT[, SOLVER=...]`).
enum class CcxSolver {
  automatic,  ///< by deck size: `iterative` from kIterativeSolverMinNodes nodes, else `spooles`
  spooles,    ///< ccx's default sparse direct solver (SPOOLES)
  iterative,  ///< SOLVER=ITERATIVE SCALING (diagonally scaled conjugate gradients)
};
/// From this many nodes `automatic` takes the iterative solver. Measured (bench/bench_ccx.cpp,
/// docs/fem.md): on decks of 173 to 5,108 nodes it ran 2.5 to 22 times faster per increment than
/// SPOOLES with the same momentum and probe stresses (to 4e-8); smaller decks, too coarse for
/// stresses and cheap either way, keep the direct solver.
inline constexpr std::size_t kIterativeSolverMinNodes = 150;
const char* to_string(CcxSolver s);
/// The solver a deck of `nodes` nodes is written with (`automatic` resolved).
CcxSolver ccx_solver_for(CcxSolver requested, std::size_t nodes);

/// DeckOptions::pulse_increments: the increments at the force table's samples.
inline constexpr int kAutoPulseIncrements = -1;
/// Auto: a table with more intervals than this (a force_table_time_step_s far finer than the
/// impulse needs) is stepped at every k-th sample, k the smallest keeping the count within it.
inline constexpr std::size_t kMaxAutoPulseIncrements = 2000;
/// Auto: a table of fewer intervals (a hand-made one) has each split so the contact gets at least
/// this many increments. ccx starts a step at each change of spacing; with a few coarse steps the
/// force's jump over one increment there shows in the momentum (a 3-sample triangle stepped at
/// its samples: 1.5e-3; the default Hertz table has ~32 intervals and meets 1.1e-4, docs/fem.md).
inline constexpr std::size_t kMinAutoPulseIncrements = 32;

struct DeckOptions {
  double end_time_s = 0.02;    ///< simulated time (the paper: 0.02 s)
  double time_step_s = 1e-5;   ///< solver step after the contact (the paper: 1e-5 s)
  /// Increments across the contact. kAutoPulseIncrements (the default): the force table's own
  /// samples, each interval split so no step exceeds time_step_s (the table's spacing is what its
  /// impulse tolerance needed; ccx then meets every sample, so the increments carry the table's
  /// impulse and peak exactly; auto_pulse_schedule). A number N: N equal steps across the contact
  /// (when finer than time_step_s); measured on the paper's case (69 us pulse), 7 steps of 1e-5 s
  /// miss 0.5 % of the impulse, 40 steps 5.4e-4, 160 steps 1.1e-4. 0 turns the refined phase off.
  int pulse_increments = -1;
  /// The solvers whose decks are written, by registry name (solver.hpp): "calculix" (impact.inp,
  /// mesh.inp), "code_aster" (mesh.med, impact.comm, impact.export). Files are written in the
  /// registry's order whatever the order here; an unknown name is refused.
  std::vector<std::string> solvers = {"calculix", "code_aster"};
  /// Whether `solvers` names `name`.
  bool writes(const std::string& name) const;
  int aster_cpus = 1;           ///< impact.export `P ncpus` (OpenMP threads of each Code_Aster process)
  int aster_mpi_processes = 1;  ///< impact.export `P mpi_nbcpu` (MPI processes)
  /// Most tetrahedra a deck may have (scene key outputs.fem.max_elements). Checked before meshing
  /// against estimate_tet_count (a mesh size too small for the body would run Gmsh for hours) and
  /// after it against the real count. Measured here: Gmsh makes about 1300 tetrahedra per second
  /// (151 000 in 118 s), so the default bounds meshing to minutes; ccx's implicit dynamics on
  /// such a mesh takes hours (its own limit: --solver-timeout-s).
  std::size_t max_elements = 500000;
  CcxSolver solver = CcxSolver::automatic;  ///< impact.inp's equation solver
  /// The decks' unit system (every file of the folder: .geo, .msh, MED, .inp, .comm, the part
  /// STL, and the result files after a ccx run): mm-t-s or SI (writable(); others are refused).
  DeckUnits units;
  MeshOptions mesh;
  /// The mesh size is a default, not the user's: while the FE body's volume or inertia (of the
  /// tetrahedra, or of ccx's mass matrix) differs from the part's by more than half its
  /// tolerance, mesh again at size / sqrt(2) (at most
  /// kMaxSizeRefinements times; each try is listed in MeshQuality::attempts).
  bool adapt_mesh_size = false;
  static constexpr int kMaxSizeRefinements = 4;
  LoadKind load = LoadKind::point;
  /// hertz_patch: the load element size is at most 2 b_max / contact_elements, so the largest
  /// ellipse spans at least this many elements along its short axis.
  int contact_elements = 4;
  /// Radius of the contact zone (von Mises inside it is reported apart) in contact semi-axes
  /// a_max; it is never less than 2 load element sizes.
  double contact_zone_factor = 3.0;
  /// The contact zone is never smaller than this (m): the refined mesh of a convergence check
  /// judges its stress at the first mesh's distance (convergence.hpp).
  double min_contact_zone_radius_m = 0;
  FemTolerances tolerances;
  /// ccx writes stresses and displacements (.frd) every increment; when nodes x increments of the
  /// free-vibration step would exceed this, every k-th increment instead (velocities too).
  double stress_output_budget = 4e6;
};

struct DeckRequest {
  std::string source;   ///< scene file named in the headers
  std::string impact;   ///< impact name
  DeckBody body;
  DeckMaterial material;
  collision::ForceTable force;  ///< F(t) on the target, N vs s; first and last force 0
  double impulse_Ns = 0;        ///< exact impulse of the force history (the checks' reference)
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();     ///< unit direction of the force
  Eigen::Vector3d load_point_m = Eigen::Vector3d::Zero();  ///< target frame, on the surface
  /// The contact ellipse at the force's maximum: always given (the contact zone's size); the
  /// patch load uses it when options.load is hertz_patch.
  ContactPatch patch;
  RigidReference model;                     ///< the rigid model (FE-vs-model checks)
  std::optional<double> yield_strength_Pa;  ///< the target's material: the stress verdict
  /// What the contact law says about the dent (the plastic verdict reports them): the law that
  /// ran, the residual dent summed over both bodies and the dent radius sqrt(R* d*) (0: none).
  std::string contact_law;
  double residual_indentation_m = 0;
  double dent_radius_m = 0;
  DeckOptions options;
  /// Where the request comes from (`run`: the scene file, its [outputs.fem] key and the impact):
  /// an error about the request or its meshing names it, then the deck folder or the file meshed
  /// (InputContext::in_file). Empty: the deck folder or that file alone.
  InputContext context;
};

/// The FE body against the part of the rigid model: geometry only, known before any solver run.
struct BodyComparison {
  double fe_volume_m3 = 0, part_volume_m3 = 0, volume_relative_error = 0;
  double fe_mass_kg = 0, part_mass_kg = 0, mass_relative_error = 0;
  /// ||I_FE - I_part||_F / ||I_part||_F, each about its own centroid (I_FE of the tetrahedra)
  double inertia_relative_error = 0;
  /// The same for the inertia of ccx's C3D4 mass matrix (TetMassProperties::one_point_inertia):
  /// what the FE spin follows. Reported; the adaptive default size keeps it within half the
  /// inertia tolerance too.
  double solver_inertia_relative_error = 0;
  double centroid_offset_m = 0;  ///< |c_FE - c_part|
  /// What the FE-vs-model velocity checks will find if the solver conserves momentum exactly:
  /// |Pi/M_FE - dv| / |dv| and |I_1pt^-1 ((p - c_FE) x Pi) - dw| / |dw| (null: central hit).
  std::optional<double> predicted_model_linear_velocity_error, predicted_model_angular_velocity_error;
  double min_gamma = 0;          ///< Gmsh's gamma (tet_gamma)
  double min_radius_ratio = 0;
  FemTolerances tolerances;
  bool passed = false;
  std::vector<std::string> failures;  ///< one line per missed threshold
};
/// The mesher's tries as JSON (mesh_attempts: surface, algorithm_2d, algorithm_3d, mesh_size_m,
/// load_mesh_size_m, outcome).
nlohmann::json to_json(const std::vector<MeshAttempt>& attempts);

/// Compares the tetrahedra (density `density_kg_m3`) with the part; with the impulse vector
/// (Pi times the force direction, N s) and the load point, also predicts the velocity checks.
BodyComparison compare_body(const TetMesh& mesh, double density_kg_m3, const RigidReference& part,
                            const FemTolerances& tolerances,
                            const Eigen::Vector3d& impulse_Ns = Eigen::Vector3d::Zero(),
                            const Eigen::Vector3d& load_point_m = Eigen::Vector3d::Zero());
/// JSON (keys in docs/fem.md; relative errors null without a part reference) and text lines.
nlohmann::json to_json(const BodyComparison& c);
std::string format_body(const BodyComparison& c);

/// What the patch load did (hertz_patch only).
struct PatchSummary {
  std::size_t load_node_count = 0;  ///< nodes that carry force at some time (1 for a point load)
  std::size_t max_nodes_loaded_at_once = 0;
  std::size_t patch_triangles = 0;
  double largest_ellipse_elements = 0;
  std::size_t point_load_samples = 0;
  double max_sum_relative_error = 0, max_moment_relative = 0;
};

struct DeckResult {
  std::filesystem::path folder;
  std::vector<std::filesystem::path> files;  ///< every file of the folder, in writing order
  DeckUnits units;                           ///< the unit system of every file of the folder
  MeshQuality quality;
  std::size_t node_count = 0, tet_count = 0;
  double mesh_seconds = 0;   ///< wall time of the meshing (Gmsh, every try and re-mesh)
  double decks_seconds = 0;  ///< wall time of the rest: patch load, body check, every file written
  LoadKind load = LoadKind::point;
  PatchSummary patch;
  double contact_zone_radius_m = 0;
  /// plastic: plastic strain within this distance of the contact point is local (stress.hpp,
  /// kLocalPlasticZoneFactor): max(3 max(a_max, dent radius), 2 load element sizes).
  double plastic_zone_radius_m = 0;
  BodyComparison body_check;
  nlohmann::json description;  ///< deck.json's contents, as written
  TetMesh mesh;               ///< the mesh of mesh.inp and mesh.med, in metres, as meshed
};

/// Equal increments from the previous segment's end (or 0) through end_s.
struct TimeSegment {
  std::size_t increments = 0;
  double step_s = 0, end_s = 0;
};

/// The time stepping of a deck: a refined phase through the end of the contact (one segment per
/// run of equal steps), then the user's step through end_time_s (adjusted down so that it divides
/// the remaining time).
struct TimeSchedule {
  std::vector<TimeSegment> pulse_segments;  ///< empty: no refined phase
  std::size_t pulse_increments = 0;         ///< over pulse_segments
  double pulse_step_s = 0;                  ///< the smallest step of pulse_segments
  double pulse_end_s = 0;
  std::size_t main_increments = 0;
  double main_step_s = 0;
};
/// The schedule of options.pulse_increments equal steps across the contact (0 or more; the
/// refined phase only when its step is finer than time_step_s).
TimeSchedule time_schedule(const DeckOptions& options, double contact_end_s);
/// The auto schedule (kAutoPulseIncrements): a segment per run of equal spacing of the table
/// (a Hertz table has two, compression and restitution), each table interval split into
/// ceil(spacing / time_step_s) increments (more if the table has under kMinAutoPulseIncrements
/// intervals); kMaxAutoPulseIncrements bounds the count.
TimeSchedule auto_pulse_schedule(const DeckOptions& options, const collision::ForceTable& force);
/// The request's schedule: auto_pulse_schedule or time_schedule by options.pulse_increments.
TimeSchedule deck_schedule(const DeckRequest& request);

/// What the increments of a schedule make of the force table: ccx evaluates the amplitude (the
/// table, linear between its samples) at the end of each increment, and for a free body its
/// implicit scheme (HHT, any alpha) adds to the momentum the trapezoidal rule over the increment
/// ends (the stiffness terms sum to zero; a change of step size where the force is F shifts it by
/// ~ |alpha| (1 - gamma) |dt' - dt| |dF|, dF the force's change over a step: ~0 at the peak and
/// at the contact's end, where the auto schedule changes step).
struct ForceSampling {
  double impulse_relative_error = 0;     ///< |sum over increments - table impulse| / table impulse
  double peak_force_relative_error = 0;  ///< 1 - (largest force at an increment) / (table's largest)
};
ForceSampling force_sampling(const collision::ForceTable& force, const TimeSchedule& schedule);

/// Tetrahedra Gmsh makes for a body of `volume_m3` at the global size `mesh_size_m`, refined to
/// `load_mesh_size_m` (0: a third) around a surface load point as the decks' size field does.
/// Calibrated on Gmsh 4.8.4 meshes (docs/reliability.md: real counts 0.78 to 1.07 times the
/// estimate from 700 to 150 000 tetrahedra); used to refuse hopeless meshes before meshing.
double estimate_tet_count(double volume_m3, double mesh_size_m, double load_mesh_size_m);

/// Meshes the body and writes the decks into the staging folder `folder` (created here; its parent
/// must exist): the caller publishes it (a RunTransaction). On failure the folder is removed.
/// Throws InputError on bad input, a meshing failure, or an estimated or real element count
/// above options.max_elements (after request.context, see there); a file that cannot be written
/// is named by its own path.
DeckResult write_deck_files(const DeckRequest& request, const std::filesystem::path& folder);

/// write_deck_files in a transaction of its own on folder's parent (common/run_transaction.hpp):
/// `folder` appears complete or not at all, and a previous `folder` is replaced only on success.
DeckResult write_decks(const DeckRequest& request, const std::filesystem::path& folder);

}  // namespace impactdeck::fem_export
