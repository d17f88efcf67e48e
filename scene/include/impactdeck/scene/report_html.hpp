#pragma once
// `run`'s report page (report.html): one self-contained file (plot/html.hpp). First the verdict
// (survives / yields, the safety factor and the governing number: stress and place), then each
// warning once, the part (three orthographic views and an isometric one drawn from its triangles,
// with the contact point, the normal, the force and the floor), the stress field at its peak when
// ccx ran, the inputs (the scene's text, materials, bodies, units), each impact's results with
// their checks (impulse, Eq. 31; Carnot, Eq. 32; the FEM checks), the pictures (F(t), Fig. 15),
// the version, the inputs' date and SHA-256 hashes, and links to every file written. Every text
// from the scene is escaped.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::scene {

/// A picture of an impact beyond the F(t) plot the page draws itself: SVG text or PNG bytes.
struct ReportPicture {
  std::string caption;
  std::string svg;  ///< an SVG document (inlined), or empty
  std::string png;  ///< PNG bytes (a data URI), or empty
};

/// The verdict of one impact: from the FEM stresses when ccx ran (an elastic deck: yield strength /
/// governing peak von Mises; a plastic deck: the equivalent plastic strain read back, the three
/// plastic verdicts of docs/fem.md), else from the Hertz peak pressure against the yield onset
/// 1.60 sigma_y (Johnson); none without a yield strength.
struct ImpactVerdict {
  enum class Kind { none, survives, yields } kind = Kind::none;
  /// The verdict in words: "survives", "yields", and for a plastic deck "survives elastically",
  /// "survives with local plastic strain", "yields beyond the contact zone"; "no verdict".
  std::string word = "no verdict";
  /// Yield strength over the governing peak (> 1 survives); none where plastic strain was found
  /// (a plastic deck's von Mises is capped near the yield strength: the strain is the measure).
  std::optional<double> safety_factor;
  std::string basis;  ///< what it was judged on
  /// The FEM verdict's mesh convergence (fem_export/convergence.hpp): "holds" or "moves with the
  /// mesh" with both meshes' governing stresses; "not checked" after a one-mesh ccx run; empty
  /// without FEM stresses. A verdict that moves with the mesh says so in `word` too.
  std::string convergence;
};
ImpactVerdict impact_verdict(const ImpactReport& ir);

/// The page's picture of the bodies of impact `impact` of `scene` as they touch (plot::part_drawing),
/// for a target hit by a plane (a drop onto the floor: the target stays where the scene puts it):
/// the contact point and the target's outward normal in the world (m, as `run --json` gives them).
/// Loads the bodies again. Empty when the impactor is not a plane or nothing can be drawn; `caption`
/// gets what it shows. Throws InputError as `run` on the scene's bodies.
std::string impact_part_svg(const Scene& scene, const std::string& impact, const Eigen::Vector3d& point_m,
                            const Eigen::Vector3d& normal, std::string& caption);

/// The page. `pictures[k]`: the extra pictures of impact k (may be shorter than the impacts).
/// The paths in `report` are shown as they are (pass the public ones). `bodies`: the run's
/// prepared bodies by name (their shapes and poses: the part's picture); null: no part picture.
std::string report_html(const Scene& scene, const RunReport& report,
                        const std::vector<std::vector<ReportPicture>>& pictures = {},
                        const std::map<std::string, contact::PreparedBody>* bodies = nullptr);

}  // namespace impactdeck::scene
