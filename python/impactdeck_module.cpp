// The Python module `impactdeck` (docs/python.md). Contract (issue 18):
//   impactdeck.run(scene_path, out=None) -> the document of `impactdeck run --json`, as a dict
//   impactdeck.inspect(path, length_unit, density_kg_m3=None, at=None) -> that of `inspect --json`
// both built by the same library calls as the CLI (scene::to_json, geometry::inspect_part), so the
// documents are the same. Also: solve_impact (plain numbers), load_part (mass properties, surface
// queries), sweep (numpy arrays), fem_check, compare_contact, campaign_plan/run/collect. Every path
// argument takes str or os.PathLike; `overrides` ({KEY: value}) are `--set KEY=VALUE`. Errors raise impactdeck.InputError (exit 3 of the CLI),
// CheckFailed (4), UsageError (2), InternalError (1), all derived from impactdeck.Error, with the
// CLI's one-line message and the exit code in `exit_code`.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/collect.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/inspect.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/part.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/scene/overrides.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/study/sweep_command.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

// The deepest nesting of lists and dicts an override's value may have (a scene's own TOML is
// refused beyond a few hundred levels; the value was converted recursively, so a list nested
// 20 000 deep overflowed the C stack and killed the interpreter).
constexpr int kMaxOverrideDepth = 64;

// ascii(text): a key named in a message whatever it holds (lone surrogates, control characters).
std::string ascii_of(const py::handle& text) {
  return py::module_::import("builtins").attr("ascii")(text).cast<std::string>();
}

// The UTF-8 bytes of a Python str; ValueError naming `what` when it holds a lone surrogate, which
// no UTF-8 text (and no scene) can hold.
std::string utf8_of(const py::handle& text, const std::string& what) {
  Py_ssize_t size = 0;
  const char* bytes = PyUnicode_AsUTF8AndSize(text.ptr(), &size);
  if (!bytes) {
    PyErr_Clear();
    throw py::value_error(what + ": holds a lone surrogate (not Unicode text): it cannot be written as UTF-8");
  }
  return std::string(bytes, static_cast<std::size_t>(size));
}

// A Python value as the TOML value text of an override: bool, int, float, str (a TOML string),
// lists/tuples (arrays), dicts with str keys (inline tables), numpy arrays and scalars (as their
// tolist()), nested at most kMaxOverrideDepth deep. Anything else is refused naming the override's
// key: UsageError for a type, ValueError for a value no scene can hold.
std::string toml_value(const py::handle& v, const std::string& key, int depth = 0) {
  const std::string where = "overrides['" + key + "']";
  if (depth > kMaxOverrideDepth) {
    throw py::value_error(where + ": lists and dicts nested deeper than " + std::to_string(kMaxOverrideDepth) +
                          " levels");
  }
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v)) return py::str(v).cast<std::string>();
  if (py::isinstance<py::float_>(v)) {
    const double x = v.cast<double>();
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    return py::repr(v).cast<std::string>();  // shortest text that reads back as x
  }
  if (py::isinstance<py::str>(v)) return nlohmann::json(utf8_of(v, where)).dump();  // a TOML basic string
  std::string out;
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    for (const py::handle e : v) out += (out.empty() ? "" : ", ") + toml_value(e, key, depth + 1);
    return "[" + out + "]";
  }
  if (py::isinstance<py::dict>(v)) {
    for (const auto& [k, e] : v.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) throw UsageError(where + ": table keys must be str");
      out += (out.empty() ? "" : ", ") + nlohmann::json(utf8_of(k, where + ": table key " + ascii_of(k))).dump() +
             " = " + toml_value(e, key, depth + 1);
    }
    return "{" + out + "}";
  }
  if (py::hasattr(v, "tolist")) return toml_value(v.attr("tolist")(), key, depth);  // numpy arrays and scalars
  throw UsageError(where + ": expected a bool, int, float, str, list, tuple or dict, not " +
                   py::str(py::type::handle_of(v).attr("__name__")).cast<std::string>());
}

// `overrides` ({KEY: value} or None) as the CLI's `--set KEY=VALUE` list: parsed by the same call
// (scene::parse_override), so a bad key or value fails as on the command line, naming "--set KEY".
// A key holding '=' (which KEY=VALUE would split, silently replacing the value) or a lone surrogate
// raises ValueError naming it.
std::vector<scene::Override> overrides_of(const py::object& overrides) {
  std::vector<scene::Override> out;
  if (overrides.is_none()) return out;
  if (!py::isinstance<py::dict>(overrides)) throw UsageError("overrides: expected a dict {KEY: value}");
  for (const auto& [k, v] : overrides.cast<py::dict>()) {
    if (!py::isinstance<py::str>(k)) throw UsageError("overrides: keys must be str, e.g. 'impacts[0].restitution'");
    const std::string key = utf8_of(k, "overrides: key " + ascii_of(k));
    if (key.find('=') != std::string::npos) {
      throw py::value_error("overrides: key " + ascii_of(k) +
                            " holds '=': a key is a dotted path such as 'impacts[0].restitution', never '='");
    }
    out.push_back(scene::parse_override(key + "=" + toml_value(v, key)));
  }
  return out;
}

