#pragma once
// Stresses of a solver run, from its nodal results (NodalResults below; CalculiX's .frd is read in
// src/calculix/frd.cpp): the nodal stresses (for ccx: S of *EL FILE, extrapolated from the elements
// and averaged at the nodes, in the deck's units) and displacements of every output time. Von Mises
//     sigma_v = sqrt(1/2 [(sx - sy)^2 + (sy - sz)^2 + (sz - sx)^2] + 3 (txy^2 + tyz^2 + tzx^2))
// at every node and time gives:
//   - each probe's history and peak (the paper's Fig. 15), and the contact node's;
//   - the body's peak over time outside the contact zone (a sphere of radius contact_zone_radius_m
//     around the contact point) and inside it, with where and when;
//   - the verdict against the yield strength: survives (safety factor) or yields (place, time).
// Under a point load the stress near the load node grows without bound as the mesh is refined,
// so the zone's peak is reported as not meaningful and only the outside one is judged.
// A plastic deck (material_model = "plastic") also writes ccx's equivalent plastic strain ("PE"
// blocks of the .frd, *EL FILE PEEQ); its verdict rests on it (docs/fem.md, "Plastic decks"):
// survives elastically, survives with local plastic strain, or yields beyond the contact zone.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {

struct DeckUnits;  // decks.hpp

/// The nodal fields of a solver's results at each output time, in the deck's unit system
/// (DeckUnits): displacement (3 components, its length unit), stress (6: XX YY ZZ XY YZ XZ, its
/// stress unit), equivalent plastic strain (1, dimensionless; plastic decks).
enum class NodalField { displacement, stress, plastic_strain };
constexpr int components(NodalField f) { return f == NodalField::displacement ? 3 : f == NodalField::stress ? 6 : 1; }

/// One pass over a solver's nodal results (NodalResults::read), in output order.
struct NodalResultsVisitor {
  std::function<void(double time_s)> time;      ///< the output time of the fields that follow
  std::function<bool(NodalField field)> field;  ///< a field begins: whether its values are wanted
  /// Optional: whether a node's values are wanted (unset: every node's); others are not parsed.
  std::function<bool(std::size_t node)> node_wanted;
  /// One node's values of a wanted field: its 0-based mesh node and components(field) numbers.
  std::function<void(std::size_t node, const double* values)> value;
  std::function<void()> end;                    ///< a wanted field ends
};

/// A solver's nodal results, read back (Solver::stresses makes them; CalculiX: calculix::FrdResults).
class NodalResults {
 public:
  virtual ~NodalResults() = default;
  virtual const std::filesystem::path& file() const = 0;  ///< the results file, named in errors
  /// One pass over the results. `node_count` > 0: a value of a node at or past it is an error
  /// (InputError naming the file and the place). Returns the bytes read.
  virtual std::size_t read(const NodalResultsVisitor& visitor, std::size_t node_count) const = 0;
};

/// Equivalent plastic strain above which a node counts as yielded: a tenth of the yield strain of
/// steel (Y/E ~ 1e-3), so yield is not missed, and far above the exact 0 ccx writes at nodes whose
/// elements stayed elastic (a hand-check: a nodal PE is the average of its C3D4 elements' one
/// integration point, so one yielded element leaves at least a quarter of its strain on each of
/// its nodes).
inline constexpr double kPlasticStrainThreshold = 1e-4;
/// Plastic strain within this many contact radii (max of the contact semi-axis a_max and the law's
/// dent radius sqrt(R* d*)) of the contact point is local: the plastic zone under a fully plastic
/// indentation reaches a few contact radii (Johnson, Contact Mechanics, 1985, Sect. 6.3, the
/// expanding-cavity model), the same reach as the stress verdict's contact zone
/// (contact_zone_factor = 3). It is never less than 2 load element sizes: under a point load the
/// elements around the load node yield whatever the contact size.
inline constexpr double kLocalPlasticZoneFactor = 3.0;

