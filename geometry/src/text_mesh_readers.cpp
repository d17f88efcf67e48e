// Own readers for OFF, OBJ, ASCII STL and PLY in double precision (text_mesh_readers.hpp).
#include "text_mesh_readers.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/numeric.hpp"

namespace impactdeck::geometry::detail {
namespace fs = std::filesystem;

namespace {

// Polygons with more corners than this that are not convex are refused: ear clipping costs up to
// k^3 operations.
constexpr std::size_t kMaxConcaveCorners = 1000;
// Measured peak memory of `inspect` (load, validation with self-intersections, mass properties,
// surface index): 216 MB for 327 680 triangles, 660 bytes each.
constexpr double kBytesPerTriangle = 700;
// Part extent limits (text_mesh_readers.hpp).
constexpr double kMaxCoordinateM = 1e20, kMinSizeM = 1e-20, kMaxSizeM = 1e20;

std::string shown(std::string_view t) {
  std::string s(t.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return "'" + s + (t.size() > 40 ? "...'" : "'");
}

// A polygon soup as read: vertices in file units, faces as runs of corners.
struct Raw {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<int> corners;
  std::vector<std::size_t> face_start{0};  // face f: corners[face_start[f], face_start[f + 1])
  std::size_t file_vertices = 0;
  void add_face(const int* c, std::size_t n) {
    corners.insert(corners.end(), c, c + n);
    face_start.push_back(corners.size());
  }
  std::size_t faces() const { return face_start.size() - 1; }
};

// A cursor over the file's bytes that knows its line.
class Text {
 public:
  Text(const std::string& s, std::string where) : p_(s.data()), end_(s.data() + s.size()), where_(std::move(where)) {}

  std::size_t line() const { return line_; }
  bool at_end() const { return p_ >= end_; }
  const char* pos() const { return p_; }
  const char* end() const { return end_; }
  void seek(const char* p) { p_ = p; }

  [[noreturn]] void fail(const std::string& reason) const {
    throw InputError(where_, "line " + std::to_string(line_), reason);
  }
  [[noreturn]] void fail_at(std::size_t line, const std::string& reason) const {
    throw InputError(where_, "line " + std::to_string(line), reason);
  }

  // Skips blanks; with `cross_lines` also line ends and `comment`-to-end-of-line comments.
  void skip(bool cross_lines, char comment) {
    while (p_ < end_) {
      const char c = *p_;
      if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++p_;
      } else if (comment && c == comment) {
        while (p_ < end_ && *p_ != '\n') ++p_;
      } else if (c == '\n' && cross_lines) {
        ++p_;
        ++line_;
      } else {
        return;
      }
    }
  }
  // The next token on this line ("" at a line end or the end of the file).
  std::string_view token(char comment) {
    skip(false, comment);
    const char* b = p_;
    while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_)) && !(comment && *p_ == comment)) ++p_;
    return std::string_view(b, static_cast<std::size_t>(p_ - b));
  }
  // The next token, crossing lines.
  std::string_view any_token(char comment) {
    skip(true, comment);
    return token(comment);
  }
  // To the start of the next line; the rest of this one is returned.
  std::string_view rest_of_line() {
    const char* b = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    std::string_view r(b, static_cast<std::size_t>(p_ - b));
    if (p_ < end_) ++p_, ++line_;
    while (!r.empty() && std::isspace(static_cast<unsigned char>(r.back()))) r.remove_suffix(1);
    return r;
  }
  bool at_line_end(char comment) {
    skip(false, comment);
    return p_ >= end_ || *p_ == '\n';
  }

 private:
  const char* p_;
  const char* end_;
  std::string where_;
  std::size_t line_ = 1;
};

// A finite double from a token; `what` names it in messages.
double number(Text& t, std::string_view tok, const char* what) {
  if (tok.empty()) t.fail(std::string("expected ") + what + ", found the end of the line");
  std::string_view s = tok;
  if (s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range) {
    t.fail(std::string(what) + " " + shown(tok) + " is outside double precision's range");
  }
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) t.fail(std::string("expected ") + what + ", got " + shown(tok));
  if (!std::isfinite(v)) t.fail(std::string(what) + " " + shown(tok) + " is not a finite number");
  return v + 0.0;
}

// A whole number from a token (faces' indices, counts).
long long integer(Text& t, std::string_view tok, const char* what) {
  if (tok.empty()) t.fail(std::string("expected ") + what + ", found the end of the line");
  std::string_view s = tok;
  if (s.front() == '+') s.remove_prefix(1);
  long long v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range) t.fail(std::string(what) + " " + shown(tok) + " is too large");
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) t.fail(std::string("expected ") + what + ", got " + shown(tok));
  return v;
}

bool iequals(std::string_view a, const char* b) {
  const std::size_t n = std::strlen(b);
  if (a.size() != n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != b[i]) return false;
  return true;
}

std::string count_text(long double n) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(0) << n;
  return o.str();
}

