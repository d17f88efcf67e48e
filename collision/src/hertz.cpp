#include "impactdeck/collision/hertz.hpp"

#include <cmath>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {
namespace {

void check_material(const ElasticMaterial& m, const char* which, const InputContext& ctx) {
  if (!(m.youngs_modulus_Pa > 0.0) || !std::isfinite(m.youngs_modulus_Pa)) {
    std::ostringstream s;
    s << "Young's modulus must be a positive finite number, got " << m.youngs_modulus_Pa << " Pa";
    throw ctx.error(std::string(which) + " youngs_modulus_Pa", s.str());
  }
  if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5)) {
    std::ostringstream s;
    s << "Poisson's ratio must lie in (-1, 0.5), got " << m.poisson_ratio;
    throw ctx.error(std::string(which) + " poisson_ratio", s.str());
  }
}

double compliance(const ElasticMaterial& m, ModulusConvention c) {
  if (c == ModulusConvention::paper) return 1.0 / m.youngs_modulus_Pa;
  return (1.0 - m.poisson_ratio * m.poisson_ratio) / m.youngs_modulus_Pa;
}

}  // namespace

double effective_modulus_Pa(const ElasticMaterial& a, const ElasticMaterial& b,
                            ModulusConvention convention, const InputContext& ctx) {
  check_material(a, "target material", ctx);
  check_material(b, "impactor material", ctx);
  return 1.0 / (compliance(a, convention) + compliance(b, convention));
}

double effective_radius_m(double k_target, double k_impactor) {
  if (!(k_target >= 0.0) || !(k_impactor >= 0.0) || !std::isfinite(k_target) ||
      !std::isfinite(k_impactor)) {
    std::ostringstream s;
    s << "contact curvatures must be finite and >= 0 (convex or flat), got " << k_target
      << " and " << k_impactor << " 1/m";
    throw InputError("", "contact curvature", s.str());
  }
  const double sum = k_target + k_impactor;
  if (!(sum > 0.0)) {
    throw InputError("", "contact curvature", "both surfaces are flat at the contact point: "
                                              "Hertz contact needs a curved surface");
  }
  return 1.0 / sum;
}

double hertz_constant(double e_star, double r_star) {
  return 4.0 / 3.0 * e_star * std::sqrt(r_star);
}

}  // namespace impactdeck::collision