/// What the reader needs to know about the deck (deck.json) besides the mesh.
struct StressInputs {
  int load_node = 0;                                  ///< 0-based mesh node of the contact point
  std::vector<std::pair<std::string, int>> probes;    ///< PROBEk and its 0-based node
  double contact_zone_radius_m = 0;
  bool patch_load = false;                            ///< hertz-patch: the zone's stresses mean something
  std::optional<double> yield_strength_Pa;
  double end_time_s = 0;                              ///< output after this (the momentum step) is ignored
  /// The deck's length unit (DeckUnits): the results' displacements are in it and their stresses in
  /// N per its square; the .vtu / .msh positions are written in it.
  LengthUnit length_unit = LengthUnit::mm;
  /// material_model = "plastic": the verdict rests on the equivalent plastic strain (PE).
  bool plastic = false;
  double plastic_zone_radius_m = 0;          ///< plastic: "local" within this of the contact point
  std::string contact_law;                   ///< plastic: the law whose dent is reported
  double residual_indentation_m = 0, dent_radius_m = 0;
};

/// The largest von Mises stress of a region over all output times.
struct VonMisesPeak {
  double von_mises_Pa = 0;
  double time_s = 0;
  int node = -1;                                        ///< 0-based; -1 when the region has no node
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
};

struct ProbeStress {
  std::string name;  ///< PROBE1, ..., or LOAD
  int node = 0;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  double max_von_mises_Pa = 0;
  double max_von_mises_time_s = 0;
  std::vector<double> von_mises_Pa;  ///< at StressResult::time_s
};

enum class VerdictKind {
  no_yield_strength,
  survives,  ///< elastic deck: governing von Mises below the yield strength
  yields,    ///< elastic deck: above it
  survives_elastically,    ///< plastic deck: no PE above kPlasticStrainThreshold
  local_plastic_strain,    ///< plastic deck: PE above it only within the plastic zone radius
  yields_beyond_contact,   ///< plastic deck: PE above it beyond the plastic zone radius
};
const char* to_string(VerdictKind k);

struct Verdict {
  VerdictKind kind = VerdictKind::no_yield_strength;
  std::optional<double> yield_strength_Pa;
  VonMisesPeak governing;            ///< the peak judged (outside the zone; with a patch load, both)
  std::string governing_region;      ///< "outside the contact zone" / "inside the contact zone"
  double safety_factor = 0;          ///< yield strength / governing peak
  std::optional<double> first_yield_time_s;  ///< yields: first output time above the yield strength
};

/// The largest equivalent plastic strain of a region over all output times (plastic decks).
struct PlasticStrainPeak {
  double plastic_strain = 0;
  double time_s = 0;
  int node = -1;  ///< 0-based; -1 when no node of the region has plastic strain
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  double distance_m = 0;  ///< from the contact node
};

/// The plastic deck's result: PE read back and the dent of the law.
struct PlasticResult {
  PlasticStrainPeak max;                 ///< the whole body
  PlasticStrainPeak beyond_zone;         ///< beyond plastic_zone_radius_m of the contact node
  double threshold = kPlasticStrainThreshold;
  double plastic_zone_radius_m = 0;
  std::size_t yielded_nodes = 0;         ///< nodes whose PE exceeded the threshold at some time
  std::string contact_law;
  double residual_indentation_m = 0, dent_radius_m = 0;
};

struct StressResult {
  std::vector<double> time_s;           ///< output times read (s)
  std::vector<ProbeStress> probes;      ///< PROBE1, ...
  ProbeStress load;                     ///< the contact node ("LOAD")
  double contact_zone_radius_m = 0;
  VonMisesPeak outside_zone, inside_zone;
  /// At each of time_s: the largest von Mises over the nodes outside the contact zone and inside
  /// it (0 when the zone has no node): the curves the verdict's peak is taken from.
  std::vector<double> outside_zone_history_Pa, inside_zone_history_Pa;
  bool inside_zone_meaningful = false;  ///< false under a point load
  Verdict verdict;
  std::optional<PlasticResult> plastic;  ///< plastic decks only
  /// Per node: the largest PE over time (plastic decks; empty otherwise).
  std::vector<double> node_peak_plastic_strain;
  std::shared_ptr<const NodalResults> results;  ///< the results read (the VTK time series is written from them)
  double end_time_s = 0;                 ///< output after this is not the impact's (the momentum step)
  /// The fields of the .vtu / .msh: per node, the peak over time and its time; the von Mises and
  /// displacement at the time of the governing peak.
  std::vector<double> node_peak_Pa, node_peak_time_s, von_mises_at_peak_Pa;
  std::vector<Eigen::Vector3d> displacement_at_peak_m;
  double peak_field_time_s = 0;
  std::size_t frd_bytes = 0;
  LengthUnit length_unit = LengthUnit::mm;   ///< of the positions in the .vtu / .msh (the deck's)
  std::vector<std::filesystem::path> files;  ///< written by write_stress_files
  std::string von_mises_svg;                 ///< the text of von_mises.svg (empty: none written)
};

