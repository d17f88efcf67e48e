// CalculiX's .frd (ccx 2.20 User's Manual, *NODE FILE / *EL FILE) as solver-neutral nodal results
// (stress.hpp: NodalResults): the DISP, STRESS and PE blocks of every output time.
#include "calculix.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"

namespace impactdeck::fem_export::calculix {
namespace fs = std::filesystem;

namespace {

// Fixed-width field [pos, pos + width) of an .frd line as a number (frd writes 1.23456E-07 and
// runs fields together when a sign fills the gap).
bool field(const std::string& line, std::size_t pos, std::size_t width, double& v) {
  if (line.size() < pos + width) return false;
  char buf[32];
  const std::size_t n = std::min<std::size_t>(width, sizeof buf - 1);
  line.copy(buf, n, pos);
  buf[n] = '\0';
  char* end = nullptr;
  v = std::strtod(buf, &end);
  return end != buf && std::isfinite(v);
}

// The `count` 12-wide values of a " -1" record (displacements, stress components).
void record_values(const std::string& line, std::size_t lineno, const std::string& where, int count, double* out,
                   const char* what) {
  for (int k = 0; k < count; ++k) {
    if (!field(line, 13 + 12 * static_cast<std::size_t>(k), 12, out[k])) {
      throw InputError(where, "line " + std::to_string(lineno), std::string("bad ") + what);
    }
  }
}

// The result blocks read (ccx 2.20 .frd names), as the fields they hold.
std::optional<NodalField> frd_field(const std::string& line) {
  if (line.rfind(" -4  DISP", 0) == 0) return NodalField::displacement;
  if (line.rfind(" -4  STRESS", 0) == 0) return NodalField::stress;
  if (line.rfind(" -4  PE ", 0) == 0) return NodalField::plastic_strain;
  return std::nullopt;
}

const char* value_name(NodalField f) {
  switch (f) {
    case NodalField::displacement: return "displacement";
    case NodalField::stress: return "stress";
    case NodalField::plastic_strain: return "equivalent plastic strain";
  }
  return "value";
}

}  // namespace

FrdResults::FrdResults(fs::path frd) : frd_(std::move(frd)) {
  check_input_file(frd_, "CalculiX results (.frd)", std::numeric_limits<std::uintmax_t>::max());  // not a FIFO
  std::ifstream f(frd_, std::ios::binary);
  if (!f) throw InputError(frd_.string(), "file", "CalculiX results (.frd) cannot be opened (missing or unreadable)");
}

// One pass: each "  100C" header's time, each " -4  NAME" block start, its " -1" node records and
// its " -3" end.
std::size_t FrdResults::read(const NodalResultsVisitor& v, std::size_t node_count) const {
  const std::string where = frd_.string();
  std::ifstream f(frd_, std::ios::binary);
  if (!f) throw InputError(where, "file", "CalculiX results (.frd) cannot be opened (missing or unreadable)");
  std::string line;
  std::size_t lineno = 0, bytes = 0;
  std::optional<NodalField> wanted;
  double values[6];
  while (std::getline(f, line)) {
    ++lineno;
    bytes += line.size() + 1;
    if (line.rfind("  100C", 0) == 0) {
      double t;
      if (!field(line, 12, 12, t)) throw InputError(where, "line " + std::to_string(lineno), "bad time in a result header");
      v.time(t);
      continue;
    }
    if (line.rfind(" -4", 0) == 0) {
      wanted = frd_field(line);
      if (wanted && !v.field(*wanted)) wanted.reset();
      continue;
    }
    if (line.rfind(" -3", 0) == 0) {
      if (wanted) v.end();
      wanted.reset();
      continue;
    }
    if (!wanted || line.rfind(" -1", 0) != 0) continue;
    double id;
    if (!field(line, 3, 10, id) || id < 1 || id != std::floor(id) || id > 1e15) {
      throw InputError(where, "line " + std::to_string(lineno), "bad node number in a result line");
    }
    // Node i of the mesh is ccx's node i + 1.
    if (node_count > 0 && id > static_cast<double>(node_count)) {
      throw InputError(where, "line " + std::to_string(lineno), "a result line names a node the mesh does not have");
    }
    const std::size_t node = static_cast<std::size_t>(id) - 1;
    if (v.node_wanted && !v.node_wanted(node)) continue;
    record_values(line, lineno, where, components(*wanted), values, value_name(*wanted));
    v.value(node, values);
  }
  return bytes;
}

}  // namespace impactdeck::fem_export::calculix

namespace impactdeck::fem_export {

StressResult read_stresses(const std::filesystem::path& frd, const TetMesh& mesh, const StressInputs& in) {
  return read_stresses(std::make_shared<calculix::FrdResults>(frd), mesh, in);
}

std::vector<double> read_node_stresses(const std::filesystem::path& frd, std::vector<ProbeStress>& probes,
                                       double end_time_s) {
  // Contact decks are in mm-t-s (MPa): contact_model.cpp.
  return read_node_stresses(calculix::FrdResults(frd), DeckUnits{LengthUnit::mm}, probes, end_time_s);
}

}  // namespace impactdeck::fem_export