// ---------------------------------------------------------------------------------------------
// OFF (Geomview): [ST][C][N]OFF, counts "V F [E]", V vertex lines (x y z, then per-vertex data
// the variant declares), F face lines "n i1 ... in [colour]". '#' starts a comment.
Raw read_off(const std::string& text, const std::string& where) {
  Text t(text, where);
  Raw raw;
  std::string_view kw = t.any_token('#');
  std::string_view v = kw;
  if (v.size() >= 2 && v.substr(0, 2) == "ST") v.remove_prefix(2);
  if (!v.empty() && v.front() == 'C') v.remove_prefix(1);
  if (!v.empty() && v.front() == 'N') v.remove_prefix(1);
  if (v != "OFF") {
    if (kw.size() >= 3 && kw.substr(kw.size() - 3) == "OFF") {
      t.fail("OFF variant " + shown(kw) + " is not supported (3-D OFF, COFF, NOFF, STOFF and their combinations are)");
    }
    t.fail("not an OFF file: the first word must be OFF (or COFF, NOFF, STOFF), got " + shown(kw));
  }
  std::string_view first = t.token('#');
  if (first == "BINARY") t.fail("binary OFF is not supported");
  if (first.empty()) first = t.any_token('#');
  const std::size_t count_line = t.line();
  const long long nv = integer(t, first, "the vertex count");
  const long long nf = integer(t, t.token('#'), "the face count");
  if (!t.at_line_end('#')) integer(t, t.token('#'), "the edge count");
  if (!t.at_line_end('#')) t.fail("unexpected " + shown(t.token('#')) + " after the counts");
  // Each vertex needs at least "0 0 0\n" (6 bytes), each face "0\n" (2 bytes): counts the file
  // cannot hold are refused before anything is reserved (assimp's OutOfMemory.off declares 3.5e11
  // vertices in 309 bytes).
  const long double need = 6.0L * nv + 2.0L * nf;
  const long double have = static_cast<long double>(t.end() - t.pos());
  if (nv < 0 || nf < 0 || need > have || nv > std::numeric_limits<int>::max()) {
    t.fail_at(count_line, "the OFF header declares " + count_text(nv) + " vertices and " + count_text(nf) +
                              " faces, more than a file of " + std::to_string(text.size()) + " bytes can hold");
  }
  raw.vertices.reserve(static_cast<std::size_t>(nv));
  t.rest_of_line();
  for (long long i = 0; i < nv; ++i) {
    t.skip(true, '#');
    if (t.at_end()) t.fail("unexpected end of file: " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    Eigen::Vector3d x;
    for (int k = 0; k < 3; ++k) x[k] = number(t, t.token('#'), "a vertex coordinate");
    raw.vertices.push_back(x);
    t.rest_of_line();  // per-vertex colour, normal or texture coordinates of the variant
  }
  raw.file_vertices = raw.vertices.size();
  std::vector<int> face;
  for (long long f = 0; f < nf; ++f) {
    t.skip(true, '#');
    if (t.at_end()) t.fail("unexpected end of file: " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    const long long n = integer(t, t.token('#'), "the face's vertex count");
    if (n < 1 || n > 1000000) t.fail("a face with " + std::to_string(n) + " vertices (1 to 1000000 allowed)");
    face.clear();
    for (long long k = 0; k < n; ++k) {
      const long long idx = integer(t, t.token('#'), "a vertex index");
      if (idx < 0 || idx >= nv) {
        t.fail("vertex index " + std::to_string(idx) + " out of range (" + std::to_string(nv) + " vertices)");
      }
      face.push_back(static_cast<int>(idx));
    }
    raw.add_face(face.data(), face.size());
    t.rest_of_line();  // face colour
  }
  t.skip(true, '#');
  if (!t.at_end()) t.fail("unexpected " + shown(t.token('#')) + " after the last face");
  return raw;
}

// ---------------------------------------------------------------------------------------------
// OBJ (Wavefront): statements "v x y z [w]" (or with a colour), "f a b c ..." with a, a/t, a//n,
// a/t/n and negative (relative) indices, "p" points and "l" lines (skipped); the other
// statements of the format (groups, materials, texture and normal vectors, free-form geometry)
// carry nothing for the mass properties and are skipped; anything else is an error.
bool known_obj_statement(std::string_view k) {
  static const char* const kKnown[] = {"vt", "vn", "vp", "g", "o", "s", "mg", "usemtl", "mtllib", "usemap",
                                       "maplib", "lod", "bevel", "c_interp", "d_interp", "trace_obj",
                                       "shadow_obj", "ctech", "stech", "cstype", "deg", "bmat", "step",
                                       "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end",
                                       "con", "call", "csh", "res"};
  for (const char* s : kKnown)
    if (k == s) return true;
  return false;
}

Raw read_obj(const std::string& original, const std::string& where, std::size_t& points, std::size_t& lines) {
  // Line continuations ("\" at the end of a line) joined first, keeping the line count: the
  // joined line gets a newline later.
  std::string text;
  if (original.find("\\\n") != std::string::npos || original.find("\\\r\n") != std::string::npos) {
    text.reserve(original.size());
    std::size_t pending = 0;
    for (std::size_t i = 0; i < original.size(); ++i) {
      if (original[i] == '\\' && (i + 1 < original.size() && (original[i + 1] == '\n' ||
                                                              (original[i + 1] == '\r' && i + 2 < original.size() &&
                                                               original[i + 2] == '\n')))) {
        i += original[i + 1] == '\r' ? 2 : 1;
        text += ' ';
        ++pending;
        continue;
      }
      text += original[i];
      if (original[i] == '\n') text.append(pending, '\n'), pending = 0;
    }
  }
  const std::string& s = text.empty() ? original : text;
  // Vertices in the file (positive indices may refer to vertices defined further down): counted
  // first, so that every error is reported at the first line that has one.
  long long total = 0;
  for (std::size_t i = 0; i < s.size(); i = s.find('\n', i), i = i == std::string::npos ? s.size() : i + 1) {
    std::size_t j = i;
    while (j < s.size() && (s[j] == ' ' || s[j] == '\t')) ++j;
    if (j + 1 < s.size() && s[j] == 'v' && (s[j + 1] == ' ' || s[j + 1] == '\t')) ++total;
  }
  Text t(s, where);
  Raw raw;
  std::vector<long long> face;
  while (!t.at_end()) {
    const std::string_view kw = t.token('#');
    if (kw.empty()) {
      t.rest_of_line();
      continue;
    }
    if (kw == "v") {
      Eigen::Vector3d x;
      for (int k = 0; k < 3; ++k) x[k] = number(t, t.token('#'), "a vertex coordinate");
      int extra = 0;
      while (!t.at_line_end('#')) number(t, t.token('#'), "a vertex weight or colour"), ++extra;
      if (extra != 0 && extra != 1 && extra != 3 && extra != 4) {
        t.fail("a vertex needs x y z [w] or x y z r g b [a], got " + std::to_string(3 + extra) + " numbers");
      }
      if (raw.vertices.size() >= static_cast<std::size_t>(std::numeric_limits<int>::max())) t.fail("too many vertices");
      raw.vertices.push_back(x);
    } else if (kw == "f" || kw == "fo" || kw == "l" || kw == "p") {
      face.clear();
      for (std::string_view ref = t.token('#'); !ref.empty(); ref = t.token('#')) {
        const std::string_view head = ref.substr(0, ref.find('/'));
        const long long idx = integer(t, head, "a vertex index");
        if (idx == 0) t.fail("vertex index 0: OBJ indices start at 1 (or count back from -1)");
        long long resolved = idx;
        if (idx < 0) {
          resolved = static_cast<long long>(raw.vertices.size()) + idx + 1;
          if (resolved < 1) {
            t.fail("vertex index " + std::to_string(idx) + " out of range (" + std::to_string(raw.vertices.size()) +
                   " vertices so far)");
          }
        } else if (idx > total) {
          t.fail("vertex index " + std::to_string(idx) + " out of range (" + std::to_string(total) + " vertices)");
        }
        face.push_back(resolved - 1);
      }
      if (kw == "p") {
        if (face.empty()) t.fail("a point statement without a vertex");
        points += face.size();
      } else if (kw == "l") {
        if (face.size() < 2) t.fail("a line needs at least 2 vertices, got " + std::to_string(face.size()));
        lines += face.size() - 1;
      } else {
        if (face.size() < 3) t.fail("a face needs at least 3 vertices, got " + std::to_string(face.size()));
        raw.corners.insert(raw.corners.end(), face.begin(), face.end());
        raw.face_start.push_back(raw.corners.size());
      }
    } else if (!known_obj_statement(kw)) {
      t.fail("unknown OBJ statement " + shown(kw));
    }
    t.rest_of_line();
  }
  raw.file_vertices = raw.vertices.size();
  return raw;
}

// ---------------------------------------------------------------------------------------------
// ASCII STL: solid NAME, then facets "facet normal nx ny nz / outer loop / vertex x y z (x3) /
// endloop / endfacet", then "endsolid [NAME]"; several solids may follow each other. Keywords in
// any case. The normals are not used (they may even be NaN in exported files of degenerate facets).
Raw read_ascii_stl(const std::string& text, const std::string& where) {
  Text t(text, where);
  Raw raw;
  auto expect = [&](const char* kw) {
    const std::string_view tok = t.any_token(0);
    if (tok.empty()) t.fail(std::string("unexpected end of file: expected '") + kw + "'");
    if (!iequals(tok, kw)) t.fail(std::string("expected '") + kw + "', got " + shown(tok));
  };
  auto any_number = [&](std::string_view tok) {  // a normal component: any number, NaN included
    std::string_view s = tok;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double v;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (tok.empty() || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range) || r.ptr != s.data() + s.size()) {
      t.fail("expected a normal component, got " + shown(tok));
    }
  };
  expect("solid");
  t.rest_of_line();
  for (;;) {
    const std::string_view tok = t.any_token(0);
    if (tok.empty()) t.fail("unexpected end of file: 'endsolid' is missing");
    if (iequals(tok, "endsolid")) {
      t.rest_of_line();
      const std::string_view next = t.any_token(0);
      if (next.empty()) break;
      if (!iequals(next, "solid")) t.fail("expected 'solid' or the end of the file after 'endsolid', got " + shown(next));
      t.rest_of_line();
      continue;
    }
    if (!iequals(tok, "facet")) t.fail("expected 'facet' or 'endsolid', got " + shown(tok));
    expect("normal");
    for (int k = 0; k < 3; ++k) any_number(t.any_token(0));
    expect("outer");
    expect("loop");
    int c[3];
    for (int k = 0; k < 3; ++k) {
      expect("vertex");
      Eigen::Vector3d x;
      for (int i = 0; i < 3; ++i) x[i] = number(t, t.any_token(0), "a vertex coordinate");
      if (raw.vertices.size() >= static_cast<std::size_t>(std::numeric_limits<int>::max())) t.fail("too many vertices");
      c[k] = static_cast<int>(raw.vertices.size());
      raw.vertices.push_back(x);
    }
    const std::string_view after = t.any_token(0);
    if (iequals(after, "vertex")) t.fail("a facet with more than 3 vertices (STL facets are triangles)");
    if (!iequals(after, "endloop")) t.fail("expected 'endloop', got " + (after.empty() ? std::string("the end of the file") : shown(after)));
    expect("endfacet");
    raw.add_face(c, 3);
  }
  raw.file_vertices = raw.vertices.size();
  return raw;
}

// ---------------------------------------------------------------------------------------------
// PLY: header, then the elements in order, ASCII (one element per line) or binary (either byte
// order). The vertex element's x, y, z (any numeric type, doubles kept) and the face element's
// vertex_indices (or vertex_index) list are used; everything else is read and skipped.
enum class PlyType { none, i8, u8, i16, u16, i32, u32, f32, f64 };

PlyType ply_type(std::string_view s) {
  static const std::pair<const char*, PlyType> kTypes[] = {
      {"char", PlyType::i8},    {"int8", PlyType::i8},    {"uchar", PlyType::u8},   {"uint8", PlyType::u8},
      {"short", PlyType::i16},  {"int16", PlyType::i16},  {"ushort", PlyType::u16}, {"uint16", PlyType::u16},
      {"int", PlyType::i32},    {"int32", PlyType::i32},  {"uint", PlyType::u32},   {"uint32", PlyType::u32},
      {"float", PlyType::f32},  {"float32", PlyType::f32}, {"double", PlyType::f64}, {"float64", PlyType::f64}};
  for (const auto& [name, t] : kTypes)
    if (s == name) return t;
  return PlyType::none;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::i8: case PlyType::u8: return 1;
    case PlyType::i16: case PlyType::u16: return 2;
    case PlyType::i32: case PlyType::u32: case PlyType::f32: return 4;
    case PlyType::f64: return 8;
    case PlyType::none: return 0;
  }
  return 0;
}