// Raises `type` (CheckFailed, InputError) with the message and the complete document in its
// `document` attribute: a call that completed but whose check failed (the CLI's exit 3 or 4).
[[noreturn]] void raise_with_document(const py::handle& type, const std::string& message, py::object doc) {
  py::object e = type(py::str(message));
  e.attr("document") = std::move(doc);
  PyErr_SetObject(type.ptr(), e.ptr());
  throw py::error_already_set();
}


LengthUnit unit_of(const std::string& s) {
  const auto u = parse_length_unit(s);
  if (!u) throw UsageError("length_unit '" + s + "': expected m, cm, mm or in" + length_unit_suggestion(s));
  return *u;
}

Eigen::Vector3d vec3(const py::handle& h, const std::string& what) {
  std::vector<double> v;
  try {
    v = h.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw UsageError(what + ": expected three numbers");
  }
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
    throw UsageError(what + ": expected three finite numbers");
  }
  return {v[0], v[1], v[2]};
}

Eigen::Matrix3d inertia_of(const py::handle& h, const std::string& what) {
  // Three principal moments, or a 3x3 tensor.
  try {
    const auto d = h.cast<std::vector<double>>();
    if (d.size() == 3) return Eigen::Vector3d(d[0], d[1], d[2]).asDiagonal();
  } catch (const py::cast_error&) {
  }
  try {
    const auto rows = h.cast<std::vector<std::vector<double>>>();
    if (rows.size() == 3) {
      Eigen::Matrix3d m;
      for (int i = 0; i < 3; ++i) {
        if (rows[i].size() != 3) throw UsageError(what + ": expected 3 moments or a 3x3 tensor");
        for (int k = 0; k < 3; ++k) m(i, k) = rows[i][k];
      }
      return m;
    }
  } catch (const py::cast_error&) {
  }
  throw UsageError(what + ": expected 3 principal moments or a 3x3 tensor (kg m^2)");
}

py::array_t<double> array(const Eigen::Vector3d& v) { return py::array_t<double>(3, v.data()); }
py::array_t<double> array(const Eigen::Matrix3d& m) {
  py::array_t<double> a({3, 3});
  auto r = a.mutable_unchecked<2>();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) r(i, k) = m(i, k);
  return a;
}

// A surface query point: three finite numbers within kMaxQueryCoordinate_m of the origin. Farther
// away the squared distances of the closest-point search leave double precision (1e160 m gave an
// infinite distance_m); the bound is the part files' own coordinate limit (docs/reliability.md).
constexpr double kMaxQueryCoordinate_m = 1e20;
Eigen::Vector3d query_point(const py::handle& h) {
  const Eigen::Vector3d x = vec3(h, "point");
  if (x.cwiseAbs().maxCoeff() > kMaxQueryCoordinate_m) {
    std::ostringstream m;
    m << "point (" << x.x() << ", " << x.y() << ", " << x.z() << ") m lies farther than 1e20 m from the origin, "
      << "beyond the coordinates a part may have: no distance can be computed there";
    throw InputError("", "point_m", m.str());
  }
  return x;
}

py::dict surface_point(const geometry::SurfacePoint& s) {
  py::dict d;
  d["point_m"] = array(s.point_m);
  d["normal"] = array(s.normal);
  d["distance_m"] = s.distance_m;
  return d;
}

// A loaded part: its shape and exact (CAD) or mesh mass properties; queries in metres.
struct PyPart {
  std::shared_ptr<const geometry::Shape> shape;
  std::string file, format;
  geometry::VolumeProperties volume;
};

PyPart load_part(const fs::path& path, const std::string& length_unit, bool repair, bool accept_approximate) {
  PyPart p;
  p.file = path.string();
  const LengthUnit u = unit_of(length_unit);
  if (const auto f = geometry::cad_format(path)) {
    p.shape = geometry::CadShape::load(path, u);
    p.format = geometry::to_string(*f);
  } else {
    geometry::PartOptions o;
    o.length_unit = u;
    o.repair = repair;
    o.accept_approximate_mass = accept_approximate;
    geometry::Part part = geometry::load_part(path, o);
    p.shape = part.shape;
    p.format = part.loaded.format;
  }
  p.volume = p.shape->volume_properties();
  return p;
}

