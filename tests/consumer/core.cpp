// Two equal steel spheres head on, from the collision core alone; prints F_max and checks it
// against the closed form F_max = k_H x_max^(3/2), x_max = (5 m_w v^2 / (4 k_H))^(2/5).
#include <cmath>
#include <cstdio>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/impact.hpp"

int main() {
  using namespace impactdeck::collision;
  const double r = 0.05, rho = 7850, v = 1.0, pi = 3.14159265358979323846;
  const double m = rho * 4.0 / 3.0 * pi * r * r * r;
  ImpactInput in;
  for (RigidBody* b : {&in.target, &in.impactor}) {
    b->mass_kg = m;
    b->inertia_kg_m2 = Eigen::Matrix3d::Identity() * 0.4 * m * r * r;
  }
  in.target.center_of_mass_m = Eigen::Vector3d(0, 0, 0);
  in.impactor.center_of_mass_m = Eigen::Vector3d(2 * r, 0, 0);
  in.impactor.velocity_m_s = Eigen::Vector3d(-v, 0, 0);
  in.contact.point_m = Eigen::Vector3d(r, 0, 0);
  in.contact.normal = Eigen::Vector3d(1, 0, 0);
  in.target_curvature = ContactCurvature::sphere(r);  // two spheres of radius r: R* = r / 2
  in.impactor_curvature = ContactCurvature::sphere(r);
  ElasticMaterial steel{2.05e11, 0.3};
  in.effective_modulus_Pa = effective_modulus_Pa(steel, steel, ModulusConvention::hertz);
  in.restitution.kind = RestitutionModel::Kind::constant;
  in.restitution.constant = 1.0;
  const ImpactResult res = solve_impact(in);
  const double kH = 4.0 / 3.0 * in.effective_modulus_Pa * std::sqrt(r / 2);
  const double xmax = std::pow(5.0 * (m / 2) * v * v / (4.0 * kH), 0.4);
  const double fmax = kH * std::pow(xmax, 1.5);
  const double got = res.history.compression.max_force_N;
  std::printf("max_force_N %.10g (closed form %.10g)\n", got, fmax);
  const double impulse = res.history.impulse_total_Ns();  // R = 1: twice m_w v
  std::printf("impulse_Ns %.10g (closed form %.10g)\n", impulse, 2 * (m / 2) * v);
  return std::abs(got - fmax) <= 1e-9 * fmax && std::abs(impulse - m * v) <= 1e-9 * m * v && res.checks.passed ? 0 : 1;
}