bool ply_integer(PlyType t) { return t != PlyType::f32 && t != PlyType::f64 && t != PlyType::none; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::none;
  PlyType count_type = PlyType::none;  // lists only
  bool list = false;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::size_t line = 0;
  std::vector<PlyProperty> properties;
};

// Reads binary PLY scalars from a bounded buffer.
class Bytes {
 public:
  Bytes(const char* p, const char* end, bool big_endian, std::string where)
      : p_(p), end_(end), big_(big_endian), where_(std::move(where)) {}
  double read(PlyType t, const std::string& what) {
    const std::size_t n = ply_size(t);
    if (static_cast<std::size_t>(end_ - p_) < n) {
      throw InputError(where_, what, "the file ends inside the binary data (cut short?)");
    }
    unsigned char b[8];
    std::memcpy(b, p_, n);
    p_ += n;
    if (big_) std::reverse(b, b + n);
    switch (t) {
      case PlyType::i8: { std::int8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::u8: return b[0];
      case PlyType::i16: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::u16: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::i32: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::u32: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::f32: { float v; std::memcpy(&v, b, 4); return v; }
      case PlyType::f64: { double v; std::memcpy(&v, b, 8); return v; }
      case PlyType::none: break;
    }
    return 0;
  }
  std::size_t left() const { return static_cast<std::size_t>(end_ - p_); }

 private:
  const char* p_;
  const char* end_;
  bool big_;
  std::string where_;
};

Raw read_ply(const std::string& text, const std::string& where) {
  Text t(text, where);
  Raw raw;
  if (t.rest_of_line() != "ply") t.fail_at(1, "not a PLY file (the first line must be 'ply')");
  enum class Format { none, ascii, little, big } format = Format::none;
  std::vector<PlyElement> elements;
  bool header_done = false;
  while (!t.at_end()) {
    const std::size_t line = t.line();
    if (line > 10000) break;  // a header is a few dozen lines: no end_header near the start
    std::istringstream ls{std::string(t.rest_of_line())};
    std::string word;
    ls >> word;
    auto fail = [&](const std::string& reason) { t.fail_at(line, reason); };
    if (word.empty() || word == "comment" || word == "obj_info") continue;
    if (word == "format") {
      std::string kind, version;
      ls >> kind >> version;
      if (kind == "ascii") format = Format::ascii;
      else if (kind == "binary_little_endian") format = Format::little;
      else if (kind == "binary_big_endian") format = Format::big;
      else fail("unknown PLY format " + shown(kind));
      if (version != "1.0") fail("PLY version " + shown(version) + " is not 1.0");
    } else if (word == "element") {
      PlyElement e;
      std::string count;
      if (!(ls >> e.name >> count)) fail("an element needs a name and a count");
      Text ct(count, where);
      try {
        e.count = integer(ct, count, "the element count");
      } catch (const InputError&) {
        fail("element " + shown(e.name) + ": the count " + shown(count) + " is not a whole number");
      }
      if (e.count < 0) fail("element " + shown(e.name) + ": negative count " + count);
      e.line = line;
      elements.push_back(std::move(e));
    } else if (word == "property") {
      if (elements.empty()) fail("a property before any element");
      PlyProperty p;
      std::string type;
      ls >> type;
      if (type == "list") {
        std::string ct, it;
        ls >> ct >> it >> p.name;
        p.list = true;
        p.count_type = ply_type(ct);
        p.type = ply_type(it);
        if (!ply_integer(p.count_type) || p.type == PlyType::none || p.name.empty()) {
          fail("property list " + shown(ct + " " + it) + ": not PLY types (an integer count, then any type) and a name");
        }
      } else {
        p.type = ply_type(type);
        ls >> p.name;
        if (p.type == PlyType::none) fail("property type " + shown(type) + " is not a PLY type");
        if (p.name.empty()) fail("a property needs a name");
      }
      elements.back().properties.push_back(p);
    } else if (word == "end_header") {
      header_done = true;
      break;
    }  // any other line is free text, as assimp and Blender's exporter ("Created by ...") take it
  }
  if (!header_done) t.fail("no end_header: the PLY header is incomplete");
  if (format == Format::none) t.fail("the PLY header has no format line");
  // Minimal size of the body (binary: every scalar and list count; ASCII: 2 bytes per value)
  // against what follows the header: counts the file cannot hold are refused first.
  long double minimal = 0;
  for (const PlyElement& e : elements) {
    long double per = 0;
    for (const PlyProperty& p : e.properties) {
      per += format == Format::ascii ? 2.0L : static_cast<long double>(ply_size(p.list ? p.count_type : p.type));
    }
    minimal += per * static_cast<long double>(e.count);
  }
  const long double body = static_cast<long double>(t.end() - t.pos());
  if (minimal > body) {
    t.fail("the PLY header declares elements needing at least " + count_text(minimal) + " bytes, but " +
           count_text(body) + " follow the header");
  }

  // Which properties matter.
  const PlyElement* vertex_el = nullptr;
  const PlyElement* face_el = nullptr;
  int xyz[3] = {-1, -1, -1};
  int face_list = -1;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex" && !vertex_el) {
      vertex_el = &e;
      for (std::size_t i = 0; i < e.properties.size(); ++i)
        for (int k = 0; k < 3; ++k)
          if (!e.properties[i].list && e.properties[i].name == std::string(1, "xyz"[k])) xyz[k] = static_cast<int>(i);
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) t.fail_at(e.line, "the vertex element has no x, y and z properties");
      if (e.count > std::numeric_limits<int>::max()) t.fail_at(e.line, "too many vertices");
    }
    if (e.name == "face" && !face_el) {
      face_el = &e;
      for (std::size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].list && (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
          face_list = static_cast<int>(i);
      if (face_list < 0) t.fail_at(e.line, "the face element has no vertex_indices list");
    }
  }
  if (!vertex_el) t.fail("no vertex element");
  if (!face_el) t.fail("no face element: the file contains no faces");
  raw.vertices.reserve(static_cast<std::size_t>(vertex_el->count));
  raw.file_vertices = static_cast<std::size_t>(vertex_el->count);
  const long long nv = vertex_el->count;

  std::vector<int> face;
  auto add_index = [&](double v, auto&& fail) {
    if (v != std::floor(v) || v < 0 || v >= static_cast<double>(nv)) {
      std::ostringstream m;
      m << "vertex index " << v << " out of range (" << nv << " vertices)";
      fail(m.str());
    }
    face.push_back(static_cast<int>(v));
  };
  auto finish_face = [&](auto&& fail) {
    if (face.empty()) fail("a face without vertices");
    raw.add_face(face.data(), face.size());
  };

  if (format == Format::ascii) {
    for (const PlyElement& e : elements) {
      for (long long i = 0; i < e.count; ++i) {
        t.skip(true, 0);
        if (t.at_end()) t.fail("unexpected end of file in element " + shown(e.name) + " " + std::to_string(i));
        auto fail = [&](const std::string& r) { t.fail("element " + e.name + " " + std::to_string(i) + ": " + r); };
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        face.clear();
        for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
          const PlyProperty& p = e.properties[pi];
          if (p.list) {
            const long long n = integer(t, t.token(0), "a list count");
            if (n < 0 || n > 1000000) fail("list count " + std::to_string(n) + " out of range");
            for (long long k = 0; k < n; ++k) {
              const double v = number(t, t.token(0), "a list value");
              if (&e == face_el && static_cast<int>(pi) == face_list) add_index(v, fail);
            }
          } else {
            const double v = number(t, t.token(0), "a property value");
            if (&e == vertex_el)
              for (int k = 0; k < 3; ++k)
                if (xyz[k] == static_cast<int>(pi)) x[k] = v;
          }
        }
        if (!t.at_line_end(0)) fail("unexpected " + shown(t.token(0)) + " after the element's values");
        t.rest_of_line();
        if (&e == vertex_el) raw.vertices.push_back(x);
        if (&e == face_el) finish_face(fail);
      }
    }
    t.skip(true, 0);
    if (!t.at_end()) t.fail("unexpected " + shown(t.token(0)) + " after the last element");
  } else {
    Bytes b(t.pos(), t.end(), format == Format::big, where);
    for (const PlyElement& e : elements) {
      for (long long i = 0; i < e.count; ++i) {
        const std::string place = "element " + e.name + " " + std::to_string(i);
        auto fail = [&](const std::string& r) -> void { throw InputError(where, place, r); };
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        face.clear();
        for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
          const PlyProperty& p = e.properties[pi];
          if (p.list) {
            const double n = b.read(p.count_type, place);
            if (n < 0 || n > 1000000 || n * static_cast<double>(ply_size(p.type)) > static_cast<double>(b.left())) {
              fail("list count " + count_text(n) + " out of range or beyond the end of the file");
            }
            for (long long k = 0; k < static_cast<long long>(n); ++k) {
              const double v = b.read(p.type, place);
              if (&e == face_el && static_cast<int>(pi) == face_list) add_index(v, fail);
            }
          } else {
            const double v = b.read(p.type, place);
            if (&e == vertex_el)
              for (int k = 0; k < 3; ++k)
                if (xyz[k] == static_cast<int>(pi)) {
                  if (!std::isfinite(v)) fail("vertex coordinate is not a finite number");
                  x[k] = v;
                }
          }
        }
        if (&e == vertex_el) raw.vertices.push_back(x);
        if (&e == face_el) finish_face(fail);
      }
    }
    if (b.left() != 0) {
      throw InputError(where, "end of file", std::to_string(b.left()) + " bytes follow the last element");
    }
  }
  return raw;
}

