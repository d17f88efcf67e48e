#pragma once
// impactdeck's own readers for OFF, OBJ, ASCII STL and PLY (ASCII and binary, any scalar type).
// Debian's assimp stores coordinates as 32-bit floats: a 1 mm cube 3 km from the origin read
// through it comes out 6.9 % short in volume. These readers keep double precision from the text
// (or the file's doubles) to the mass integrals, are strict (one message with the line or element
// that is wrong, no guessing) and bounded (counts checked against the bytes that must hold them
// before anything is reserved). Binary STL (float32 by definition) is left to mesh_io.cpp.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "impactdeck/common/units.hpp"
#include "impactdeck/geometry/mesh_io.hpp"

namespace impactdeck::geometry::detail {

/// Reads `file` (`bytes` long, extension `ext` in lower case with its dot) when it is OFF, OBJ,
/// PLY or an ASCII STL; nullopt for a binary STL. Polygons are triangulated (fan when convex, ear
/// clipping in their plane otherwise), points and lines are counted and skipped, vertices with
/// equal coordinates are merged. Throws InputError(file, "line N" / "face N" / ..., reason).
std::optional<LoadedMesh> read_own_format(const std::filesystem::path& file, const std::string& ext, LengthUnit unit,
                                          std::uintmax_t bytes);

/// The same from the file's whole text `text` (already read): OFF, OBJ, PLY or ASCII STL by `ext`.
std::optional<LoadedMesh> read_own_text(std::string text, const std::filesystem::path& file, const std::string& ext,
                                        LengthUnit unit);

/// An ASCII STL starts with "solid" and does not have the binary size 84 + 50 n (a binary STL's
/// 80-byte header may start with "solid" too; assimp and every reader use the same test). `head`:
/// the file's first (up to) 84 bytes; `bytes`: its size.
bool is_ascii_stl(const std::string& head, std::uintmax_t bytes);

/// The end of every reader: a warning for the points and lines skipped, an InputError(file,
/// "faces", ...) when no triangle is left.
void finish_loaded(LoadedMesh& mesh, const std::string& where);

/// A part file that may be read: a regular file whose reading fits in the free memory. Returns its
/// size; throws InputError(file, "file", reason) naming the figures.
std::uintmax_t check_part_file(const std::filesystem::path& file);

/// After loading: every coordinate within 1e20 m of the origin and 0 or at least 1e-100 m in
/// magnitude, the part between 1e-20 m and
/// 1e20 m across (its volume integrals, up to size^5, stay within [1e-100, 1e100]), and enough
/// free memory for validation, mass properties and the surface index (about 700 bytes per
/// triangle, measured).
void check_part_extent(const LoadedMesh& mesh, const std::string& where);

}  // namespace impactdeck::geometry::detail
