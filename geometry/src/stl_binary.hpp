#pragma once
// Private to geometry/src: the binary STL fast path of load_mesh (no assimp, no per-triangle
// allocation).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "impactdeck/geometry/mesh_io.hpp"

namespace impactdeck::geometry::detail {

/// Reads a binary STL of `bytes` bytes on from `f`, positioned just after its first 84 bytes
/// `head` (the caller has read them to tell binary from ASCII: the file is opened once), when it is
/// a binary STL by assimp's own test — exactly 84 + 50 n bytes with n >= 1 triangles, whatever the
/// header says — and returns nullopt otherwise (ASCII, empty or malformed files go to the general
/// readers, which report them). The result is the one assimp's route gives: vertex ids in order of
/// first use, coordinates the exact doubles of the float32 values times metres_per(unit), the same
/// counts and the same message for a non-finite coordinate; errors name `where`.
std::optional<LoadedMesh> read_binary_stl(std::FILE* f, const std::string& head, const std::string& where,
                                          LengthUnit unit, std::uintmax_t bytes);

}  // namespace impactdeck::geometry::detail