// ---------------------------------------------------------------------------------------------
// Triangulation of one polygon (k >= 4 corners): a fan when it is convex in its plane (Newell
// normal), ear clipping otherwise. Triangles keep the polygon's orientation.
void triangulate(const std::vector<Eigen::Vector3d>& v, const int* c, std::size_t k,
                 std::vector<std::array<int, 3>>& out, const std::string& where, std::size_t face) {
  const Eigen::Vector3d o = v[c[0]];
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < k; ++i) n += (v[c[i]] - o).cross(v[c[(i + 1) % k]] - o);
  int ax = 0;
  n.cwiseAbs().maxCoeff(&ax);
  const int ua = (ax + 1) % 3, wa = (ax + 2) % 3;
  const double sign = n[ax] >= 0 ? 1.0 : -1.0;
  std::vector<Eigen::Vector2d> p(k);
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::Vector3d d = v[c[i]] - o;
    p[i] = Eigen::Vector2d(d[ua], sign * d[wa]);  // counter-clockwise in this frame
  }
  auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q) {
    return (b - a).x() * (q - a).y() - (b - a).y() * (q - a).x();
  };
  bool convex = n.squaredNorm() > 0;
  for (std::size_t i = 0; i < k && convex; ++i) convex = cross(p[i], p[(i + 1) % k], p[(i + 2) % k]) >= 0;
  if (convex) {
    for (std::size_t i = 1; i + 1 < k; ++i) out.push_back({c[0], c[i], c[i + 1]});
    return;
  }
  if (k > kMaxConcaveCorners) {
    throw InputError(where, "face " + std::to_string(face),
                     "a polygon of " + std::to_string(k) + " corners that is not convex: at most " +
                         std::to_string(kMaxConcaveCorners) + " corners are triangulated by ear clipping");
  }
  std::vector<std::size_t> ring(k);
  for (std::size_t i = 0; i < k; ++i) ring[i] = i;
  while (ring.size() > 3) {
    bool clipped = false;
    const std::size_t m = ring.size();
    for (std::size_t j = 0; j < m && !clipped; ++j) {
      const std::size_t a = ring[(j + m - 1) % m], b = ring[j], d = ring[(j + 1) % m];
      if (cross(p[a], p[b], p[d]) <= 0) continue;  // reflex or flat corner: no ear
      bool empty = true;
      for (std::size_t q = 0; q < m && empty; ++q) {
        const std::size_t r = ring[q];
        if (r == a || r == b || r == d) continue;
        empty = !(cross(p[a], p[b], p[r]) >= 0 && cross(p[b], p[d], p[r]) >= 0 && cross(p[d], p[a], p[r]) >= 0);
      }
      if (!empty) continue;
      out.push_back({c[a], c[b], c[d]});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(j));
      clipped = true;
    }
    if (!clipped) break;  // self-intersecting or degenerate: the rest as a fan (validation reports it)
  }
  for (std::size_t i = 1; i + 1 < ring.size(); ++i) out.push_back({c[ring[0]], c[ring[i]], c[ring[i + 1]]});
}

