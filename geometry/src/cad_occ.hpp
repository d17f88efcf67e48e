#pragma once
// OpenCASCADE used directly by the CAD plugin (cad_occ.cpp; no OpenCASCADE type in this header):
// its own readers, and its adaptive integration of the mass properties, which reports the relative
// error it reached (Gmsh's occ::getMass uses a fixed Gauss rule, not exact on B-spline faces).
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/geometry/cad_shape.hpp"

namespace impactdeck::geometry::detail {

/// Mass properties of the solids of a file, in the reader's unit (mm for STEP and IGES).
struct OccMass {
  int solids = 0;
  double volume = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< per unit density, about `centre`
  double area = 0;                                     ///< of the distinct faces
  double relative_error = 0;  ///< OpenCASCADE's estimate for the volume integration (largest over the solids)
};

/// Makes OpenCASCADE's IGES and STEP translators ready (their parameters, such as the target unit
/// "xstep.cascade.unit", exist only after this: Gmsh 4.8 sets the unit before it creates its IGES
/// reader, which failed with "Could not set OpenCASCADE target unit 'MM'").
void occ_init_translators();

/// Reads `file` with OpenCASCADE's own reader (STEP and IGES converted to mm, as Gmsh's import
/// with Geometry.OCCTargetUnit = "MM"; a BREP as stored) and integrates each solid about a point
/// near it, adaptively to the relative accuracy `eps`. Throws InputError(file, "mass properties", ...).
OccMass occ_mass_properties(const std::filesystem::path& file, CadFormat format, double eps);

/// OpenCASCADE's own triangulation of the faces (BRepMesh_IncrementalMesh), the fallback when
/// every Gmsh try failed: nodes welded along the shared edges (each edge is discretised once),
/// triangles oriented along the face's orientation, in the reader's unit.
struct OccTriangulation {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangle_face;         ///< 0-based index of the OpenCASCADE face
  std::vector<Eigen::Vector3d> face_probe;  ///< per face: the centroid of its largest triangle
};

/// Reads `file` (as occ_mass_properties) and triangulates it with chordal deflection
/// `deflection` (reader's unit) and angular deflection `angle_rad`. Throws InputError(file,
/// "triangulation", ...).
OccTriangulation occ_triangulate(const std::filesystem::path& file, CadFormat format, double deflection,
                                 double angle_rad);

}  // namespace impactdeck::geometry::detail
