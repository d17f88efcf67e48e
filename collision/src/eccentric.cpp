#include "impactdeck/collision/eccentric.hpp"

#include <cmath>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

bool RigidBody::fixed() const { return std::isinf(mass_kg); }

Eigen::Vector3d RigidBody::point_velocity(const Eigen::Vector3d& p) const {
  return velocity_m_s + angular_velocity_rad_s.cross(p - center_of_mass_m);
}

double RigidBody::kinetic_energy_J() const {
  if (fixed()) return 0.0;
  return 0.5 * mass_kg * velocity_m_s.squaredNorm() +
         0.5 * angular_velocity_rad_s.dot(inertia_kg_m2 * angular_velocity_rad_s);
}

namespace {

// Solves I x = b for a symmetric positive definite inertia tensor; throws otherwise.
Eigen::Vector3d solve_inertia(const Eigen::Matrix3d& inertia, const Eigen::Vector3d& b) {
  const double scale = inertia.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || !inertia.allFinite() ||
      (inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    throw InputError("", "inertia tensor", "must be finite, symmetric and non-zero");
  }
  Eigen::LLT<Eigen::Matrix3d> llt(inertia / scale);
  if (llt.info() != Eigen::Success) {
    throw InputError("", "inertia tensor", "is not positive definite");
  }
  return llt.solve(b) / scale;
}

}  // namespace

double inverse_effective_mass(const RigidBody& body, const Eigen::Vector3d& r,
                              const Eigen::Vector3d& n) {
  if (body.fixed()) return 0.0;
  if (!(body.mass_kg > 0.0)) {
    std::ostringstream s;
    s << "must be positive, got " << body.mass_kg << " kg";
    throw InputError("", "mass", s.str());
  }
  const Eigen::Vector3d rxn = r.cross(n);
  return 1.0 / body.mass_kg + rxn.dot(solve_inertia(body.inertia_kg_m2, rxn));
}

double reduced_mass_kg(const RigidBody& target, const RigidBody& impactor, const Contact& c) {
  if (target.fixed() && impactor.fixed()) {
    throw InputError("", "bodies", "both bodies are fixed (infinite mass): nothing can move");
  }
  const double inv =
      inverse_effective_mass(target, c.point_m - target.center_of_mass_m, c.normal) +
      inverse_effective_mass(impactor, c.point_m - impactor.center_of_mass_m, c.normal);
  return 1.0 / inv;
}

double inverse_effective_mass_eq21(double m, const Eigen::Vector3d& moments,
                                   const Eigen::Matrix3d& axes, const Eigen::Vector3d& r,
                                   const Eigen::Vector3d& n) {
  // Coordinates of the contact point (x_O, y_O, z_O) and of the impact line's versor
  // (n_i, n_j, n_k) along the principal axes i, j, k.
  const double x = r.dot(axes.col(0)), y = r.dot(axes.col(1)), z = r.dot(axes.col(2));
  const double ni = n.dot(axes.col(0)), nj = n.dot(axes.col(1)), nk = n.dot(axes.col(2));
  const double tx = z * nj - y * nk, ty = z * ni - x * nk, tz = y * ni - x * nj;
  return 1.0 / m + tx * tx / moments.x() + ty * ty / moments.y() + tz * tz / moments.z();
}

double approach_velocity_m_s(const RigidBody& target, const RigidBody& impactor, const Contact& c) {
  const Eigen::Vector3d u = impactor.point_velocity(c.point_m) - target.point_velocity(c.point_m);
  return -c.normal.dot(u);
}

void velocity_jumps(const RigidBody& target, const RigidBody& impactor, const Contact& c,
                    double impulse, VelocityJump& tj, VelocityJump& ij) {
  auto jump = [&](const RigidBody& b, double sign, VelocityJump& j) {
    j = VelocityJump{};
    if (b.fixed()) return;
    const Eigen::Vector3d p = sign * impulse * c.normal;
    j.delta_velocity_m_s = p / b.mass_kg;
    j.delta_angular_velocity_rad_s =
        solve_inertia(b.inertia_kg_m2, (c.point_m - b.center_of_mass_m).cross(p));
  };
  jump(target, -1.0, tj);
  jump(impactor, +1.0, ij);
}

double kinetic_energy_loss_J(const RigidBody& b, const VelocityJump& j) {
  if (b.fixed()) return 0.0;
  const Eigen::Vector3d& dv = j.delta_velocity_m_s;
  const Eigen::Vector3d& dw = j.delta_angular_velocity_rad_s;
  return -(b.mass_kg * dv.dot(b.velocity_m_s + 0.5 * dv) +
           dw.dot(b.inertia_kg_m2 * (b.angular_velocity_rad_s + 0.5 * dw)));
}

double carnot_energy_loss_J(double m_w, double v_w, double restitution) {
  return 0.5 * (1.0 - restitution * restitution) * m_w * v_w * v_w;
}

}  // namespace impactdeck::collision