/// Reads `results` for `mesh`. Throws InputError when they have no stress output or name nodes the
/// mesh does not have.
StressResult read_stresses(std::shared_ptr<const NodalResults> results, const TetMesh& mesh, const StressInputs& in);
/// The same from ccx's .frd (node i = ccx node i + 1; src/calculix/frd.cpp). Throws InputError
/// when the file is missing, too.
StressResult read_stresses(const std::filesystem::path& frd, const TetMesh& mesh, const StressInputs& in);

/// Reads the von Mises history of the given nodes (1-based ids: `ProbeStress::node`) from results
/// in `units` whose stress output may be limited to those nodes, up to `end_time_s`; fills each
/// probe's history, peak and time, and returns the output times. Throws InputError when a probe
/// has no stress at some output time.
std::vector<double> read_node_stresses(const NodalResults& results, const DeckUnits& units,
                                       std::vector<ProbeStress>& probes, double end_time_s);
/// The same from the .frd of a contact deck (mm-t-s; `*EL FILE, NSET=`; src/calculix/frd.cpp).
std::vector<double> read_node_stresses(const std::filesystem::path& frd, std::vector<ProbeStress>& probes,
                                       double end_time_s);

/// Writes into `dir`: von_mises_history.csv (time, each probe, LOAD; SI), von_mises_peak.vtu
/// (ParaView; positions in r.length_unit, stated in its FieldData metres_per_length_unit: peak von Mises and its time per node, von Mises and displacement at the governing
/// peak's time), von_mises_peak.msh (the same as Gmsh $NodeData views) and von_mises.svg (the
/// paper's Fig. 15: von Mises against time at the probes and the load). Records them in `files`.
void write_stress_files(const std::filesystem::path& dir, const TetMesh& mesh, StressResult& r,
                        const std::string& title);

/// The VTK time series (write_results_series): at most this many .vtu files, ...
inline constexpr std::size_t kMaxSeriesFiles = 100;
/// ... and at most this many nodes x files (about 150 bytes of ASCII per node and file: ~300 MB);
/// fewer files on a big mesh, never fewer than 2.
inline constexpr double kSeriesNodeFileBudget = 2e6;

/// Writes the solver's results (r.results) as a VTK time series into `dir`: results.pvd and
/// results_NNNN.vtu, one per kept output time up to r.end_time_s (every k-th, k the smallest that
/// keeps within kMaxSeriesFiles and kSeriesNodeFileBudget; the last time and the governing peak's
/// time always kept). Point data in the deck's unit system (the results'): displacement (same length
/// unit as the positions), stress (6 components XX YY ZZ XY YZ XZ), von_mises, and
/// equivalent_plastic_strain when the results have it. Each .vtu states its units in FieldData
/// (unit_system, length_unit, stress_unit, metres_per_length_unit, pascals_per_stress_unit) and a comment, and
/// its time in FieldData TimeValue. Returns the files written (the .pvd first).
std::vector<std::filesystem::path> write_results_series(const std::filesystem::path& dir, const TetMesh& mesh,
                                                        const StressResult& r);

/// JSON of the result (keys in docs/fem.md).
nlohmann::json to_json(const StressResult& r);
/// Human-readable lines: probe peaks, the zones' peaks, the verdict.
std::string format_stress(const StressResult& r);

}  // namespace impactdeck::fem_export