// Raw soup -> LoadedMesh: metres, triangles, exact-position merge with ids in order of first use.
LoadedMesh build(Raw& raw, const std::string& format, LengthUnit unit, const std::string& where, std::size_t points,
                 std::size_t lines) {
  LoadedMesh out;
  out.format = format;
  out.file_vertices = raw.file_vertices;
  out.points_ignored = points;
  out.lines_ignored = lines;
  std::vector<std::array<int, 3>> tris;
  tris.reserve(raw.corners.size());
  for (std::size_t f = 0; f < raw.faces(); ++f) {
    const std::size_t b = raw.face_start[f], k = raw.face_start[f + 1] - b;
    const int* c = raw.corners.data() + b;
    if (k == 1) ++out.points_ignored;
    else if (k == 2) ++out.lines_ignored;
    else if (k == 3) tris.push_back({c[0], c[1], c[2]});
    else {
      ++out.polygons_triangulated;
      triangulate(raw.vertices, c, k, tris, where, f);
    }
  }
  const double to_m = metres_per(unit);
  for (auto& x : raw.vertices) {
    x *= to_m;
    for (int i = 0; i < 3; ++i) x[i] += 0.0;  // -0 -> +0: one position, one vertex
  }
  // Merge: raw vertices sorted by position, equal runs share one id; ids in order of first use by
  // a triangle corner (unused vertices are dropped).
  std::vector<int> order;
  std::vector<char> used(raw.vertices.size(), 0);
  for (const auto& t : tris)
    for (int c : t) used[static_cast<std::size_t>(c)] = 1;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i]) order.push_back(static_cast<int>(i));
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const Eigen::Vector3d &x = raw.vertices[a], &y = raw.vertices[b];
    if (x.x() != y.x()) return x.x() < y.x();
    if (x.y() != y.y()) return x.y() < y.y();
    if (x.z() != y.z()) return x.z() < y.z();
    return a < b;
  });
  std::vector<int> group(raw.vertices.size(), -1);
  int groups = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (i > 0 && raw.vertices[order[i]] == raw.vertices[order[i - 1]]) {
      group[order[i]] = group[order[i - 1]];
      ++out.merged_vertices;
    } else {
      group[order[i]] = groups++;
    }
  }
  std::vector<int> id(static_cast<std::size_t>(groups), -1);
  out.mesh.vertices_m.reserve(static_cast<std::size_t>(groups));
  out.mesh.triangles.reserve(tris.size());
  for (const auto& t : tris) {
    std::array<int, 3> m{};
    for (int k = 0; k < 3; ++k) {
      int& g = id[static_cast<std::size_t>(group[t[k]])];
      if (g < 0) {
        g = static_cast<int>(out.mesh.vertices_m.size());
        out.mesh.vertices_m.push_back(raw.vertices[t[k]]);
      }
      m[k] = g;
    }
    out.mesh.triangles.push_back(m);
  }
  return out;
}

}  // namespace

