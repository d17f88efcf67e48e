#pragma once
// Standard drop programmes (campaign `[drop_test]`, docs/campaign-format.md): the drops of a
// standard on the faces, edges and corners of a part's box along its principal axes of inertia,
// each as a placement of the body (orientation, position, velocity) that a campaign case sets.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::campaign {

/// The standards `[drop_test] standard` accepts, in the order the docs list them.
inline constexpr const char* kMilStd810h = "MIL-STD-810H-516.8-IV";
inline constexpr const char* kIsta1a = "ISTA-1A";
inline constexpr const char* kIec60068_2_31 = "IEC-60068-2-31";
const std::vector<std::string>& drop_standard_names();

/// Standard gravity (m/s^2), the drop speed's g when the scene has no gravity_m_s2.
inline constexpr double kStandardGravity = 9.80665;

/// MIL-STD-810H Method 516.8 Procedure IV, Table 516.8-VI: the one row checked against a source,
/// mass < 45.4 kg with the largest dimension < 0.91 m: 1.22 m (26 drops). Any other item: nullopt,
/// and the campaign asks for height_m. The table's other rows (larger or heavier items) are not
/// built in: no copy of the standard's table was at hand to check them, and a drop height from
/// memory would be a silent number (docs/campaign-format.md).
std::optional<double> mil_std_810h_height_m(double mass_kg, double largest_dimension_m);
/// ISTA 1A by mass: [0, 10) kg 0.76 m, [10, 19) 0.61 m, [19, 28) 0.46 m, [28, 45) 0.31 m,
/// [45, 68] 0.20 m; heavier: nullopt (ISTA 1A covers packages up to 68 kg).
std::optional<double> ista_1a_height_m(double mass_kg);
/// IEC 60068-2-31's preferred free-fall heights, m: 0.025, 0.05, 0.1, 0.25, 0.5, 1.
const std::vector<double>& iec_60068_2_31_heights_m();

/// A drop: the box point hit, as signs along the principal axes (+1, -1, or 0 for the middle of
/// the box along that axis), and its name: "face +x", "edge +x-y", "corner +x+y-z".
struct DropPoint {
  Eigen::Vector3i signs = Eigen::Vector3i::Zero();
  std::string name;
};
/// The 6 faces (+x, -x, +y, -y, +z, -z), then the 12 edges (xy, xz, yz; ++, +-, -+, --), then the
/// 8 corners (+++, ++-, +-+, ..., ---): MIL-STD-810H's 26 drops.
std::vector<DropPoint> all_drop_points();
/// ISTA 1A's 10 drops: corner +x+y+z (the standard's corner 2-3-5), its three edges from the
/// shortest to the longest, then the faces from the smallest area to the largest, each pair + then
/// -. `box_lengths_m`: the box's side along each principal axis (ties keep the axis order).
std::vector<DropPoint> ista_1a_drop_points(const Eigen::Vector3d& box_lengths_m);
/// IEC 60068-2-31: the 6 faces, then the 8 corners.
std::vector<DropPoint> iec_drop_points();

/// The part's box along its principal axes of inertia (own frame).
struct PrincipalBox {
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  /// Columns: the principal axes (own frame), by ascending moment of inertia (x the smallest);
  /// the largest-magnitude own-frame component of x and y is positive, z = x cross y.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d low_m = Eigen::Vector3d::Zero(), high_m = Eigen::Vector3d::Zero();  ///< from the centroid, along each axis
  Eigen::Vector3d lengths_m() const { return high_m - low_m; }
  /// The box point of `signs`, relative to the centroid, in principal coordinates.
  Eigen::Vector3d point(const Eigen::Vector3i& signs) const;
};

/// One planned drop of the body: the case's placement (world frame, SI).
struct Drop {
  DropPoint point;
  double height_m = 0;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< own -> world
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();             ///< the body's own origin
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();           ///< sqrt(2 g h) down, or 0 (sequences)
};

/// `[drop_test]` of a campaign file, read.
struct DropTestSpec {
  std::string standard, body;
  std::optional<double> height_m;
  /// Where each key is ("line 4, key 'drop_test.standard'"): the errors name it.
  std::string standard_place, body_place, height_place, table_place;
};

/// What a drop_test campaign runs: the base scene's sequence of `body` (released at rest), or else
/// its first-contact impact (given the free-fall speed).
struct DropProgramme {
  std::string sequence;  ///< the [[sequences]] name; empty: `impact` mode
  std::size_t body_index = 0;
  double mass_kg = 0, gravity_m_s2 = kStandardGravity, height_m = 0;
  PrincipalBox box;
  std::vector<Drop> drops;
};

/// Plans the drops of `spec` on `base` (its body's mass properties and shape). `impact`: the
/// campaign's collected impact (its index), used when the scene has no sequence of the body.
/// Throws InputError (fr_name, place) naming the key: an unknown standard (did you mean), no
/// table height for the body, an IEC height that is not a preferred one, no sequence or
/// first-contact impact of the body against a plane.
DropProgramme plan_drops(const scene::Scene& base, const DropTestSpec& spec, std::optional<std::size_t> impact,
                         const InputContext& ctx);

/// The drop's --set overrides of body `body_index` (scene length unit, 17 significant digits).
std::vector<scene::Override> drop_overrides(const scene::Scene& base, std::size_t body_index, const Drop& drop);

/// `bodies[j].orientation_axis` and `orientation_angle_deg` of `q` (the identity as [0, 0, 1], 0).
std::vector<scene::Override> orientation_overrides(const std::string& body_prefix, const Eigen::Quaterniond& q);

}  // namespace impactdeck::campaign
