#include "vtk_xml.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <ostream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/xml_text.hpp"
#include "impactdeck/common/error.hpp"
#include "parallel.hpp"

namespace impactdeck::study::detail {

std::size_t VtkArray::value_bytes() const {
  if (type == "Float64" || type == "Int64" || type == "UInt64") return 8;
  if (type == "Float32" || type == "Int32" || type == "UInt32") return 4;
  if (type == "Int8" || type == "UInt8") return 1;
  throw Error(ExitCode::internal_error, "VTK array '" + name + "': unknown type " + type);
}

namespace {

// Uncompressed bytes per block: a multiple of every tuple size written (1, 4, 8, 24 bytes), so that
// a block holds whole tuples. 384 KiB: large enough that the per-block cost (a zlib stream's set-up,
// 8 header bytes) vanishes, small enough that a batch of them in flight stays a few megabytes.
constexpr std::size_t kBlockBytes = 24 * 16384;

// How an array's blocks are deflated, chosen on a sample of its first values (below): the fast
// entropy coders where they pay, and stored (zlib's level 0: a copy and a checksum) where the
// values are noise that Huffman coding would shrink by a few per cent at the cost of most of the
// writing time (point coordinates and normals of a random cloud).
enum class Deflate { stored, rle, fast };

std::string deflate_block(const char* data, std::size_t bytes, Deflate mode) {
  z_stream z{};
  const int level = mode == Deflate::stored ? 0 : 1;
  const int strategy = mode == Deflate::rle ? Z_RLE : Z_DEFAULT_STRATEGY;
  if (deflateInit2(&z, level, Z_DEFLATED, 15, 8, strategy) != Z_OK) {
    throw Error(ExitCode::internal_error, "zlib: deflateInit2 failed");
  }
  std::string out(deflateBound(&z, static_cast<uLong>(bytes)), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
  z.avail_in = static_cast<uInt>(bytes);
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  const std::size_t written = out.size() - z.avail_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw Error(ExitCode::internal_error, "zlib: deflate did not finish a block");
  out.resize(written);
  return out;
}

// The mode of an array from its first (at most 32 KiB of) values: long repeats (a constant, a
// count) deflate best with matches; otherwise run-length Huffman, or stored when that saves under
// 5 %.
Deflate choose_deflate(const VtkArray& a, std::size_t n) {
  const std::size_t tuples = std::min(n, std::max<std::size_t>(1, 32768 / a.tuple_bytes()));
  if (tuples == 0) return Deflate::fast;
  std::string sample(tuples * a.tuple_bytes(), '\0');
  a.fill(0, tuples, sample.data());
  const double rle = static_cast<double>(deflate_block(sample.data(), sample.size(), Deflate::rle).size());
  const double fast = static_cast<double>(deflate_block(sample.data(), sample.size(), Deflate::fast).size());
  if (fast < 0.7 * rle) return Deflate::fast;
  if (rle > 0.95 * static_cast<double>(sample.size())) return Deflate::stored;
  return Deflate::rle;
}

bool little_endian() {
  const std::uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

// An offset attribute written before its value is known: `offset="` then a field of fixed width
// (the number, its closing quote, spaces up to the width: whitespace between attributes).
constexpr std::size_t kOffsetField = 22;

void put_offset_field(std::ostream& o, std::uint64_t offset) {
  std::string f = std::to_string(offset) + "\"";
  f.resize(kOffsetField, ' ');
  o.write(f.data(), static_cast<std::streamsize>(f.size()));
}

template <class T>
void put(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s.append(b, sizeof(T));
}

}  // namespace

void write_vtk_points(const std::filesystem::path& path, std::size_t n, const std::vector<VtkArray>& point_data,
                      const VtkArray& points, const std::string& scalars, const std::string& normals,
                      const std::string& comment, const std::string& metres_per_length_unit,
                      const VtkWriteOptions& options) {
  const bool poly = options.dataset == VtkDataset::poly_data;
  // One vertex cell per point: connectivity 0..n-1, offsets 1..n (Int32 while they fit), and for an
  // unstructured grid the cell types (1: VTK_VERTEX).
  const bool int32 = n < static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  auto count = [int32](const char* name, std::int64_t first) {
    VtkArray a{int32 ? "Int32" : "Int64", name, 1, nullptr};
    a.fill = [int32, first](std::size_t begin, std::size_t end, char* out) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::int64_t v = first + static_cast<std::int64_t>(i);
        if (int32) {
          const std::int32_t v32 = static_cast<std::int32_t>(v);
          std::memcpy(out + 4 * (i - begin), &v32, 4);
        } else {
          std::memcpy(out + 8 * (i - begin), &v, 8);
        }
      }
    };
    return a;
  };
  const VtkArray connectivity = count("connectivity", 0), offsets = count("offsets", 1);
  const VtkArray types{"UInt8", "types", 1, [](std::size_t begin, std::size_t end, char* out) {
                         std::memset(out, 1, end - begin);
                       }};
  std::vector<const VtkArray*> all;
  for (const VtkArray& a : point_data) all.push_back(&a);
  all.push_back(&points);
  all.push_back(&connectivity);
  all.push_back(&offsets);
  if (!poly) all.push_back(&types);