// An ASCII STL starts with "solid" and does not have the binary size 84 + 50 n (a binary STL's
// 80-byte header may start with "solid" too; assimp and every reader use the same test).
bool is_ascii_stl(const std::string& head, std::uintmax_t bytes) {
  std::size_t i = head.find_first_not_of(" \t\r\n");
  if (i == std::string::npos || head.compare(i, 5, "solid") != 0) return false;
  if (bytes >= 84 && head.size() >= 84) {
    std::uint32_t n;
    std::memcpy(&n, head.data() + 80, 4);
    if (84 + 50 * static_cast<std::uintmax_t>(n) == bytes) return false;
  }
  return true;
}

std::optional<LoadedMesh> read_own_format(const fs::path& file, const std::string& ext, LengthUnit unit,
                                          std::uintmax_t bytes) {
  std::string text = read_input_file(file, "part file", bytes);
  if (ext == ".stl" && !is_ascii_stl(text.substr(0, 84), text.size())) return std::nullopt;
  return read_own_text(std::move(text), file, ext, unit);
}

std::optional<LoadedMesh> read_own_text(std::string text, const fs::path& file, const std::string& ext,
                                        LengthUnit unit) {
  const std::string where = file.string();
  std::size_t points = 0, lines = 0;
  Raw raw;
  if (ext == ".off") raw = read_off(text, where);
  else if (ext == ".obj") raw = read_obj(text, where, points, lines);
  else if (ext == ".ply") raw = read_ply(text, where);
  else if (ext == ".stl") raw = read_ascii_stl(text, where);
  else return std::nullopt;
  std::string().swap(text);  // the file's bytes are no longer needed
  LoadedMesh out = build(raw, ext.substr(1), unit, where, points, lines);
  finish_loaded(out, where);
  return out;
}