py::dict impact_dict(const collision::ImpactResult& r, std::size_t samples) {
  py::dict d;
  d["reduced_mass_kg"] = r.reduced_mass_kg;
  d["effective_radius_m"] = r.effective_radius_m;
  d["effective_modulus_Pa"] = r.effective_modulus_Pa;
  d["hertz_constant"] = r.hertz_constant;
  d["approach_velocity_m_s"] = r.approach_velocity_m_s;
  d["max_force_N"] = r.history.compression.max_force_N;
  d["max_indentation_m"] = r.history.compression.max_indentation_m;
  d["compression_time_s"] = r.history.compression.compression_time_s;
  d["contact_time_s"] = r.history.contact_time_s();
  d["restitution"] = r.history.restitution;
  d["impulse_Ns"] = r.history.impulse_total_Ns();
  d["target_delta_velocity_m_s"] = array(r.target_jump.delta_velocity_m_s);
  d["target_delta_angular_velocity_rad_s"] = array(r.target_jump.delta_angular_velocity_rad_s);
  d["impactor_delta_velocity_m_s"] = array(r.impactor_jump.delta_velocity_m_s);
  d["impactor_delta_angular_velocity_rad_s"] = array(r.impactor_jump.delta_angular_velocity_rad_s);
  py::dict checks;
  checks["passed"] = r.checks.passed;
  checks["impulse_relative_error"] = r.checks.impulse_relative_error;
  checks["energy_relative_error"] = r.checks.energy_relative_error;
  checks["carnot_loss_J"] = r.checks.carnot_loss_J;
  d["checks"] = checks;
  d["warnings"] = r.warnings;
  if (samples >= 2) {
    py::array_t<double> t(samples), f(samples);
    auto tt = t.mutable_unchecked<1>();
    auto ff = f.mutable_unchecked<1>();
    const double T = r.history.contact_time_s();
    for (std::size_t k = 0; k < samples; ++k) {
      tt(k) = T * static_cast<double>(k) / static_cast<double>(samples - 1);
      ff(k) = r.history.force_N(tt(k));
    }
    d["time_s"] = t;
    d["force_N"] = f;
  }
  return d;
}

}  // namespace

namespace {

// The Python types of InputError and CheckFailed, for the calls that raise them with a document
// (set by define_errors; the exception objects live as long as the module).
py::handle input_error_type, check_failed_type;

/// The module's doc, version and exception types (each with the command's exit code), and the translation of impactdeck's errors to them.
void define_errors(py::module_& m) {
  m.doc() = "impactdeck: eccentric Hertz impacts of mesh and CAD parts, as in `impactdeck run` (docs/python.md)";
  m.attr("__version__") = kVersion;

  static py::exception<Error> base(m, "Error");
  static py::exception<UsageError> usage(m, "UsageError", base.ptr());
  static py::exception<InputError> input(m, "InputError", base.ptr());
  static py::exception<CheckFailed> check(m, "CheckFailed", base.ptr());
  static py::exception<Error> internal(m, "InternalError", base.ptr());
  base.attr("exit_code") = static_cast<int>(ExitCode::internal_error);
  // numpy's C API is looked up once, here, under the import: pybind11 does it on the first array
  // made, inside a C++ static initialiser that imports numpy; two threads making their first
  // array at once deadlocked there (one holding the initialiser's guard and waiting for the GIL,
  // the other holding the GIL and waiting for the guard).
  py::module_::import("numpy");
  (void)py::array_t<double>(0);
  (void)py::array_t<bool>(0);
  base.doc() = "Every error of impactdeck; `exit_code` is the command's exit code (docs/cli.md).";
  usage.doc() = "A call made wrongly (the command's exit code 2).";
  input.doc() = "Bad input: a file, scene key or value (exit code 3); the message names file, place and reason.";
  check.doc() = "A physics self-check failed (exit code 4); `document` holds the complete document when there is one.";
  internal.doc() = "A defect of impactdeck (exit code 1).";
  usage.attr("exit_code") = static_cast<int>(ExitCode::usage);
  input.attr("exit_code") = static_cast<int>(ExitCode::invalid_input);
  check.attr("exit_code") = static_cast<int>(ExitCode::check_failed);
  internal.attr("exit_code") = static_cast<int>(ExitCode::internal_error);
  input_error_type = input;
  check_failed_type = check;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      switch (e.code()) {
        case ExitCode::usage: PyErr_SetString(usage.ptr(), e.what()); return;
        case ExitCode::invalid_input: PyErr_SetString(input.ptr(), e.what()); return;
        case ExitCode::check_failed: PyErr_SetString(check.ptr(), e.what()); return;
        default: PyErr_SetString(internal.ptr(), e.what()); return;
      }
    }
  });
}

