#pragma once
// Orientations spread evenly over SO(3) for drop-test campaigns.
#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

namespace impactdeck::campaign {

/// `count` unit quaternions spread evenly over SO(3): the super-Fibonacci spiral (M. Alexa,
/// "Super-Fibonacci Spirals: Fast, Low-Discrepancy Sampling of SO(3)", CVPR 2022). Deterministic,
/// each with w >= 0 (q and -q are one rotation). Throws InputError for count = 0.
std::vector<Eigen::Quaterniond> super_fibonacci_orientations(std::size_t count);

/// Geodesic distance on SO(3): the angle (rad, in [0, pi]) of the rotation taking a to b.
double rotation_angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace impactdeck::campaign