void finish_loaded(LoadedMesh& out, const std::string& where) {
  if (out.lines_ignored + out.points_ignored > 0) {
    out.warnings.push_back(where + ": ignored " + std::to_string(out.lines_ignored) + " line(s) and " +
                           std::to_string(out.points_ignored) +
                           " point(s): only triangles and polygons describe a surface");
  }
  if (out.mesh.triangles.empty()) {
    std::string detail;
    if (out.lines_ignored + out.points_ignored > 0) {
      detail = " (only " + std::to_string(out.points_ignored) + " point(s) and " + std::to_string(out.lines_ignored) +
               " line(s))";
    }
    throw InputError(where, "faces", "the file contains no triangles" + detail);
  }
}

std::uintmax_t check_part_file(const fs::path& file) {
  const std::uintmax_t bytes = check_input_file(file, "part file", std::numeric_limits<std::uintmax_t>::max());
  // Reading needs the file's bytes plus the soup (vertices at 24 bytes, corners at 4): at most
  // about 3 times the file for text, 4 times for binary PLY; then kBytesPerTriangle per triangle
  // (check_part_extent). The first part is checked before reading.
  const double need = 4.0 * static_cast<double>(bytes);
  const double avail = static_cast<double>(available_memory_bytes());
  if (need > avail) {
    throw InputError(file.string(), "file",
                     "reading this " + format_bytes(static_cast<double>(bytes)) + " part needs about " +
                         format_bytes(need) + " of memory (4 bytes per byte of the file), more than the " +
                         format_bytes(avail) + " available");
  }
  return bytes;
}

