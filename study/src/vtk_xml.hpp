#pragma once
// VTK XML files of points with point data (private to study/src): PolyData (.vtp, one vertex cell
// per point) or UnstructuredGrid (.vtu, one VTK_VERTEX cell per point; the one of the two that
// meshio reads too), every array `format="appended"` in one `<AppendedData encoding="raw">`
// section. Compressed (the default): the file declares `compressor="vtkZLibDataCompressor"` and
// `header_type="UInt64"`, and each array is its header [blocks, block size, last block size,
// compressed size of each block] followed by its blocks, each one zlib stream (VTK's documented
// layout, what vtkXMLReader, ParaView and meshio read). Raw: each array is its byte count (UInt32
// or UInt64) and its values. Values in the host's byte order (the `byte_order` attribute).
//
// Streamed within bounded memory: blocks are filled from the caller's arrays and compressed by
// worker threads a batch at a time and written in order as each batch is done; nothing is held
// but the batch in flight (a few blocks per thread), and nothing written is read back. The
// offsets and each array's block sizes are written as placeholders and filled in (overwritten in
// place) once known.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "impactdeck/study/sweep.hpp"

namespace impactdeck::study::detail {

/// One data array: VTK type name, name, components, and its values of tuples [begin, end) written
/// to `out` (tuple k at out + (k - begin) * tuple_bytes()); called concurrently for disjoint ranges.
struct VtkArray {
  std::string type;  ///< Float64, Int64, Int32, UInt8
  std::string name;
  int components = 1;
  std::function<void(std::size_t begin, std::size_t end, char* out)> fill;
  std::size_t value_bytes() const;  ///< of one component
  std::size_t tuple_bytes() const { return value_bytes() * static_cast<std::size_t>(components); }
};

enum class VtkDataset { poly_data, unstructured_grid };

struct VtkWriteOptions {
  VtkDataset dataset = VtkDataset::poly_data;
  bool compress = true;          ///< zlib blocks (header_type UInt64); false: raw values
  bool uint64_headers = false;   ///< raw only: UInt64 byte counts even when UInt32 would do
  unsigned threads = 0;          ///< compressing workers; 0: all cores
  ProgressFn progress;           ///< (tuples written over all arrays, total)
};

/// Writes the file of `points` (n tuples, "Points", 3 components) with `point_data` (n tuples
/// each) and one vertex cell per point, `comment` (an XML comment: "--" is replaced) and FieldData
/// `metres_per_length_unit` (ascii). `scalars` and `normals` name the PointData's active arrays
/// (empty: none). Atomic (common/atomic_file.hpp).
void write_vtk_points(const std::filesystem::path& path, std::size_t n, const std::vector<VtkArray>& point_data,
                      const VtkArray& points, const std::string& scalars, const std::string& normals,
                      const std::string& comment, const std::string& metres_per_length_unit,
                      const VtkWriteOptions& options);

}  // namespace impactdeck::study::detail
