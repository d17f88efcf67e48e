#pragma once
// A triangulated part as a Shape: surface queries on a closed, outward-oriented mesh. Built once
// (AABB tree, adjacency, vertex normals, sharp edges), then every query is cheap.
// CGAL stays in the .cpp (pimpl); this header uses Eigen and the standard library only.
#include <functional>
#include <memory>

#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/geometry/triangle_mesh.hpp"

namespace impactdeck::geometry {

struct MeshShapeOptions {
  /// An edge is sharp when the angle between its two face normals exceeds this (degrees).
  double sharp_angle_deg = 30.0;
  /// Geodesic rings (around the three corners of the hit triangle) in the curvature fit; the
  /// error estimate refits with one ring more and reports the difference.
  int curvature_rings = 2;
  /// Degree of the fitted jet (CGAL Monge_via_jet_fitting; 2..4). 3 gives O(h^2) curvature.
  int jet_degree = 3;
};

/// Curvature with the details of its fit.
struct CurvatureFit {
  Curvature curvature;             ///< k1 >= k2, positive convex; error estimate included
  double condition_number = 0;     ///< of the jet least-squares system (CGAL; curvature_fit only)
  int neighbourhood_points = 0;    ///< points in the main fit
  bool planar = false;             ///< neighbourhood too small but coplanar: k = 0 exactly
};

class MeshShape final : public Shape {
 public:
  /// `mesh` must be closed and oriented outward (see validate_mesh / repair_mesh); `mass` its
  /// mass properties (compute_mass_properties). Throws InputError for an empty mesh.
  MeshShape(TriangleMesh mesh, const MeshMassProperties& mass, const MeshShapeOptions& options = {});
  ~MeshShape() override;
  MeshShape(const MeshShape&) = delete;
  MeshShape& operator=(const MeshShape&) = delete;

  std::string kind() const override { return "mesh"; }
  VolumeProperties volume_properties() const override { return mass_.volume; }
  /// Closest point (AABB tree) and outward normal there: the face normal on or next to a sharp
  /// edge, the barycentric blend of area-weighted vertex normals elsewhere.
  SurfacePoint closest_point(const Eigen::Vector3d& query_m) const override;
  /// Principal curvatures by jet fitting at the closest surface point (see curvature_fit).
  Curvature curvature(const SurfacePoint& at) const override;
  CurvatureFit curvature_fit(const Eigen::Vector3d& point_m) const;
  /// Within 1e-6 mean edge lengths of a sharp edge or of a vertex on one (the test curvature_fit
  /// applies before fitting).
  bool on_sharp_feature(const SurfacePoint& at) const override;
  /// The edge or corner there (Shape::sharp_feature): O(sharp edges at the vertex + the edge's
  /// run of mesh edges).
  std::optional<SharpFeature> sharp_feature(const SurfacePoint& at) const override;
  /// Eq. 26 on the mesh: the three axis-normal planes through the point cut the surface; each
  /// section's radius at the point follows from the jet-fitted curvature tensor by Euler's and
  /// Meusnier's theorems (κ = κ_n(t)/|n×e|, t = n×e/|n×e|); tangent cuts (|n×e| ≤ 1e-3) are left
  /// out. InputError on a sharp feature or when no cut is left.
  double paper_radius_m(const SurfacePoint& at) const override;
  std::optional<SurfacePoint> ray_exit(const Eigen::Vector3d& origin_m,
                                       const Eigen::Vector3d& direction) const override;
  double size_m() const override;
  /// Area-uniform over the triangles (cumulative areas, deterministic mt19937_64).
  std::vector<SurfacePoint> sample_surface(std::size_t count, std::uint64_t seed) const override;
  /// The extreme vertex along the direction (an exact support point of the polytope; among
  /// equal dot products the lowest vertex index), with the surface normal there (as
  /// closest_point gives it).
  std::optional<SurfacePoint> support_point(const Eigen::Vector3d& direction) const override;
  /// The support point of the smoothed surface (the blended vertex normals that closest_point
  /// reports): the point near the extreme vertex where that normal is `direction`, found on the
  /// faces within three rings of it. Smooth parts of a mesh converge to the true support point at
  /// second order this way, where the extreme vertex is first order. nullopt on a sharp feature or
  /// where no face brackets the direction.
  std::optional<SurfacePoint> smooth_support_point(const Eigen::Vector3d& direction) const;
  /// On the surface (within 1e-12 of the part's size) or inside: the orientation of the first
  /// face a ray meets (outward: inside), retried along other rays when the hit is within 1e-9
  /// of an edge or grazing; after 16 ambiguous rays, the sign of the winding number.
  bool contains(const Eigen::Vector3d& own_point_m) const override;
  const MeshShape* triangle_mesh() const override { return this; }

  /// Broad phase of continuous collision on the AABB tree: visits every face whose bounding box
  /// the box `moving` (own frame) meets while it translates by s * direction, s in
  /// [s_min, s_max], boxes entered earlier first. `visit(face, s_max)` returns the new s_max:
  /// lowering it prunes the rest of the search. Returns the final s_max.
  double sweep_faces(const Eigen::AlignedBox3d& moving, const Eigen::Vector3d& direction, double s_min,
                     double s_max, const std::function<double(int face, double s_max)>& visit) const;
  /// The same between two meshes (both AABB trees, best first over pairs of boxes): `mover`'s
  /// frame maps into this one by x -> rotation x + translation, and it translates by
  /// s * direction (this frame); its boxes are taken in this frame (the box of a rotated box)
  /// and padded by `pad_m`. Visits the pairs (own face, mover face) whose boxes meet for some s
  /// in [s_min, s_max]; `visit(own_face, mover_face, s_max)` returns the new s_max.
  double sweep_face_pairs(const MeshShape& mover, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                          const Eigen::Vector3d& direction, double pad_m, double s_min, double s_max,
                          const std::function<double(int own_face, int mover_face, double s_max)>& visit) const;

  /// Index of the triangle holding the closest surface point (AABB tree).
  int closest_triangle(const Eigen::Vector3d& query_m) const;

  const TriangleMesh& mesh() const { return mesh_; }
  const MeshMassProperties& mass_properties() const { return mass_; }
  std::size_t sharp_edge_count() const;
  const MeshShapeOptions& options() const { return options_; }
  double mean_edge_length_m() const;

 private:
  CurvatureFit fit_curvature(const Eigen::Vector3d& point_m, bool with_condition_number) const;
  struct Index;  // CGAL AABB tree and adjacency
  bool near_sharp_feature(int face, const Eigen::Vector3d& p) const;
  TriangleMesh mesh_;
  MeshMassProperties mass_;
  MeshShapeOptions options_;
  std::unique_ptr<Index> index_;
};

/// The sharp-edge count MeshShape reports (sharp_edge_count) for `sharp_angle_deg`, without
/// building its index (O(F): one edge table and the face normals).
std::size_t count_sharp_edges(const TriangleMesh& mesh, double sharp_angle_deg);
/// The same on the mesh's edge table (build_edge_table) when the caller has it already.
std::size_t count_sharp_edges(const TriangleMesh& mesh, const EdgeTable& edges, double sharp_angle_deg);

}  // namespace impactdeck::geometry
