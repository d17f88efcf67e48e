#pragma once
// Stresses of a CalculiX run, read back from its .frd (ccx 2.20 User's Manual, *EL FILE): the nodal
// stresses S (extrapolated from the elements and averaged at the nodes by ccx, MPa in the deck's
// units) and displacements U of every output increment. Von Mises
//     sigma_v = sqrt(1/2 [(sx - sy)^2 + (sy - sz)^2 + (sz - sx)^2] + 3 (txy^2 + tyz^2 + tzx^2))
// at every node and time gives:
//   - each probe's history and peak (the paper's Fig. 15), and the contact node's;
//   - the body's peak over time outside the contact zone (a sphere of radius contact_zone_radius_m
//     around the contact point) and inside it, with where and when;
//   - the verdict against the yield strength: survives (safety factor) or yields (place, time).
// Under a point load the stress near the load node grows without bound as the mesh is refined,
// so the zone's peak is reported as not meaningful and only the outside one is judged.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {

/// What the reader needs to know about the deck (deck.json) besides the mesh.
struct StressInputs {
  int load_node = 0;                                  ///< 0-based mesh node of the contact point
  std::vector<std::pair<std::string, int>> probes;    ///< PROBEk and its 0-based node
  double contact_zone_radius_m = 0;
  bool patch_load = false;                            ///< hertz-patch: the zone's stresses mean something
  std::optional<double> yield_strength_Pa;
  double end_time_s = 0;                              ///< output after this (the momentum step) is ignored
  /// The deck's length unit (DeckUnits): the .frd's displacements are in it and its stresses in
  /// N per its square; the .vtu / .msh positions are written in it.
  LengthUnit length_unit = LengthUnit::mm;
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

enum class VerdictKind { no_yield_strength, survives, yields };
const char* to_string(VerdictKind k);

struct Verdict {
  VerdictKind kind = VerdictKind::no_yield_strength;
  std::optional<double> yield_strength_Pa;
  VonMisesPeak governing;            ///< the peak judged (outside the zone; with a patch load, both)
  std::string governing_region;      ///< "outside the contact zone" / "inside the contact zone"
  double safety_factor = 0;          ///< yield strength / governing peak
  std::optional<double> first_yield_time_s;  ///< yields: first output time above the yield strength
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

/// Reads `frd` (ccx's results) for `mesh` (node i = ccx node i + 1). Throws InputError when the
/// file is missing, has no stress output, or names nodes the mesh does not have.
StressResult read_stresses(const std::filesystem::path& frd, const TetMesh& mesh, const StressInputs& in);

/// Reads the von Mises history of the named ccx nodes (1-based ids: `ProbeStress::node`) from an
/// .frd in mm-N-s-tonne (a contact deck) whose stress output may be limited to those nodes
/// (`*EL FILE, NSET=`), up to `end_time_s`;
/// fills each probe's history, peak and time, and returns the output times. Throws InputError when
/// the file is missing or a probe has no stress at some output time.
std::vector<double> read_node_stresses(const std::filesystem::path& frd, std::vector<ProbeStress>& probes,
                                       double end_time_s);

/// Writes into `dir`: von_mises_history.csv (time, each probe, LOAD; SI), von_mises_peak.vtu
/// (ParaView; positions in r.length_unit, stated in its FieldData metres_per_length_unit: peak von Mises and its time per node, von Mises and displacement at the governing
/// peak's time), von_mises_peak.msh (the same as Gmsh $NodeData views) and von_mises.svg (the
/// paper's Fig. 15: von Mises against time at the probes and the load). Records them in `files`.
void write_stress_files(const std::filesystem::path& dir, const TetMesh& mesh, StressResult& r,
                        const std::string& title);

/// JSON of the result (keys in docs/fem.md).
nlohmann::json to_json(const StressResult& r);
/// Human-readable lines: probe peaks, the zones' peaks, the verdict.
std::string format_stress(const StressResult& r);

}  // namespace impactdeck::fem_export