  const bool compress = options.compress;
  const bool wide = compress || options.uint64_headers || n * 24 > 0xffffffffull;
  std::vector<Deflate> modes(all.size(), Deflate::stored);
  if (compress)
    for (std::size_t k = 0; k < all.size(); ++k) modes[k] = choose_deflate(*all[k], n);

  write_file_atomically(path, [&](std::ostream& o) {
    // The XML part, each offset a placeholder filled in at the end.
    std::vector<std::streampos> offset_at(all.size());
    auto declare = [&](std::size_t k) {
      const VtkArray& a = *all[k];
      o << "<DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\"";
      if (a.components != 1) o << " NumberOfComponents=\"" << a.components << "\"";
      o << " format=\"appended\" offset=\"";
      offset_at[k] = o.tellp();
      put_offset_field(o, 0);
      o << "/>\n";
    };
    // The header holds the scene's names: made comment text ("--" and control characters are not
    // allowed inside an XML comment).
    const std::string note = xml_comment_text(comment);
    const char* grid = poly ? "PolyData" : "UnstructuredGrid";
    o << "<?xml version=\"1.0\"?>\n<!--\n" << note << "-->\n"
      << "<VTKFile type=\"" << grid << "\" version=\"1.0\" byte_order=\"" << (little_endian() ? "LittleEndian" : "BigEndian")
      << "\" header_type=\"" << (wide ? "UInt64" : "UInt32") << "\""
      << (compress ? " compressor=\"vtkZLibDataCompressor\"" : "") << ">\n<" << grid << ">\n"
      << "<FieldData>\n<DataArray type=\"Float64\" Name=\"metres_per_length_unit\" NumberOfTuples=\"1\" "
         "format=\"ascii\">" << metres_per_length_unit << "</DataArray>\n</FieldData>\n";
    if (poly) {
      o << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
        << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
    } else {
      o << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n";
    }
    o << "<PointData";
    if (!scalars.empty()) o << " Scalars=\"" << scalars << "\"";
    if (!normals.empty()) o << " Normals=\"" << normals << "\"";
    o << ">\n";
    std::size_t k = 0;
    for (; k < point_data.size(); ++k) declare(k);
    o << "</PointData>\n<Points>\n";
    declare(k++);
    o << "</Points>\n" << (poly ? "<Verts>\n" : "<Cells>\n");
    for (; k < all.size(); ++k) declare(k);
    o << (poly ? "</Verts>\n" : "</Cells>\n") << "</Piece>\n</" << grid << ">\n<AppendedData encoding=\"raw\">\n_";
    const std::streampos appended = o.tellp();

    // The blocks of every array in file order, a batch at a time: filled (and deflated) by the
    // workers, each into its own slot, then written in order by this thread.
    struct Block {
      std::size_t array, index, begin, end;  // tuples [begin, end) of all[array]
    };
    std::vector<std::size_t> blocks_of(all.size());
    std::vector<Block> blocks;
    for (std::size_t a = 0; a < all.size(); ++a) {
      const std::size_t per = kBlockBytes / all[a]->tuple_bytes();
      blocks_of[a] = (n + per - 1) / per;
      for (std::size_t b = 0; b < blocks_of[a]; ++b) blocks.push_back({a, b, b * per, std::min(n, (b + 1) * per)});
    }
    const unsigned threads = resolve_threads(options.threads);
    const std::size_t batch = std::max<std::size_t>(2, 4 * static_cast<std::size_t>(threads));
    std::vector<std::string> slot(batch);
    std::vector<std::uint64_t> offset_of(all.size(), 0);
    std::vector<std::uint64_t> sizes;  // deflated sizes of the current array's blocks
    std::streampos header_at{};
    // An array's header: compressed, [blocks, block size, last block size, each block's size],
    // written as zeros first and filled in after its last block; raw, its byte count.
    auto start_array = [&](std::size_t a) {
      offset_of[a] = static_cast<std::uint64_t>(o.tellp() - appended);
      std::string h;
      if (compress) {
        header_at = o.tellp();
        h.assign((3 + blocks_of[a]) * 8, '\0');
        sizes.clear();
      } else {
        const std::uint64_t bytes = static_cast<std::uint64_t>(n) * all[a]->tuple_bytes();
        if (wide) put(h, bytes);
        else put(h, static_cast<std::uint32_t>(bytes));
      }
      o.write(h.data(), static_cast<std::streamsize>(h.size()));
    };
    auto end_array = [&](std::size_t a) {
      if (!compress) return;
      const std::uint64_t per_bytes = kBlockBytes / all[a]->tuple_bytes() * all[a]->tuple_bytes();
      const std::uint64_t bytes = static_cast<std::uint64_t>(n) * all[a]->tuple_bytes();
      std::string h;
      put<std::uint64_t>(h, blocks_of[a]);
      put<std::uint64_t>(h, per_bytes);
      put<std::uint64_t>(h, blocks_of[a] == 0 ? 0 : bytes - (blocks_of[a] - 1) * per_bytes);
      for (std::uint64_t s : sizes) put(h, s);
      const std::streampos end = o.tellp();
      o.seekp(header_at);
      o.write(h.data(), static_cast<std::streamsize>(h.size()));
      o.seekp(end);
    };
    if (n == 0) {
      for (std::size_t a = 0; a < all.size(); ++a) {
        start_array(a);
        end_array(a);
      }
    }
    const std::uint64_t total = static_cast<std::uint64_t>(n) * all.size();
    std::uint64_t done = 0;
    for (std::size_t first = 0; first < blocks.size(); first += batch) {
      const std::size_t here = std::min(batch, blocks.size() - first);
      parallel_for(here, threads, 1, [&](std::size_t s) {
        const Block& b = blocks[first + s];
        const VtkArray& a = *all[b.array];
        if (!compress) {
          slot[s].resize((b.end - b.begin) * a.tuple_bytes());
          a.fill(b.begin, b.end, slot[s].data());
          return;
        }
        thread_local std::string raw;
        raw.resize((b.end - b.begin) * a.tuple_bytes());
        a.fill(b.begin, b.end, raw.data());
        slot[s] = deflate_block(raw.data(), raw.size(), modes[b.array]);
      }, nullptr);
      for (std::size_t s = 0; s < here; ++s) {
        const Block& b = blocks[first + s];
        if (b.index == 0) start_array(b.array);
        o.write(slot[s].data(), static_cast<std::streamsize>(slot[s].size()));
        sizes.push_back(slot[s].size());
        done += b.end - b.begin;
        if (b.index + 1 == blocks_of[b.array]) end_array(b.array);
      }
      if (options.progress) options.progress(done, total);
    }
    o << "\n</AppendedData>\n</VTKFile>\n";
    // The offsets, now known, into their fields.
    const std::streampos end = o.tellp();
    for (std::size_t a = 0; a < all.size(); ++a) {
      o.seekp(offset_at[a]);
      put_offset_field(o, offset_of[a]);
    }
    o.seekp(end);
    if (!o) throw Error(ExitCode::internal_error, "VTK file: write failed");
  });
}

}  // namespace impactdeck::study::detail