/// run, inspect and solve_impact: a scene, a part's report, one impact from plain numbers.
void define_impacts(py::module_& m) {
  m.def(
      "run",
      [](const fs::path& scene_path, std::optional<fs::path> out, py::object overrides) -> py::object {
        const std::vector<scene::Override> set = overrides_of(overrides);
        nlohmann::json doc;
        bool passed = true;
        {
          py::gil_scoped_release release;
          const scene::Scene sc = scene::load_scene(scene_path, set);
          const fs::path dir = out.value_or(fs::path("."));
          std::error_code ec;
          fs::create_directories(dir, ec);
          if (!fs::is_directory(dir)) throw InputError(dir.string(), "--out", "cannot create the output folder");
          scene::RunOptions opt;
          opt.out_dir = dir;
          const scene::RunReport rep = scene::run_scene(sc, opt);
          doc = scene::to_json(sc, rep);
          passed = rep.all_checks_passed();
        }
        // As the CLI: the document is complete, and the run fails with exit code 4.
        if (!passed) raise_with_document(check_failed_type, "a physics self-check failed (see checks above)", to_python(doc));
        return to_python(doc);
      },
      py::arg("scene_path"), py::arg("out") = py::none(), py::arg("overrides") = py::none(),
      "Runs a scene as `impactdeck run SCENE --out OUT [--set KEY=VALUE ...] --json` and returns its JSON "
      "document as a dict (outputs go to `out`, default the current folder). `overrides`: {KEY: value}, "
      "each applied as `--set KEY=VALUE` (value: bool, number, str, list or dict, written as TOML) and "
      "validated like the file; an error names the override ('--set KEY'). A failed self-check raises "
      "CheckFailed whose `document` attribute holds the document.");

  m.def(
      "inspect",
      [](const fs::path& path, const std::string& length_unit, std::optional<double> density_kg_m3,
         py::object at) -> py::object {
        geometry::InspectOptions o;
        o.part = path;
        o.length_unit = unit_of(length_unit);
        o.density_kg_m3 = density_kg_m3;
        if (!at.is_none()) {
          const double to_m = metres_per(o.length_unit);
          for (const py::handle h : at) {
            if (py::isinstance<py::str>(h)) {
              const std::string s = h.cast<std::string>();
              o.points_m.push_back(geometry::parse_point(s, to_m, "at"));
              o.point_labels.push_back(s);
            } else {
              const Eigen::Vector3d v = vec3(h, "at");
              std::ostringstream s;
              s.precision(17);
              s << v.x() << "," << v.y() << "," << v.z();
              o.points_m.push_back(v * to_m);
              o.point_labels.push_back(s.str());
            }
          }
        }
        geometry::InspectReport r;
        {
          py::gil_scoped_release release;
          r = geometry::inspect_part(o);
        }
        return to_python(r.document);
      },
      py::arg("path"), py::arg("length_unit"), py::arg("density_kg_m3") = py::none(), py::arg("at") = py::none(),
      "The document of `impactdeck inspect PATH --length-unit U [--density-kg-m3 D] [--at x,y,z ...] --json` "
      "as a dict. `at`: points in the file's unit, as 'x,y,z' strings or sequences of three numbers.");

  m.def(
      "solve_impact",
      [](double mass1_kg, double mass2_kg, py::object inertia1_kg_m2, py::object inertia2_kg_m2,
         py::object lever_arm1_m, py::object lever_arm2_m, py::object normal, py::object velocity1_m_s,
         py::object velocity2_m_s, py::object angular_velocity1_rad_s, py::object angular_velocity2_rad_s,
         std::optional<double> radius_m, py::object curvatures1_per_m, py::object curvatures2_per_m,
         py::object directions1, py::object directions2, double effective_modulus_Pa, py::object restitution,
         std::size_t samples) {
        collision::ImpactInput in;
        const Eigen::Vector3d n = vec3(normal, "normal").normalized();
        in.contact.point_m = Eigen::Vector3d::Zero();
        in.contact.normal = n;
        auto body = [&](collision::RigidBody& b, double m, py::object I, py::object r, py::object v, py::object w,
                        const std::string& which) {
          b.mass_kg = m;
          b.inertia_kg_m2 = inertia_of(I, "inertia" + which + "_kg_m2");
          b.center_of_mass_m = -vec3(r, "lever_arm" + which + "_m");  // contact point at the origin
          b.velocity_m_s = vec3(v, "velocity" + which + "_m_s");
          b.angular_velocity_rad_s = w.is_none() ? Eigen::Vector3d::Zero() : vec3(w, "angular_velocity" + which + "_rad_s");
        };
        body(in.target, mass1_kg, inertia1_kg_m2, lever_arm1_m, velocity1_m_s, angular_velocity1_rad_s, "1");
        body(in.impactor, mass2_kg, inertia2_kg_m2, lever_arm2_m, velocity2_m_s, angular_velocity2_rad_s, "2");
        if (radius_m && !curvatures1_per_m.is_none()) throw UsageError("give radius_m or curvatures, not both");
        if (radius_m) {
          // R* as the target's radius against a flat impactor: the same R* under every rule.
          in.target_curvature = collision::ContactCurvature::sphere(*radius_m);
          in.impactor_curvature = collision::ContactCurvature::flat();
        } else {
          if (curvatures1_per_m.is_none() || curvatures2_per_m.is_none()) {
            throw UsageError("give radius_m (R*) or curvatures1_per_m and curvatures2_per_m (k1, k2 of each body)");
          }
          const auto k1 = curvatures1_per_m.cast<std::vector<double>>(), k2 = curvatures2_per_m.cast<std::vector<double>>();
          if (k1.size() != 2 || k2.size() != 2) throw UsageError("curvatures: expected (k1, k2) per body, 1/m");
          // Principal directions: given, or any tangent pair (enough when a body is isotropic).
          const Eigen::Vector3d t = n.unitOrthogonal();
          const Eigen::Vector3d d1a = directions1.is_none() ? t : vec3(directions1, "directions1");
          const Eigen::Vector3d d1b = directions2.is_none() ? t : vec3(directions2, "directions2");
          auto surface = [&](const std::vector<double>& k, const Eigen::Vector3d& d1) {
            collision::ContactCurvature c;
            c.k1_per_m = k[0];
            c.k2_per_m = k[1];
            c.d1 = d1.normalized();
            c.d2 = n.cross(c.d1).normalized();
            return c;
          };
          in.target_curvature = surface(k1, d1a);
          in.impactor_curvature = surface(k2, d1b);
          in.rule = collision::ContactRule::elliptical;
        }
        in.effective_modulus_Pa = effective_modulus_Pa;
        if (py::isinstance<py::str>(restitution)) {
          if (restitution.cast<std::string>() != "energy-flux") throw UsageError("restitution: a number in [0, 1] or \"energy-flux\"");
          in.restitution.kind = collision::RestitutionModel::Kind::energy_flux;  // Eq. 14 + 30, flux in J/cm^3
        } else {
          in.restitution.kind = collision::RestitutionModel::Kind::constant;
          in.restitution.constant = restitution.cast<double>();
        }
        return impact_dict(collision::solve_impact(in), samples);
      },
      py::kw_only(), py::arg("mass1_kg"), py::arg("mass2_kg"), py::arg("inertia1_kg_m2"), py::arg("inertia2_kg_m2"),
      py::arg("lever_arm1_m"), py::arg("lever_arm2_m"), py::arg("normal"), py::arg("velocity1_m_s"),
      py::arg("velocity2_m_s"), py::arg("angular_velocity1_rad_s") = py::none(),
      py::arg("angular_velocity2_rad_s") = py::none(), py::arg("radius_m") = py::none(),
      py::arg("curvatures1_per_m") = py::none(), py::arg("curvatures2_per_m") = py::none(),
      py::arg("directions1") = py::none(), py::arg("directions2") = py::none(), py::arg("effective_modulus_Pa"),
      py::arg("restitution") = 1.0, py::arg("samples") = 201,
      "One eccentric impact from plain numbers (SI). Body 1 is the target, 2 the impactor; lever_armI_m "
      "runs from body I's centre of mass to the contact point; `normal` is body 1's outward normal there. "
      "Radius: R* (radius_m) or each body's principal curvatures (k1, k2), with d1 directions when not "
      "isotropic (elliptical Hertz equivalent radius). restitution: R, or \"energy-flux\" (Eq. 30, J/cm^3). Returns a dict (max_force_N, impulse_Ns, jumps, "
      "checks, and time_s / force_N arrays of `samples` points).");
}

