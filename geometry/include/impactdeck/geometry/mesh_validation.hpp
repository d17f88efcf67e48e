#pragma once
// Validation report of a triangulated part (CGAL Polygon Mesh Processing inside) and the repairs
// done only when asked.
#include <string>
#include <vector>

#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/triangle_mesh.hpp"

namespace impactdeck::geometry {

struct ValidationOptions {
  bool check_self_intersections = true;  ///< O(F log F) box intersection; can be off for huge parts
  unsigned threads = 0;                  ///< self-intersection test; 0: all cores
  /// Count self-intersections through CGAL's own route (orient the soup, build a Surface_mesh, run
  /// PMP::self_intersections) instead of on the triangle array: slower, the reference the direct
  /// test is checked against (tests, bench). Non-manifold, inconsistently oriented or degenerate
  /// meshes take this route anyway (orienting the soup splits their vertices, which changes the
  /// count).
  bool self_intersections_via_surface_mesh = false;
};

struct ValidationReport {
  std::size_t triangles = 0;
  std::size_t vertices = 0;
  int shells = 0;                         ///< edge-connected components
  bool closed = false;                    ///< no boundary edge
  std::size_t boundary_edges = 0;         ///< edges with one triangle
  std::size_t non_manifold_edges = 0;     ///< edges with more than two triangles
  std::size_t non_manifold_vertices = 0;  ///< vertices whose triangles form several fans
  std::size_t orientation_conflicts = 0;  ///< manifold edges traversed twice the same way
  bool consistently_oriented = false;     ///< no conflict
  bool outward_oriented = false;          ///< every shell positive, cavities negative (nesting)
  std::vector<int> inward_shells;         ///< shells whose orientation is reversed
  std::vector<int> shell_nesting_depth;   ///< 0 outer, 1 cavity, 2 island in a cavity, ...
  std::size_t degenerate_triangles = 0;   ///< repeated vertex or zero area (exact predicate)
  bool self_intersections_checked = false;
  std::size_t self_intersecting_pairs = 0;  ///< pairs of triangles that intersect
  /// True when volume integrals are exact for this mesh: closed, manifold, consistently and
  /// outward oriented, no self-intersection (or not checked: then stated).
  bool valid_solid() const;
  /// The first reason why mass properties are only an approximation ("" when valid_solid()).
  std::string approximation_reason() const;
};

ValidationReport validate_mesh(const TriangleMesh& mesh, const ValidationOptions& options = {});

/// What validate_mesh computes on the way, for callers that need it next (load_part): the same
/// values build_edge_table, label_shells and compute_mass_properties give for the mesh, not
/// computed twice.
struct ValidationByproducts {
  EdgeTable edges;
  ShellLabels shells;
  MeshMassProperties mass;
};
ValidationReport validate_mesh(const TriangleMesh& mesh, const ValidationOptions& options,
                               ValidationByproducts* byproducts);

/// What `repair_mesh` did, one line per action ("merged 12 duplicate points", ...).
struct RepairLog {
  std::vector<std::string> actions;
};

/// Repairs asked for with --repair: removes degenerate triangles, merges duplicate points and
/// triangles, stitches borders, orients every shell consistently and outward (cavities inward).
/// Uses CGAL PMP. The mesh is replaced.
RepairLog repair_mesh(TriangleMesh& mesh);

}  // namespace impactdeck::geometry
