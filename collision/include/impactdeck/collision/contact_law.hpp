#pragma once
// A contact law: the normal force law of an impact and its restitution, as one type. The kernel
// (kernel.hpp) finds the contact point's reduced mass, approach speed and radius; the law turns
// them into F_max, the times, the restitution, F(t) and what the impact leaves behind (a dent).
// Hertz with the restitution models of restitution.hpp is one implementation (hertz_law.hpp).
// A new law is its own file, one line in the registry (contact_law.cpp) and its tests
// (docs/extending.md, "A contact law").
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "impactdeck/collision/restitution.hpp"

namespace impactdeck::collision {

/// The sharp feature of a mesh or CAD part at a contact point (docs/sharp-contacts.md).
enum class SharpKind : std::uint8_t {
  none,    ///< a smooth point (or a flat face)
  edge,    ///< on a sharp edge: a dihedral angle and a length
  corner,  ///< on a vertex where sharp edges meet: an apex half-angle
};

/// The normal direction of one impact as a law sees it (SI).
struct LawInput {
  double reduced_mass_kg = 0;        ///< m_w at the contact point (Eq. 16-21)
  double approach_velocity_m_s = 0;  ///< v_w > 0 along the normal
  double effective_modulus_Pa = 0;   ///< E*
  double effective_radius_m = 0;     ///< R* (the Hertz-equivalent radius of an elliptical contact)
  double yield_strength_Pa = 0;      ///< of the weaker body; 0 when not known
  /// The sharp feature of the body that has one at the point (the laws "wedge" and "cone"; the
  /// line contact of a rounded edge reads its length).
  SharpKind sharp_kind = SharpKind::none;
  double sharp_angle_rad = 0;  ///< edge: the interior dihedral angle 2 beta; corner: the apex half-angle alpha
  double sharp_length_m = 0;   ///< edge: the length L of the straight edge through the point
};

/// Why a law gives no result for an impact (the kernel maps it to its ContactFlag).
enum class LawStatus : std::uint8_t {
  ok,
  restitution_range,    ///< outside the restitution's validity range under policy "error"
  restitution_invalid,  ///< R outside [0, 1]
  degenerate,           ///< a number not finite or not positive (under- or overflow)
};

/// What a law gives for one impact. Every law fills every field; Poisson's restitution R is the
/// restitution impulse over the compression impulse m_w v_w, so impulse_total_Ns = (1 + R) m_w v_w.
struct LawResult {
  LawStatus status = LawStatus::ok;
  double stiffness = 0;               ///< the law's constant (Hertz: k_H in N/m^1.5)
  double max_indentation_m = 0;       ///< x_max
  double max_force_N = 0;             ///< F_max
  double compression_time_s = 0;      ///< t_m, the time of x_max
  double contact_time_s = 0;          ///< t_c, the force back at 0
  double unloading_time_s = 0;        ///< t_c - t_m as the law computes it (exact for tables)
  RestitutionValue restitution;       ///< R and how it was found
  double impulse_compression_Ns = 0;  ///< m_w v_w
  double impulse_total_Ns = 0;        ///< (1 + R) m_w v_w
  double residual_indentation_m = 0;  ///< the dent left behind (0 for an elastic law)
  /// The dent's radius on the surface (0 when there is no dent): "thornton", "jackson-green" the
  /// contact circle at d*, hertz_contact_radius_m(R*, d*) = sqrt(R* d*); "wedge" the indent's
  /// half-width x* tan(beta) (at most L/2); "cone" the indent's radius x* tan(alpha).
  double dent_radius_m = 0;
  /// R_p of the Hertz unloading F = 4/3 E* sqrt(R_p) (d - d_p)^1.5 through (d*, F*): R* for an
  /// elastic Hertz impact, Thornton's R_p, Brake's R_bar; 0 for a law whose unloading is not a
  /// Hertz curve ("wedge", "cone", "line").
  double unloading_radius_m = 0;
  /// A rate-dependent law (LawOptions::cowper_symonds_D_per_s): the contact's characteristic strain
  /// rate (contact_strain_rate_per_s at F_max) and the flow stress the law ran at there; 0 otherwise.
  double strain_rate_per_s = 0;
  double flow_stress_Pa = 0;
  std::array<double, 4> state{};      ///< the law's own numbers for its F(t); opaque to callers
  /// The law's own contact patch at F_max (semi-axes a >= b) and its pressure there; 0: the kernel
  /// takes the Hertz ellipse of F_max (every law but "wedge" and "cone").
  double contact_semi_axis_a_m = 0, contact_semi_axis_b_m = 0, contact_pressure_Pa = 0;
};

/// The interface. solve() is the kernel's hot path: noexcept and allocation-free; the kernel calls
/// it once per group of points (up to kKernelLanes), so a law's loop over the group is its own code.
class ContactLaw {
 public:
  virtual ~ContactLaw() = default;
  /// The registry's name ("hertz", ...), said in outputs.
  virtual const char* name() const noexcept = 0;
  /// out[k] for in[k], k < count. A failed impact comes back with out[k].status != ok (the values
  /// computed up to there kept).
  virtual void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept = 0;
  /// F(t) in N of a solved impact: 0 for t <= 0 and t >= t_c.
  virtual double force_N(const LawResult& r, double t_s) const noexcept = 0;
  /// F at n times 0 <= t <= t_m of the loading phase (for tables; default: force_N at each).
  virtual void loading_forces(const LawResult& r, const double* t_s, double* force_N, std::size_t n) const;
  /// F at n fractions 0 <= u <= 1 of the unloading phase, t = t_m + u unloading_time_s (default: force_N).
  virtual void unloading_forces(const LawResult& r, const double* u, double* force_N, std::size_t n) const;
  /// One line on a restitution outside its range or invalid (for warnings and errors); empty when
  /// `r` is inside the range. The default: the coefficient, when it lies outside [0, 1].
  virtual std::string describe_restitution(const LawResult& r, double approach_velocity_m_s) const;
  /// True for a law of a sharp edge or corner (LawInput::sharp_kind): the kernel passes it the
  /// points where one body is sharp instead of flagging them (ContactFlag::sharp).
  virtual bool takes_sharp_points() const noexcept { return false; }
  /// True for the line contact of a rounded edge ("line"): the kernel passes it the points where
  /// one body's surface is an edge rounded by its edge radius (ContactCurvature::feature edge, not
  /// sharp) and the relative curvature along the edge is 0 (else flagged ContactFlag::line), with
  /// R* the radius across the edge.
  virtual bool takes_line_contacts() const noexcept { return false; }
  /// True for a law that reads LawInput::yield_strength_Pa (the plastic and sharp laws): a
  /// rate-dependent flow stress (LawOptions::cowper_symonds_D_per_s) applies to it.
  virtual bool uses_yield_strength() const noexcept { return false; }
};

/// Thornton's default limiting pressure p_y over the weaker body's yield strength: the onset of
/// yield under a circular Hertz contact, p0 = 1.60 Y for nu = 0.3 (Johnson 1985, Sect. 6.2).
inline constexpr double kThorntonYieldFactor = 1.6;

/// Johnson's yield velocity (Johnson 1985, Sect. 11.4; docs/plastic.md): the approach speed at which
/// a Hertz impact first reaches the limiting pressure p_y, 1/2 m* V_y^2 = W_y = 2/5 F_y d_y:
/// V_y = (pi / (2 E*))^2 (8 pi R*^3 / (15 m*))^(1/2) p_y^(5/2). Below it "thornton" is elastic.
double yield_velocity_m_s(double reduced_mass_kg, double effective_modulus_Pa, double effective_radius_m,
                          double limiting_pressure_Pa);

/// The force at which a rounded edge's line contact first yields (the law "line-plastic",
/// docs/sharp-contacts.md): the plane-strain Hertz peak pressure reaches p_y at
/// F_y = pi R* L p_y^2 / E* (Johnson 1985, Sect. 4.3), written with the line law's stiffness
/// k = (pi/4) E* L (LawResult::stiffness) as 4 R* p_y^2 k / E*^2. The yield velocity is
/// F_y / sqrt(m* k): 1/2 m* V_y^2 = 1/2 F_y^2 / k.
double line_yield_force_N(double effective_modulus_Pa, double effective_radius_m, double line_stiffness_N_m,
                          double limiting_pressure_Pa);

/// The default indentation hardness of the laws "wedge" and "cone" over the weaker body's yield
/// strength: a fully plastic indentation by a sharp indenter, H = 3 Y (Tabor 1951; Johnson 1985,
/// Sect. 6.5). A sharp edge or corner is fully plastic at once.
inline constexpr double kTaborHardnessFactor = 3.0;

/// What a scene says about the law of an impact (each law reads what it needs).
struct LawOptions {
  RestitutionModel restitution;     ///< "hertz": its restitution model
  double limiting_pressure_Pa = 0;  ///< "thornton", "line-plastic": p_y; 0: kThorntonYieldFactor x the yield strength
  /// "jackson-green": the yielding (weaker) body's material, the one whose yield strength the law
  /// gets: its Poisson's ratio (C = 1.295 exp(0.736 nu)), its tangent modulus E_t in [0, E) (0:
  /// perfectly plastic) and its Young's modulus E (read when E_t > 0: hardening by E_t/E).
  double poisson_ratio = 0.3;
  double tangent_modulus_Pa = 0;
  double youngs_modulus_Pa = 0;
  /// "wedge" and "cone": the indentation pressure p; 0: kTaborHardnessFactor x the yield strength.
  double hardness_Pa = 0;
  /// "jackson-green", "jackson-green-sneddon": take F_max, the times, e and the dent from a table of
  /// the dimensionless impact against V/V_c, built once per material pair (Y/E*, nu, E_t/E) on first
  /// use, instead of integrating each impact. For sweeps (many impacts, one material pair); the
  /// table's error is measured when it is built and kept below kLawTableRel, else the law integrates
  /// (docs/plastic-laws.md, "Tabulated").
  bool tabulated = false;
  /// Cowper - Symonds rate dependence of the yielding body's flow stress (0: rate-independent):
  /// Y_d = Y (1 + (rate / D)^(1/q)) at the contact's characteristic strain rate
  /// (contact_strain_rate_per_s), solved together with the impact (docs/plastic.md, "Rate effects").
  /// Applies to a law that uses_yield_strength(); D > 0 in 1/s, q > 0.
  double cowper_symonds_D_per_s = 0;
  double cowper_symonds_q = 0;
};

/// The characteristic strain rate of a plastic contact of radius a under the approach speed V:
/// 0.2 V / a (Tabor's estimate of the mean strain rate under an indenting sphere, as Johnson 1985,
/// Sect. 11.4, quotes it; an order of magnitude). A law evaluates it at F_max, a = sqrt(R* d*).
double contact_strain_rate_per_s(double approach_velocity_m_s, double contact_radius_m);

/// Cowper - Symonds: the flow stress at the strain rate `rate`, Y (1 + (rate / D)^(1/q)).
double cowper_symonds_flow_stress_Pa(double yield_strength_Pa, double strain_rate_per_s, double D_per_s, double q);

/// The largest relative error of a tabulated plastic law (LawOptions::tabulated) against the
/// integrated law, on F_max, x_max, t_m, t_c, e and the dent, as measured at the midpoints between
/// the table's nodes when it is built (a cubic Hermite interpolant's error peaks there).
inline constexpr double kLawTableRel = 1e-6;

using ContactLawFactory = std::function<std::shared_ptr<const ContactLaw>(const LawOptions&)>;

/// Adds a law under `name`. Throws Error(internal_error) when the name is taken or empty.
void register_contact_law(const std::string& name, ContactLawFactory factory);

/// The law `name` built from `options`. Throws ctx.error("contact_law", ...) naming the known laws
/// when `name` is not registered; the factory's own errors pass through.
std::shared_ptr<const ContactLaw> make_contact_law(const std::string& name, const LawOptions& options,
                                                   const InputContext& ctx = {});

/// The registered names, sorted.
std::vector<std::string> contact_law_names();

}  // namespace impactdeck::collision