/// Part and load_part: a part file as a shape, with its surface queries.
void define_part(py::module_& m) {
  py::class_<PyPart>(m, "Part", "A part file loaded as a shape: mass properties and surface queries (SI, metres).")
      .def_readonly("file", &PyPart::file, "The part file, as given to load_part (str).")
      .def_readonly("format", &PyPart::format, "The file's format: 'stl', 'obj', 'ply', 'off', 'step', 'iges' or 'brep'.")
      .def_property_readonly("kind", [](const PyPart& p) { return p.shape->kind(); },
                             "What the shape is: 'mesh' (a triangle mesh) or 'cad' (an OpenCASCADE B-rep).")
      .def_property_readonly("volume_m3", [](const PyPart& p) { return p.volume.volume_m3; }, "Enclosed volume, m^3.")
      .def_property_readonly("area_m2", [](const PyPart& p) { return p.volume.area_m2; }, "Surface area, m^2.")
      .def_property_readonly("center_of_mass_m", [](const PyPart& p) { return array(p.volume.centroid_m); },
                             "Centre of mass (the volume's centroid: uniform density), m, numpy array of 3.")
      .def_property_readonly("inertia_per_density_m5", [](const PyPart& p) { return array(p.volume.inertia_per_density_m5); },
                             "Inertia tensor about the centre of mass divided by the density, m^5, 3x3 numpy "
                             "array (times rho in kg/m^3: kg m^2).")
      .def_property_readonly("size_m", [](const PyPart& p) { return p.shape->size_m(); },
                             "Largest extent of the part, m (the scale of relative tolerances).")
      .def("__repr__", [](const PyPart& p) {
        std::ostringstream r;
        r.precision(6);
        r << "<impactdeck.Part " << py::repr(py::str(p.file)).cast<std::string>() << " " << p.format << " ("
          << p.shape->kind() << "), volume " << p.volume.volume_m3 << " m^3, size " << p.shape->size_m() << " m>";
        return r.str();
      })
      .def("closest_point", [](const PyPart& p, py::object q) {
        const Eigen::Vector3d x = query_point(q);
        geometry::SurfacePoint s;
        {
          py::gil_scoped_release release;
          s = p.shape->closest_point(x);
        }
        return surface_point(s);
      }, py::arg("point_m"), "The surface point nearest to point_m (m): dict of point_m, normal (outward), distance_m.")
      .def("curvature", [](const PyPart& p, py::object q) {
        const Eigen::Vector3d x = query_point(q);
        geometry::Curvature c;
        double radius = std::numeric_limits<double>::quiet_NaN();
        geometry::SurfacePoint s;
        {
          py::gil_scoped_release release;
          s = p.shape->closest_point(x);
          c = p.shape->curvature(s);
          if (!c.sharp_feature) radius = p.shape->paper_radius_m(s);
        }
        py::dict d = surface_point(s);
        d["sharp_feature"] = c.sharp_feature;
        d["principal_curvatures_1_per_m"] = py::make_tuple(c.k1_per_m, c.k2_per_m);
        d["principal_directions"] = py::make_tuple(array(c.d1), array(c.d2));
        d["curvature_error_estimate_1_per_m"] = c.error_estimate_per_m;
        d["paper_radius_m"] = c.sharp_feature ? py::object(py::none()) : py::object(py::float_(radius));
        return d;
      }, py::arg("point_m"), "Principal curvatures, directions and the Eq. 26 radius at the surface point nearest to point_m.")
      .def("sample_surface", [](const PyPart& p, std::size_t count, std::uint64_t seed) {
        std::vector<geometry::SurfacePoint> pts;
        {
          py::gil_scoped_release release;
          pts = p.shape->sample_surface(count, seed);
        }
        py::array_t<double> xyz({pts.size(), std::size_t{3}}), nrm({pts.size(), std::size_t{3}});
        auto a = xyz.mutable_unchecked<2>();
        auto b = nrm.mutable_unchecked<2>();
        for (std::size_t i = 0; i < pts.size(); ++i)
          for (int k = 0; k < 3; ++k) a(i, k) = pts[i].point_m[k], b(i, k) = pts[i].normal[k];
        return py::make_tuple(xyz, nrm);
      }, py::arg("count"), py::arg("seed") = 1, "(points, normals): count x 3 arrays, uniform by area.");

  m.def("load_part", &load_part, py::arg("path"), py::arg("length_unit"), py::arg("repair") = false,
        py::arg("accept_approximate") = false,
        "Loads a mesh part (STL, OBJ, PLY, OFF) or a CAD part (STEP, IGES, BREP) as `inspect` does. `path`: "
        "str or os.PathLike; length_unit: the file's unit, m, cm, mm or in.");
}

