// MED mesh writer (libmedc). med.h is used only in this file.
#include <med.h>

#include <cstring>
#include <map>
#include <set>

#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;

namespace {

// A MED file, closed on every way out.
class MedFile {
 public:
  MedFile(const fs::path& p) : fid_(MEDfileOpen(p.c_str(), MED_ACC_CREAT)) {}
  ~MedFile() {
    if (fid_ >= 0) MEDfileClose(fid_);
  }
  MedFile(const MedFile&) = delete;
  MedFile& operator=(const MedFile&) = delete;
  med_idt id() const { return fid_; }
  bool close() {
    const bool ok = MEDfileClose(fid_) >= 0;
    fid_ = -1;
    return ok;
  }

 private:
  med_idt fid_;
};

// A fixed-width, space-padded MED name field.
std::string padded(const std::string& s, std::size_t width) {
  std::string r = s.substr(0, width);
  r.resize(width, ' ');
  return r;
}

}  // namespace

void write_med(const TetMesh& mesh, const fs::path& path, const std::string& mesh_name, LengthUnit length_unit) {
  const DeckUnits units{length_unit};
  const std::string where = path.string();
  auto check = [&](med_err rc, const char* step) {
    if (rc < 0) throw InputError(where, "MED", std::string("libmedc failed: ") + step);
  };
  if (mesh.tets.empty()) throw InputError(where, "MED", "mesh has no tetrahedra");
  if (mesh_name.size() > MED_NAME_SIZE) throw InputError(where, "MED", "mesh name too long");
  for (const auto& [g, n] : mesh.node_groups) {
    if (g.size() > 8) throw InputError(where, "MED", "group name '" + g + "' longer than 8 characters");
  }
  MedFile f(path);
  if (f.id() < 0) throw InputError(where, "MED", "cannot create the file");
  const med_idt fid = f.id();

  // Axis names and units: 3 fields of MED_SNAME_SIZE characters each.
  const std::string axis = padded("X", MED_SNAME_SIZE) + padded("Y", MED_SNAME_SIZE) + padded("Z", MED_SNAME_SIZE);
  const std::string l = to_string(length_unit);
  const std::string unit = padded(l, MED_SNAME_SIZE) + padded(l, MED_SNAME_SIZE) + padded(l, MED_SNAME_SIZE);
  const std::string description = "impactdeck target body, " + units.name();
  check(MEDmeshCr(fid, mesh_name.c_str(), 3, 3, MED_UNSTRUCTURED_MESH,
                  description.c_str(), "s", MED_SORT_DTIT, MED_CARTESIAN,
                  axis.c_str(), unit.c_str()), "MEDmeshCr");

  std::vector<med_float> xyz;
  xyz.reserve(3 * mesh.nodes_m.size());
  for (const auto& p : mesh.nodes_m) {
    const Eigen::Vector3d x = p * units.per_m();
    xyz.insert(xyz.end(), {x.x(), x.y(), x.z()});
  }
  check(MEDmeshNodeCoordinateWr(fid, mesh_name.c_str(), MED_NO_DT, MED_NO_IT, 0.0, MED_FULL_INTERLACE,
                                static_cast<med_int>(mesh.nodes_m.size()), xyz.data()),
        "MEDmeshNodeCoordinateWr");

  // MED TETRA4 order is Gmsh's with nodes 2 and 3 swapped (Gmsh's own MED writer does the same).
  std::vector<med_int> conn;
  conn.reserve(4 * mesh.tets.size());
  for (const auto& t : mesh.tets) {
    conn.insert(conn.end(), {t[0] + 1, t[2] + 1, t[1] + 1, t[3] + 1});
  }
  check(MEDmeshElementConnectivityWr(fid, mesh_name.c_str(), MED_NO_DT, MED_NO_IT, 0.0, MED_CELL,
                                     MED_TETRA4, MED_NODAL, MED_FULL_INTERLACE,
                                     static_cast<med_int>(mesh.tets.size()), conn.data()),
        "MEDmeshElementConnectivityWr");

  // Families: 0 = no group (mandatory FAMILLE_ZERO); node families > 0, one per distinct set of
  // node groups; cell family -1 = group BODY.
  check(MEDfamilyCr(fid, mesh_name.c_str(), "FAMILLE_ZERO", 0, 0, ""), "MEDfamilyCr 0");
  std::map<int, std::set<std::string>> groups_of_node;
  for (const auto& [g, n] : mesh.node_groups) groups_of_node[n].insert(g);
  std::map<std::set<std::string>, med_int> family_of_set;
  std::vector<med_int> node_family(mesh.nodes_m.size(), 0);
  for (const auto& [n, gs] : groups_of_node) {
    auto it = family_of_set.find(gs);
    if (it == family_of_set.end()) {
      const med_int num = static_cast<med_int>(family_of_set.size() + 1);
      std::string names, fam = "FAM";
      for (const auto& g : gs) names += padded(g, MED_LNAME_SIZE), fam += "_" + g;
      check(MEDfamilyCr(fid, mesh_name.c_str(), fam.substr(0, MED_NAME_SIZE).c_str(), num,
                        static_cast<med_int>(gs.size()), names.c_str()), "MEDfamilyCr nodes");
      it = family_of_set.emplace(gs, num).first;
    }
    node_family[static_cast<std::size_t>(n)] = it->second;
  }
  check(MEDfamilyCr(fid, mesh_name.c_str(), "FAM_BODY", -1, 1, padded("BODY", MED_LNAME_SIZE).c_str()),
        "MEDfamilyCr cells");
  check(MEDmeshEntityFamilyNumberWr(fid, mesh_name.c_str(), MED_NO_DT, MED_NO_IT, MED_NODE, MED_NONE,
                                    static_cast<med_int>(node_family.size()), node_family.data()),
        "MEDmeshEntityFamilyNumberWr nodes");
  std::vector<med_int> cell_family(mesh.tets.size(), -1);
  check(MEDmeshEntityFamilyNumberWr(fid, mesh_name.c_str(), MED_NO_DT, MED_NO_IT, MED_CELL, MED_TETRA4,
                                    static_cast<med_int>(cell_family.size()), cell_family.data()),
        "MEDmeshEntityFamilyNumberWr cells");
  if (!f.close()) throw InputError(where, "MED", "libmedc failed to close the file");
}

}  // namespace impactdeck::fem_export