void check_part_extent(const LoadedMesh& m, const std::string& where) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (const auto& x : m.mesh.vertices_m) {
    if (!x.allFinite() || x.cwiseAbs().maxCoeff() > kMaxCoordinateM) {
      std::ostringstream s;
      s << "a vertex at (" << x.x() << ", " << x.y() << ", " << x.z() << ") m lies more than " << kMaxCoordinateM
        << " m from the origin (check the length unit)";
      throw InputError(where, "vertices", s.str());
    }
    for (int i = 0; i < 3; ++i) {
      // 0 or at least 1e-100 m (numeric.hpp): a coordinate like 1e-300 m makes vertices 1e-300 m
      // apart, whose cross products underflow to 0 and whose normals become NaN.
      if (x[i] != 0.0 && !within_magnitude_range(x[i])) {
        std::ostringstream s;
        s << "a vertex at (" << x.x() << ", " << x.y() << ", " << x.z() << ") m has a coordinate below 1e-100 m "
          << "in magnitude (it would underflow in the geometry): write it as 0";
        throw InputError(where, "vertices", s.str());
      }
    }
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double size = m.mesh.vertices_m.empty() ? 0.0 : (hi - lo).norm();
  if (!(size >= kMinSizeM && size <= kMaxSizeM)) {
    std::ostringstream s;
    s << "the part is " << size << " m across; impactdeck reads parts from " << kMinSizeM << " m to " << kMaxSizeM
      << " m across (their volume integrals, up to size^5, must stay within 1e-100 to 1e100; check the length unit)";
    throw InputError(where, "size", s.str());
  }
  const double need = kBytesPerTriangle * static_cast<double>(m.mesh.triangles.size());
  const double avail = static_cast<double>(available_memory_bytes());
  if (need > avail) {
    throw InputError(where, "faces",
                     std::to_string(m.mesh.triangles.size()) + " triangles need about " + format_bytes(need) +
                         " of memory for validation, mass properties and the surface index (about 700 bytes per "
                         "triangle, measured), more than the " + format_bytes(avail) + " available");
  }
}

}  // namespace impactdeck::geometry::detail