/// sweep, fem_check and compare_contact.
void define_analyses(py::module_& m) {
  m.def(
      "sweep",
      [](const fs::path& scene_path, const std::string& impact, const std::string& cloud, std::size_t count,
         std::uint64_t seed, int grid_steps, unsigned threads, py::object overrides) {
        const std::vector<scene::Override> set = overrides_of(overrides);
        study::SweepResult r;
        {
          py::gil_scoped_release release;
          const scene::Scene sc = scene::load_scene(scene_path, set);
          study::SweepRequest q;  // no out_dir: no files
          q.impact = impact;
          q.cloud = cloud;
          q.count = count;
          q.seed = seed;
          q.grid_steps = grid_steps;
          q.max_points = std::numeric_limits<std::size_t>::max();  // a script sizes its own sweep
          q.sweep.threads = threads;
          r = study::run_sweep_command(scene::sweep_case(sc, impact), q).result;
        }
        const std::size_t N = r.points.size();
        py::array_t<double> point({N, std::size_t{3}}), normal({N, std::size_t{3}});
        py::array_t<double> fmax(N), mw(N), reff(N), tm(N), xmax(N);
        py::array_t<bool> sharp(N);
        auto P = point.mutable_unchecked<2>();
        auto Nn = normal.mutable_unchecked<2>();
        for (std::size_t i = 0; i < N; ++i) {
          const auto& p = r.points[i];
          for (int k = 0; k < 3; ++k) P(i, k) = p.point_m[k], Nn(i, k) = p.normal[k];
          fmax.mutable_at(i) = p.max_force_N;
          mw.mutable_at(i) = p.reduced_mass_kg;
          reff.mutable_at(i) = p.effective_radius_m;
          tm.mutable_at(i) = p.compression_time_s;
          xmax.mutable_at(i) = p.max_indentation_m;
          sharp.mutable_at(i) = p.sharp_feature;
        }
        py::dict d;
        d["point_m"] = point;
        d["normal"] = normal;
        d["max_force_N"] = fmax;
        d["reduced_mass_kg"] = mw;
        d["effective_radius_m"] = reff;
        d["compression_time_s"] = tm;
        d["max_indentation_m"] = xmax;
        d["sharp_feature"] = sharp;
        d["force_ratio"] = r.force_ratio;
        d["mass_only_ratio"] = r.mass_only_ratio;
        d["min_index"] = r.min_index;
        d["max_index"] = r.max_index;
        d["sharp_count"] = r.sharp_count;
        return d;
      },
      py::arg("scene_path"), py::arg("impact") = "", py::arg("cloud") = "auto", py::arg("count") = 2000,
      py::arg("seed") = 1, py::arg("grid_steps") = 8, py::arg("threads") = 0, py::arg("overrides") = py::none(),
      "Force map of a scene's impact over the target's surface, as `impactdeck sweep`, with the per-point "
      "results as numpy arrays (no files written). `overrides` as in run().");

  m.def(
      "fem_check",
      [](const fs::path& deck_dir, const std::string& ccx, bool run_solver, double linear_tolerance,
         double angular_tolerance, int threads, double solver_timeout_s) -> py::object {
        if (threads < 0) throw UsageError("threads: expected 0 (all cores) or a positive number");
        for (const double x : {linear_tolerance, angular_tolerance, solver_timeout_s}) {
          if (!(std::isfinite(x) && x >= 0)) throw UsageError("tolerances and solver_timeout_s: finite numbers >= 0");
        }
        fem_export::CheckOptions o;
        o.executables["calculix"] = ccx;
        o.run_solver = run_solver;
        o.linear_tolerance = linear_tolerance;
        o.angular_tolerance = angular_tolerance;
        o.threads = threads;
        o.timeout_s = solver_timeout_s;
        nlohmann::json doc;
        std::string failed;
        {
          py::gil_scoped_release release;
          // As `fem-check`: one transaction on the deck folder.
          const fem_export::CheckResult r = fem_export::check_deck_folder(deck_dir, o);
          for (std::size_t i = 0; i < r.failures.size(); ++i) failed += (i ? "; " : "") + r.failures[i];
          doc = fem_export::to_json(r);
        }
        if (!failed.empty()) {
          raise_with_document(check_failed_type, (deck_dir / "impact.dat").string() + ": FEM check failed: " + failed, to_python(doc));
        }
        return to_python(doc);
      },
      py::arg("deck_dir"), py::kw_only(), py::arg("ccx") = "ccx", py::arg("run") = true,
      py::arg("linear_tolerance") = 0.0, py::arg("angular_tolerance") = 0.0, py::arg("threads") = 0,
      py::arg("solver_timeout_s") = 0.0,
      "Runs CalculiX on a deck folder written by run() ([outputs.fem]) and checks momentum, the FE body and "
      "stresses, as `impactdeck fem-check DIR --json`; returns its document (keys: docs/fem.md). run=False "
      "checks the folder's existing impact.dat (--no-run); tolerances 0: the deck's. The folder changes only "
      "when the checks pass; a failed check raises CheckFailed with the document in `document`.");

  m.def(
      "compare_contact",
      [](const fs::path& scene_path, std::optional<fs::path> out, py::object overrides, const std::string& impact,
         double threshold, int refine, bool hybrid, double solver_timeout_s) -> py::object {
        const std::vector<scene::Override> set = overrides_of(overrides);
        if (!(std::isfinite(threshold) && threshold > 0)) throw UsageError("threshold: a positive number");
        if (refine < 0 || refine > 6) throw UsageError("refine: 0 to 6");
        if (!(std::isfinite(solver_timeout_s) && solver_timeout_s >= 0)) throw UsageError("solver_timeout_s: a finite number >= 0");
        nlohmann::json doc;
        std::string in_doubt;
        bool disagree = false;
        {
          py::gil_scoped_release release;
          const scene::Scene sc = scene::load_scene(scene_path, set);
          const fs::path dir = out.value_or(fs::path("."));
          // As `compare-contact`: one transaction; the decks and results are published together.
          RunTransaction txn(dir);
          scene::CompareOptions o;
          o.impact = impact;
          o.threshold = threshold;
          o.refine = refine;
          o.run_hybrid = hybrid;
          o.solver_timeout_s = solver_timeout_s;
          o.out_dir = dir;
          o.place_output = [&txn, &dir](const std::string& name, bool is_folder) {
            return is_folder ? txn.folder(name, dir.string(), "out") : txn.file(name, dir.string(), "out");
          };
          scene::CompareReport r = txn.run([&] {
            scene::CompareReport report = scene::compare_contact(sc, o);
            txn.commit();
            return report;
          });
          scene::map_paths(r, [&txn](const fs::path& p) { return txn.public_path(p); });
          doc = scene::to_json(r);
          disagree = r.verdict == scene::CompareVerdict::disagree;
          in_doubt = r.in_doubt;
        }
        if (disagree) {
          raise_with_document(check_failed_type, "contact F_max differs from the analytic force beyond the threshold; in doubt: " +
                                         in_doubt, to_python(doc));
        }
        return to_python(doc);
      },
      py::arg("scene_path"), py::arg("out") = py::none(), py::arg("overrides") = py::none(), py::kw_only(),
      py::arg("impact") = "", py::arg("threshold") = 0.03, py::arg("refine") = 0, py::arg("hybrid") = true,
      py::arg("solver_timeout_s") = 0.0,
      "Runs an impact as the hybrid deck and as a full-contact CalculiX model and compares both with the analytic "
      "Hertz force, as `impactdeck compare-contact SCENE --out OUT --json` (docs/contact-vs-hybrid.md); returns "
      "its document. Outputs go to `out` (default the current folder) in one transaction. A verdict 'disagree' "
      "raises CheckFailed with the document in `document`. Minutes of ccx per run.");
}

