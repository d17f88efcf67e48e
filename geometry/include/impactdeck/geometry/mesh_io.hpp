#pragma once
// Reading triangulated parts (STL ascii/binary, OBJ, PLY, OFF, via assimp) and writing STL.
// The length unit of a file is always declared by the user, never guessed.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "impactdeck/common/units.hpp"
#include "impactdeck/geometry/triangle_mesh.hpp"

namespace impactdeck::geometry {

struct LoadedMesh {
  TriangleMesh mesh;                    ///< merged vertices, SI metres
  std::string format;                   ///< "stl", "obj", "ply", "off"
  std::size_t file_vertices = 0;        ///< vertex records read (before merging)
  std::size_t merged_vertices = 0;      ///< records that coincided exactly with an earlier one
  std::size_t polygons_triangulated = 0;  ///< faces with more than 3 corners split by assimp
  std::size_t lines_ignored = 0;
  std::size_t points_ignored = 0;
  std::vector<std::string> warnings;    ///< one line each
};

/// Loads a part and converts it to metres. Coordinates are exact double conversions of what the
/// parser produced (assimp stores 32-bit floats in Debian's build: see docs/geometry.md).
/// Throws InputError("FILE", place, reason) for a missing/empty/unreadable file, a parse error
/// and a file without triangles; lines and points are ignored with a warning.
LoadedMesh load_mesh(const std::filesystem::path& file, LengthUnit unit);

/// Writes a binary STL (80-byte header without "solid", float32 coordinates), atomically.
/// Coordinates are divided by `metres_per(unit)`.
void write_stl_binary(const std::filesystem::path& file, const TriangleMesh& mesh,
                      LengthUnit unit = LengthUnit::m, const std::string& header = "impactdeck");
/// Writes an ASCII STL with 9 significant digits, atomically.
void write_stl_ascii(const std::filesystem::path& file, const TriangleMesh& mesh,
                     LengthUnit unit = LengthUnit::m, const std::string& solid_name = "impactdeck");

/// The same STL written to a stream (`-o -`: stdout); `name` names the output in messages.
void write_stl_binary(std::ostream& out, const std::string& name, const TriangleMesh& mesh,
                      LengthUnit unit = LengthUnit::m, const std::string& header = "impactdeck");
void write_stl_ascii(std::ostream& out, const std::string& name, const TriangleMesh& mesh,
                     LengthUnit unit = LengthUnit::m, const std::string& solid_name = "impactdeck");

}  // namespace impactdeck::geometry
