#pragma once
// The one way numbers enter impactdeck's JSON documents (run, inspect, sweep, fem-check, ...): a
// non-finite value becomes null (a document never holds NaN or Inf, docs/cli.md), and -0 becomes 0.
// Header-only, for the modules that write JSON (nlohmann-json); common's own sources do not use it.
#include <cmath>
#include <optional>

#include <nlohmann/json.hpp>

namespace impactdeck {

/// x, or null when x is NaN or infinite; -0 written as 0.
inline nlohmann::json json_number(double x) {
  return std::isfinite(x) ? nlohmann::json(x + 0.0) : nlohmann::json(nullptr);
}

/// null when empty, else json_number.
inline nlohmann::json json_number(const std::optional<double>& x) {
  return x ? json_number(*x) : nlohmann::json(nullptr);
}

/// An array of json_number, one per component of `v` (anything with size() and operator[], e.g. an
/// Eigen vector or a std::vector<double>).
template <class Vector>
nlohmann::json json_vector(const Vector& v) {
  nlohmann::json a = nlohmann::json::array();
  for (decltype(v.size()) i = 0; i < v.size(); ++i) a.push_back(json_number(static_cast<double>(v[i])));
  return a;
}

}  // namespace impactdeck