/// campaign_plan, campaign_run and campaign_collect.
void define_campaigns(py::module_& m) {
  m.def(
      "campaign_plan",
      [](const fs::path& campaign_file, const fs::path& out) {
        campaign::PlanResult r;
        {
          py::gil_scoped_release release;
          r = campaign::plan_campaign(campaign::read_campaign(campaign_file), out);
        }
        py::dict d;
        d["cases"] = r.cases;
        d["already_planned"] = r.already_planned;
        d["input_hash"] = r.input_hash;
        d["warnings"] = r.warnings;
        return d;
      },
      py::arg("campaign_file"), py::arg("out"),
      "Expands a campaign file (docs/campaign-format.md) into case folders and campaign.json in `out`, as "
      "`impactdeck campaign plan FILE --out OUT`. Returns {cases, already_planned, input_hash, warnings}.");

  m.def(
      "campaign_run",
      [](const fs::path& dir, std::size_t jobs, int threads, std::optional<fs::path> executable) -> py::object {
        if (jobs < 1 || jobs > 100000) throw UsageError("jobs: 1 to 100000");
        if (threads < 1 || threads > 1024) throw UsageError("threads: 1 to 1024");
        campaign::LocalOptions o;
        o.jobs = jobs;
        o.ccx_threads = threads;
        o.progress_bar = false;
        if (executable) {
          o.executable = *executable;
        } else {
          // The command installed with the module (a venv's bin/ first), else the one on the PATH.
          const fs::path beside = fs::path(py::module_::import("sys").attr("prefix").cast<std::string>()) / "bin" / "impactdeck";
          const py::object which = py::module_::import("shutil").attr("which")("impactdeck");
          std::error_code ec;
          if (fs::is_regular_file(beside, ec)) o.executable = beside;
          else if (!which.is_none()) o.executable = which.cast<std::string>();
          else throw UsageError("campaign_run: no impactdeck command in " + beside.parent_path().string() +
                                " or on the PATH: pass executable=");
        }
        campaign::RunSummary s;
        {
          py::gil_scoped_release release;
          s = campaign::run_local(dir, o);
        }
        py::dict d;
        d["total"] = s.total;
        d["done"] = s.done;
        d["skipped"] = s.skipped;
        d["failed"] = s.failed;
        d["checks_failed"] = s.checks_failed;
        d["not_run"] = s.other;
        d["failed_ids"] = s.failed_ids;
        d["exit_code"] = s.exit_code();
        if (s.failed || s.other) {
          raise_with_document(input_error_type, fs::absolute(dir).lexically_normal().string() + ": " +
                                         std::to_string(s.failed + s.other) + " of " + std::to_string(s.total) +
                                         " case(s) failed or were not run (each failed case's failure.json says why)", d);
        }
        if (s.checks_failed) {
          raise_with_document(check_failed_type, fs::absolute(dir).lexically_normal().string() + ": " +
                                         std::to_string(s.checks_failed) + " case(s) with a failed self-check", d);
        }
        return std::move(d);
      },
      py::arg("dir"), py::kw_only(), py::arg("jobs") = 1, py::arg("threads") = 1, py::arg("executable") = py::none(),
      "Runs every case of a planned campaign that is not done, `jobs` at a time, each as the child process "
      "`EXECUTABLE campaign run-case DIR ID` (as `impactdeck campaign run DIR --jobs J --threads T`; a killed "
      "campaign resumes). executable: default the impactdeck installed beside this Python (sys.prefix/bin), "
      "else the PATH's. Returns {total, done, skipped, failed, checks_failed, not_run, failed_ids, exit_code}; "
      "failed cases raise InputError, failed self-checks CheckFailed, with that dict in `document`.");

  m.def(
      "campaign_collect",
      [](const fs::path& dir) {
        campaign::CollectResult r;
        {
          py::gil_scoped_release release;
          r = campaign::collect(dir);
        }
        auto opt = [](const std::optional<fs::path>& p) { return p ? py::object(py::str(p->string())) : py::object(py::none()); };
        py::dict d;
        d["done"] = r.done;
        d["failed"] = r.failed;
        d["pending"] = r.pending;
        d["csv"] = r.csv.string();
        d["json"] = r.json.string();
        d["report_html"] = r.report_html.string();
        d["worst_id"] = r.worst_id ? py::object(py::int_(*r.worst_id)) : py::object(py::none());
        d["worst_case"] = opt(r.worst_case);
        d["map_svg"] = opt(r.map_svg);
        d["map_vtp"] = opt(r.map_vtp);
        return d;
      },
      py::arg("dir"),
      "Collects a campaign folder as `impactdeck campaign collect DIR`: collect/cases.csv and cases.json, the "
      "worst case's copy, the map and report.html. Returns {done, failed, pending, csv, json, report_html, "
      "worst_id, worst_case, map_svg, map_vtp} (paths as str, None when not written).");
}

}  // namespace

PYBIND11_MODULE(impactdeck, m) {
  define_errors(m);
  define_impacts(m);
  define_part(m);
  define_analyses(m);
  define_campaigns(m);
}
