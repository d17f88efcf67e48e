// Files of sweeps, of the Table 1 study and of `run`'s force plot, parsed back: XML well-formed
// (tinyxml2), element and value counts, numbers finite, PNGs decodable by cairo with the expected
// size and content.
#include <cmath>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <cairo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyxml2.h>
#include <zlib.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/plot/force_plot.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/study/sweep_output.hpp"
#include "impactdeck/study/table1.hpp"
#include "impactdeck/study/table1_output.hpp"

namespace impactdeck::study {
namespace {
namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("impactdeck_study_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Parses an XML file; fails the test if it is not well-formed.
struct Xml {
  tinyxml2::XMLDocument doc;
  explicit Xml(const fs::path& p) {
    const tinyxml2::XMLError e = doc.LoadFile(p.string().c_str());
    EXPECT_EQ(e, tinyxml2::XML_SUCCESS) << p << ": " << doc.ErrorStr();
  }
};

// Elements named `name` anywhere below `e`.
void collect(const tinyxml2::XMLElement* e, const char* name, std::vector<const tinyxml2::XMLElement*>& out) {
  for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    if (std::string(c->Name()) == name) out.push_back(c);
    collect(c, name, out);
  }
}
std::vector<const tinyxml2::XMLElement*> all(const tinyxml2::XMLElement* root, const char* name) {
  std::vector<const tinyxml2::XMLElement*> v;
  collect(root, name, v);
  return v;
}

// Every number in an attribute list is finite and parses completely.
void expect_finite_attributes(const tinyxml2::XMLElement* e, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    const char* v = e->Attribute(n);
    ASSERT_NE(v, nullptr) << n;
    char* end = nullptr;
    const double x = std::strtod(v, &end);
    EXPECT_TRUE(std::isfinite(x) && *end == '\0') << n << "=\"" << v << "\"";
  }
}

std::vector<double> numbers(const char* text) {
  std::vector<double> v;
  std::istringstream s(text ? text : "");
  std::string tok;
  while (s >> tok) {
    char* end = nullptr;
    const double x = std::strtod(tok.c_str(), &end);
    EXPECT_TRUE(*end == '\0' && std::isfinite(x)) << tok;
    v.push_back(x);
  }
  return v;
}

struct Png {
  int width = 0, height = 0;
  double non_white_fraction = 0;
  double dark_fraction = 0;  // luminance < 0.25
};

Png read_png(const fs::path& p) {
  Png out;
  cairo_surface_t* s = cairo_image_surface_create_from_png(p.string().c_str());
  EXPECT_EQ(cairo_surface_status(s), CAIRO_STATUS_SUCCESS) << p;
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(s);
    out.width = cairo_image_surface_get_width(s);
    out.height = cairo_image_surface_get_height(s);
    const int stride = cairo_image_surface_get_stride(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    std::size_t non_white = 0, dark = 0;
    for (int y = 0; y < out.height; ++y) {
      const auto* row = reinterpret_cast<const std::uint32_t*>(data + y * stride);
      for (int x = 0; x < out.width; ++x) {
        const std::uint32_t px = row[x];
        const double r = ((px >> 16) & 0xff) / 255.0, g = ((px >> 8) & 0xff) / 255.0, b = (px & 0xff) / 255.0;
        if (r + g + b < 2.95) ++non_white;
        if (0.2126 * r + 0.7152 * g + 0.0722 * b < 0.25) ++dark;
      }
    }
    const double n = static_cast<double>(out.width) * out.height;
    out.non_white_fraction = non_white / n;
    out.dark_fraction = dark / n;
  }
  cairo_surface_destroy(s);
  return out;
}

struct SweepFiles : ::testing::Test {
  static void SetUpTestSuite() {
    dir = new fs::path(temp_dir("sweep"));
    sc = new scene::Scene(scene::load_scene(std::string(IMPACTDECK_SOURCE_DIR) + "/samples/fig4_sweep.toml"));
    ss = new SweepCase(scene::sweep_case(*sc));
    const auto cloud = make_cloud(*ss->setup.target.shape, CloudKind::both, 8, 300, 1);
    SweepOptions o;
    o.curves = true;
    o.curve_samples = 21;
    result = new SweepResult(run_sweep(ss->setup, cloud, o));
    SweepMeta meta{"fig4_sweep.toml", "fig4", "ellipsoid", "ball", "both -- test"};
    write_sweep_csv(*dir / "s.csv", *result, meta);
    write_sweep_curves_csv(*dir / "s_curves.csv", *result, meta);
    write_sweep_pos(*dir / "s.pos", *result, meta);
    write_sweep_vtp(*dir / "s.vtp", *result, meta);
    const plot::Drawing d = force_map_drawing(*ss->setup.target.shape, ss->setup.target.volume.centroid_m, *result);
    plot::write_svg(*dir / "s.svg", d);
    plot::write_png(*dir / "s.png", d, 1.0);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir);
    delete result;
    delete ss;
    delete sc;
    delete dir;
  }
  static inline fs::path* dir = nullptr;
  static inline scene::Scene* sc = nullptr;
  static inline SweepCase* ss = nullptr;
  static inline SweepResult* result = nullptr;
};

TEST_F(SweepFiles, CsvHasOneRowPerPoint) {
  std::istringstream s(slurp(*dir / "s.csv"));
  std::string line;
  std::size_t rows = 0, header_cols = 0;
  bool header = false;
  while (std::getline(s, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t cols = std::count(line.begin(), line.end(), ',') + 1;
    if (!header) {
      header = true;
      header_cols = cols;
      EXPECT_NE(line.find("max_force_N"), std::string::npos);
      continue;
    }
    EXPECT_EQ(cols, header_cols) << line;
    EXPECT_EQ(line.find("nan"), std::string::npos);
    EXPECT_EQ(line.find("inf"), std::string::npos);
    ++rows;
  }
  EXPECT_EQ(header_cols, 29u);  // ... residual_indentation_m, target_dv..., contact_ellipse_axis_ratio, sharp_feature, flag
  EXPECT_EQ(rows, result->points.size());
  EXPECT_EQ(result->points.size(), 690u);  // 390 grid + 300 uniform

  const std::string curves = slurp(*dir / "s_curves.csv");
  EXPECT_EQ(static_cast<std::size_t>(std::count(curves.begin(), curves.end(), '\n')),
            result->points.size() * 21 + 1 + static_cast<std::size_t>(std::count(curves.begin(), curves.end(), '#')));
}

TEST_F(SweepFiles, GmshPosViews) {
  const std::string pos = slurp(*dir / "s.pos");
  const std::regex sp(R"(SP\(([^,]+),([^,]+),([^)]+)\)\{([^}]+)\};)");
  std::size_t count = 0;
  for (auto it = std::sregex_iterator(pos.begin(), pos.end(), sp); it != std::sregex_iterator(); ++it) {
    for (int k = 1; k <= 4; ++k) {
      char* end = nullptr;
      const std::string v = (*it)[k].str();
      const double x = std::strtod(v.c_str(), &end);
      EXPECT_TRUE(std::isfinite(x) && *end == '\0') << v;
    }
    ++count;
  }
  EXPECT_EQ(count, 5 * result->points.size());  // no sharp point on an ellipsoid: no sixth view
  const std::regex view(
      R"re(View "(max_force_N|force_ratio|restitution|residual_indentation_m|contact_ellipse_axis_ratio)" \{)re");
  EXPECT_EQ(std::distance(std::sregex_iterator(pos.begin(), pos.end(), view), std::sregex_iterator()), 5);
  EXPECT_EQ(std::count(pos.begin(), pos.end(), '{'), std::count(pos.begin(), pos.end(), '}'));
}

// A binary VTK file (.vtp, .vtu) split into its XML part (well-formed once the appended block is
// cut out) and its arrays decoded from the appended raw data, by their offsets and the header_type's
// block sizes: raw (a byte count, then the values) or, with compressor="vtkZLibDataCompressor",
// VTK's compressed layout (blocks, block size, last block size, each block's size, then the
// blocks, each inflated by zlib).
struct Vtp {
  tinyxml2::XMLDocument doc;
  std::map<std::string, std::vector<double>> arrays;  // every type's values as doubles
  std::map<std::string, double> field_data;            // <FieldData> (ASCII, one value each)
  std::string header_type;
  bool compressed = false;
};
void read_vtp(const fs::path& p, Vtp& v) {
  const std::string text = slurp(p);
  const std::string tag = "<AppendedData encoding=\"raw\">";
  const std::size_t at = text.find(tag);
  ASSERT_NE(at, std::string::npos);
  const std::size_t underscore = text.find('_', at + tag.size());
  ASSERT_NE(underscore, std::string::npos);
  ASSERT_EQ(text.compare(at + tag.size(), underscore - at - tag.size(), "\n"), 0);  // only a newline before '_'
  const std::string xml = text.substr(0, at) + "</VTKFile>\n";
  ASSERT_EQ(v.doc.Parse(xml.c_str()), tinyxml2::XML_SUCCESS) << v.doc.ErrorStr();
  const auto* root = v.doc.RootElement();
  ASSERT_STREQ(root->Attribute("byte_order"), "LittleEndian");
  v.header_type = root->Attribute("header_type");
  ASSERT_TRUE(v.header_type == "UInt32" || v.header_type == "UInt64") << v.header_type;
  v.compressed = root->Attribute("compressor") != nullptr;
  if (v.compressed) {
    ASSERT_STREQ(root->Attribute("compressor"), "vtkZLibDataCompressor");
    ASSERT_EQ(v.header_type, "UInt64");
  }
  const std::size_t size_bytes = v.header_type == "UInt64" ? 8 : 4;
  const char* data = text.data() + underscore + 1;
  const std::size_t data_size = text.size() - underscore - 1;
  auto word = [&](std::size_t at) {
    std::uint64_t x = 0;
    std::memcpy(&x, data + at, size_bytes);
    return x;
  };
  std::size_t expected_offset = 0;
  for (const auto* a : all(root, "DataArray")) {
    if (std::string(a->Parent()->ToElement()->Name()) == "FieldData") {
      ASSERT_STREQ(a->Attribute("format"), "ascii");
      v.field_data[a->Attribute("Name")] = std::stod(a->GetText());
      continue;
    }
    ASSERT_STREQ(a->Attribute("format"), "appended");
    const std::size_t offset = std::stoull(a->Attribute("offset"));
    EXPECT_EQ(offset, expected_offset) << a->Attribute("Name");  // blocks follow each other
    std::string values;
    if (!v.compressed) {
      const std::uint64_t bytes = word(offset);
      ASSERT_LE(offset + size_bytes + bytes, data_size);
      values.assign(data + offset + size_bytes, bytes);
      expected_offset = offset + size_bytes + bytes;
    } else {
      const std::uint64_t blocks = word(offset), block = word(offset + 8), last = word(offset + 16);
      std::size_t at_block = offset + 8 * (3 + blocks);
      for (std::uint64_t b = 0; b < blocks; ++b) {
        const std::uint64_t packed = word(offset + 8 * (3 + b));
        ASSERT_LE(at_block + packed, data_size);
        uLongf size = static_cast<uLongf>(b + 1 == blocks ? last : block);
        std::string out(size, '\0');
        ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(out.data()), &size,
                             reinterpret_cast<const Bytef*>(data + at_block), static_cast<uLong>(packed)), Z_OK);
        ASSERT_EQ(size, b + 1 == blocks ? last : block);
        values += out;
        at_block += packed;
      }
      expected_offset = at_block;
    }
    const std::string type = a->Attribute("type");
    std::vector<double>& out = v.arrays[a->Attribute("Name")];
    auto decode = [&](auto x) {
      ASSERT_EQ(values.size() % sizeof(x), 0u);
      for (std::size_t k = 0; k < values.size(); k += sizeof(x)) {
        std::memcpy(&x, values.data() + k, sizeof(x));
        out.push_back(static_cast<double>(x));
      }
    };
    if (type == "Float64") decode(0.0);
    else if (type == "Int64") decode(std::int64_t{0});
    else if (type == "Int32") decode(std::int32_t{0});
    else if (type == "UInt8") decode(std::uint8_t{0});
    else FAIL() << "type " << type;
  }
  // After the last block: the closing tags only.
  EXPECT_EQ(text.substr(underscore + 1 + expected_offset), "\n</AppendedData>\n</VTKFile>\n");
}

TEST_F(SweepFiles, VtpIsBinaryPolyDataWithTheResultsArrays) {
  // Compressed (the default), and raw with UInt32 and UInt64 block sizes; as PolyData and as an
  // UnstructuredGrid of vertex cells.
  struct Case {
    bool compress, wide, grid;
  };
  for (const Case c : {Case{true, false, false}, Case{false, false, false}, Case{false, true, false}, Case{true, false, true},
                       Case{false, false, true}}) {
    SCOPED_TRACE(std::string(c.grid ? "vtu, " : "vtp, ") +
                 (c.compress ? "compressed" : c.wide ? "UInt64 block sizes" : "UInt32 block sizes"));
    SweepWriteOptions o;
    o.vtk_compress = c.compress;
    o.vtp_uint64_headers = c.wide;
    const fs::path f = *dir / (c.grid ? "w.vtu" : "w.vtp");
    if (c.grid) write_sweep_vtu(f, *result, {}, o);
    else write_sweep_vtp(f, *result, {}, o);
    Vtp v;
    read_vtp(f, v);
    EXPECT_EQ(v.header_type, c.wide || c.compress ? "UInt64" : "UInt32");
    EXPECT_EQ(v.compressed, c.compress);
    const auto* root = v.doc.RootElement();
    EXPECT_STREQ(root->Name(), "VTKFile");
    EXPECT_STREQ(root->Attribute("type"), c.grid ? "UnstructuredGrid" : "PolyData");
    const auto pieces = all(root, "Piece");
    ASSERT_EQ(pieces.size(), 1u);
    const std::size_t n = result->points.size();
    EXPECT_EQ(pieces[0]->UnsignedAttribute("NumberOfPoints"), n);
    EXPECT_EQ(pieces[0]->UnsignedAttribute(c.grid ? "NumberOfCells" : "NumberOfVerts"), n);
    // 10 scalars (flag included) + normals + points + connectivity + offsets (+ cell types)
    EXPECT_EQ(v.arrays.size(), c.grid ? 15u : 14u);
    const double fmax = result->points[result->max_index].max_force_N;
    for (std::size_t i = 0; i < n; ++i) {
      const PointResult& p = result->points[i];
      // The same doubles as the result (bitwise: == on finite values, and no -0 written).
      ASSERT_EQ(v.arrays["max_force_N"].at(i), p.max_force_N);
      ASSERT_EQ(v.arrays["force_ratio"].at(i), p.max_force_N / fmax);
      ASSERT_EQ(v.arrays["restitution"].at(i), p.restitution);
      ASSERT_EQ(v.arrays["residual_indentation_m"].at(i), p.residual_indentation_m);
      ASSERT_EQ(v.arrays["reduced_mass_kg"].at(i), p.reduced_mass_kg);
      ASSERT_EQ(v.arrays["effective_radius_m"].at(i), p.effective_radius_m);
      ASSERT_EQ(v.arrays["target_radius_m"].at(i), p.target_radius_m);
      ASSERT_EQ(v.arrays["contact_ellipse_axis_ratio"].at(i), p.contact_ellipse_axis_ratio);
      ASSERT_EQ(v.arrays["sharp_feature"].at(i), 0.0);
      ASSERT_EQ(v.arrays["flag"].at(i), static_cast<double>(p.flag));
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(v.arrays["normal"].at(3 * i + k), p.normal[k]);
        ASSERT_EQ(v.arrays["Points"].at(3 * i + k), p.point_m[k]);
      }
      ASSERT_EQ(v.arrays["connectivity"].at(i), static_cast<double>(i));
      ASSERT_EQ(v.arrays["offsets"].at(i), static_cast<double>(i + 1));
      if (c.grid) ASSERT_EQ(v.arrays["types"].at(i), 1.0);  // VTK_VERTEX
    }
  }
}

// A compressed file of many blocks (a 200 000-point result: 5 blocks per Float64 array) decodes to
// the same values on 1 and 3 threads, byte for byte the same file, and is smaller than the raw one.
TEST_F(SweepFiles, CompressedVtkOfManyBlocks) {
  SweepResult big = *result;
  big.points.resize(200000);
  for (std::size_t i = result->points.size(); i < big.points.size(); ++i) {
    big.points[i] = result->points[i % result->points.size()];
    big.points[i].point_m *= 1.0 + 1e-7 * static_cast<double>(i);
  }
  std::string first;
  for (unsigned threads : {1u, 3u}) {
    SweepWriteOptions o;
    o.threads = threads;
    const fs::path f = *dir / ("big" + std::to_string(threads) + ".vtu");
    write_sweep_vtu(f, big, {}, o);
    if (first.empty()) first = slurp(f);
    else EXPECT_TRUE(slurp(f) == first);
  }
  Vtp v;
  read_vtp(*dir / "big1.vtu", v);
  ASSERT_EQ(v.arrays["Points"].size(), 3 * big.points.size());
  for (std::size_t i = 0; i < big.points.size(); ++i) {
    ASSERT_EQ(v.arrays["max_force_N"][i], big.points[i].max_force_N);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(v.arrays["Points"][3 * i + k], big.points[i].point_m[k]);
  }
  SweepWriteOptions raw;
  raw.vtk_compress = false;
  write_sweep_vtu(*dir / "big_raw.vtu", big, {}, raw);
  EXPECT_LT(fs::file_size(*dir / "big1.vtu"), fs::file_size(*dir / "big_raw.vtu"));
}

// The coordinates in the output length unit (issue 18): the .vtp's points, the CSV's columns and
// the .pos's SP(x,y,z) are point_m * (1 / metres_per(unit)) like the decks' (1000 exactly for mm),
// and each file says which unit.
TEST_F(SweepFiles, CoordinatesInTheOutputLengthUnit) {
  SweepWriteOptions o;
  o.length_unit = LengthUnit::mm;
  write_sweep_vtp(*dir / "mm.vtp", *result, {}, o);
  write_sweep_csv(*dir / "mm.csv", *result, {}, o);
  write_sweep_pos(*dir / "mm.pos", *result, {}, o);
  Vtp v;
  read_vtp(*dir / "mm.vtp", v);
  EXPECT_EQ(v.field_data.at("metres_per_length_unit"), 1e-3);
  const std::size_t n = result->points.size();
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(v.arrays["Points"].at(3 * i + k), result->points[i].point_m[k] * 1000.0);
  // The CSV is plain (header + rows); its JSON sidecar names the unit of every column.
  const std::string csv = slurp(*dir / "mm.csv");
  EXPECT_EQ(csv.rfind("index,x_mm,y_mm,z_mm,nx,", 0), 0u);
  const nlohmann::json side = nlohmann::json::parse(slurp(*dir / "mm.csv.json"));
  EXPECT_EQ(side.at("columns").at(1).at("name"), "x_mm");
  EXPECT_EQ(side.at("columns").at(1).at("unit"), "mm");
  EXPECT_NE(side.dump().find("in mm"), std::string::npos);
  const std::string pos = slurp(*dir / "mm.pos");
  EXPECT_NE(pos.find("coordinates in mm"), std::string::npos);
  const PointResult& p0 = result->points[0];
  ASSERT_NE(pos.find("SP("), std::string::npos);
  double x = 0;
  ASSERT_EQ(std::sscanf(pos.c_str() + pos.find("SP(") + 3, "%lf", &x), 1);
  EXPECT_EQ(x, p0.point_m.x() * 1000.0);
  // The library's default stays metres.
  write_sweep_vtp(*dir / "m.vtp", *result, {});
  Vtp m;
  read_vtp(*dir / "m.vtp", m);
  EXPECT_EQ(m.field_data.at("metres_per_length_unit"), 1.0);
}

// Every number of the CSV and the .pos reads back as the very double computed: the shortest
// round-trip text (std::to_chars) loses nothing.
TEST_F(SweepFiles, NumbersReadBackBitwise) {
  std::istringstream s(slurp(*dir / "s.csv"));
  std::string line;
  std::vector<std::string> names;
  std::size_t row = 0;
  const double fmax = result->points[result->max_index].max_force_N;
  while (std::getline(s, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
    if (!line.empty() && line.back() == ',') cells.emplace_back();  // an empty last cell (flag)
    if (names.empty()) {
      names = cells;
      continue;
    }
    ASSERT_EQ(cells.size(), names.size());
    // The last column is the flag word (empty: the model applies), the rest are numbers.
    ASSERT_EQ(names.back(), "flag");
    EXPECT_EQ(cells.back(), collision::flag_word(result->points.at(row).flag));
    cells.pop_back();
    const PointResult& p = result->points.at(row);
    const double expected[] = {static_cast<double>(row), p.point_m.x(), p.point_m.y(), p.point_m.z(), p.normal.x(),
                               p.normal.y(), p.normal.z(), p.target_radius_m, p.impactor_radius_m,
                               p.effective_radius_m, p.reduced_mass_kg, p.hertz_constant, p.max_indentation_m,
                               p.max_force_N, p.max_force_N / fmax, p.compression_time_s, p.restitution,
                               p.contact_time_s, p.impulse_total_Ns, p.residual_indentation_m,
                               p.target_delta_velocity_m_s.x(),
                               p.target_delta_velocity_m_s.y(), p.target_delta_velocity_m_s.z(),
                               p.target_delta_angular_velocity_rad_s.x(), p.target_delta_angular_velocity_rad_s.y(),
                               p.target_delta_angular_velocity_rad_s.z(), p.contact_ellipse_axis_ratio,
                               p.sharp_feature ? 1.0 : 0.0};
    ASSERT_EQ(cells.size(), std::size(expected));
    for (std::size_t k = 0; k < cells.size(); ++k) {
      char* end = nullptr;
      const double x = std::strtod(cells[k].c_str(), &end);
      ASSERT_EQ(*end, '\0') << cells[k];
      const double want = expected[k] + 0.0;  // the writers never write "-0"
      ASSERT_EQ(std::memcmp(&x, &want, sizeof x), 0) << names[k] << " row " << row << ": " << cells[k];
    }
    ++row;
  }
  EXPECT_EQ(row, result->points.size());

  // .pos: SP(x,y,z){v} of the first view are the points and their F_max.
  const std::string pos = slurp(*dir / "s.pos");
  const std::regex sp(R"(SP\(([^,]+),([^,]+),([^)]+)\)\{([^}]+)\};)");
  std::size_t i = 0;
  for (auto it = std::sregex_iterator(pos.begin(), pos.end(), sp); it != std::sregex_iterator() && i < result->points.size();
       ++it, ++i) {
    const PointResult& p = result->points[i];
    for (int k = 0; k < 3; ++k) ASSERT_EQ(std::stod((*it)[k + 1].str()), p.point_m[k]);
    ASSERT_EQ(std::stod((*it)[4].str()), p.max_force_N);
  }
  EXPECT_EQ(i, result->points.size());
}

// The text is the same on one thread as on several (chunks are written in order).
TEST_F(SweepFiles, FilesDoNotDependOnTheThreadCount) {
  SweepMeta meta{"fig4_sweep.toml", "fig4", "ellipsoid", "ball", "both -- test"};
  for (unsigned threads : {1u, 3u}) {
    SweepWriteOptions o;
    o.threads = threads;
    // Per file: progress never goes back, stays within its total, and ends at it.
    std::size_t last_done = 0, last_total = 0, calls = 0;
    o.progress = [&](std::size_t done, std::size_t total) {
      EXPECT_LE(done, total);
      EXPECT_GE(done, last_done);
      last_done = done;
      last_total = total;
      ++calls;
    };
    auto file = [&](auto&& write) {
      last_done = last_total = calls = 0;
      write();
      EXPECT_GT(calls, 0u);
      EXPECT_EQ(last_done, last_total);
    };
    const fs::path d = *dir / ("threads" + std::to_string(threads));
    fs::create_directories(d);
    file([&] { write_sweep_csv(d / "s.csv", *result, meta, o); });
    file([&] { write_sweep_curves_csv(d / "s_curves.csv", *result, meta, o); });
    file([&] { write_sweep_pos(d / "s.pos", *result, meta, o); });
    file([&] { write_sweep_vtp(d / "s.vtp", *result, meta, o); });
  }
  for (const char* f : {"s.csv", "s_curves.csv", "s.pos", "s.vtp"}) {
    EXPECT_TRUE(slurp(*dir / "threads1" / f) == slurp(*dir / "threads3" / f)) << f;
    EXPECT_TRUE(slurp(*dir / "threads1" / f) == slurp(*dir / f)) << f;  // the default: all cores
  }
}

// A non-finite number is a bug upstream: an internal error from whichever chunk holds it, on any
// thread, and no file left behind.
TEST_F(SweepFiles, NonFiniteValueIsAnInternalErrorAndNoFile) {
  SweepResult big = *result;
  big.points.assign(30000, result->points[result->max_index]);
  big.min_index = big.max_index = 0;
  big.points[21000].compression_time_s = std::nan("");
  for (unsigned threads : {1u, 2u}) {
    SweepWriteOptions o;
    o.threads = threads;
    try {
      write_sweep_csv(*dir / "nan.csv", big, {}, o);
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::internal_error);
      EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(*dir / "nan.csv"));
  }
}

TEST(SweepFormats, ParsesTheListAndRefusesUnknownOrRepeatedNames) {
  const SweepFormats old = parse_sweep_formats("csv,vtp,pos,svg,png");
  EXPECT_TRUE(old.csv && old.vtp && old.pos && old.svg && old.png && !old.vtu && !old.curves);
  const SweepFormats two = parse_sweep_formats("png,csv");
  EXPECT_TRUE(two.csv && two.png && !two.vtp && !two.pos && !two.svg && !two.vtu);
  const SweepFormats every = parse_sweep_formats("all");
  EXPECT_TRUE(every.csv && every.vtp && every.pos && every.svg && every.png && every.vtu);
  const SweepFormats defaults;  // the compressed .vtu and the picture's SVG
  EXPECT_TRUE(defaults.vtu && defaults.svg && !defaults.csv && !defaults.vtp && !defaults.pos && !defaults.png);
  EXPECT_THROW(parse_sweep_formats("csv,,pos"), std::invalid_argument);
  EXPECT_THROW(parse_sweep_formats("csv,xyz"), std::invalid_argument);
  EXPECT_THROW(parse_sweep_formats("csv,csv"), std::invalid_argument);
  EXPECT_THROW(parse_sweep_formats(""), std::invalid_argument);
}

TEST_F(SweepFiles, ForceMapSvgAndPng) {
  Xml x(*dir / "s.svg");
  const auto* root = x.doc.RootElement();
  ASSERT_NE(root, nullptr);
  EXPECT_STREQ(root->Name(), "svg");
  const auto circles = all(root, "circle");
  EXPECT_EQ(circles.size(), result->points.size() + 2);  // one per point, two rings at the extremes
  double rmin = 1e300, rmax = 0;
  for (const auto* c : circles) {
    expect_finite_attributes(c, {"cx", "cy", "r"});
    rmin = std::min(rmin, c->DoubleAttribute("r"));
    rmax = std::max(rmax, c->DoubleAttribute("r"));
  }
  // Radius proportional to F_max (the rings are 3 px larger than their circle; SVG keeps 2 decimals).
  EXPECT_NEAR(rmin / (rmax - 3.0), result->force_ratio, 0.01);
  std::string texts;
  for (const auto* t : all(root, "text")) texts += std::string(t->GetText() ? t->GetText() : "") + "|";
  EXPECT_NE(texts.find("F_max [kN]"), std::string::npos) << texts;  // colour bar with its unit
  EXPECT_NE(texts.find("min/max"), std::string::npos);
  EXPECT_GT(all(root, "polyline").size(), 20u);  // the wireframe

  const Png png = read_png(*dir / "s.png");
  EXPECT_EQ(png.width, 960);
  EXPECT_EQ(png.height, 640);
  EXPECT_GT(png.non_white_fraction, 0.05);  // something drawn
  EXPECT_LT(png.non_white_fraction, 0.8);   // not a filled canvas
  EXPECT_GT(png.dark_fraction, 0.002);      // dark circles / text present
}

TEST_F(SweepFiles, LargeCloudPictureIsThinned) {
  const auto cloud = make_cloud(*ss->setup.target.shape, CloudKind::area_uniform, 8, 12000, 9);
  const SweepResult big = run_sweep(ss->setup, cloud);
  ForceMapOptions fo;
  fo.max_points = 5000;  // stride 3: points 0, 3, 6, ... (4000) plus the extremes if off-stride
  const std::string svg = plot::to_svg(force_map_drawing(*ss->setup.target.shape, ss->setup.target.volume.centroid_m, big, fo));
  std::size_t circles = 0;
  for (std::size_t k = svg.find("<circle"); k != std::string::npos; k = svg.find("<circle", k + 1)) ++circles;
  const std::size_t extra = (big.min_index % 3 != 0) + (big.max_index % 3 != 0);
  EXPECT_EQ(circles, 4000 + extra + 2);
  EXPECT_NE(svg.find("12000 points (" + std::to_string(4000 + extra) + " drawn)"), std::string::npos);
}

TEST(Table1Files, CsvMarkdownHeatmap) {
  const fs::path dir = temp_dir("table1");
  Table1Options o = table1_preset("paper");
  const Table1Result r = run_table1(o);
  write_table1_csv(dir / "t.csv", r);
  const std::string csv = slurp(dir / "t.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 81);  // header, 81 cells: no comment line
  EXPECT_EQ(csv.rfind("geometric_ratio,mass_ratio,collision_force_ratio,mass_only_ratio", 0), 0u);
  const std::string side = slurp(dir / "t.csv.json");  // the settings moved to the JSON sidecar
  EXPECT_NE(side.find("\"settings\": \"cloud paper-grid"), std::string::npos) << side;
  const std::string md = table1_markdown(r);
  EXPECT_NE(md.find("| **1e4** |"), std::string::npos);
  EXPECT_NE(md.find("Eq. 40"), std::string::npos);
  EXPECT_EQ(md.find("nan"), std::string::npos);

  const plot::Drawing heat = table1_heatmap(r);
  plot::write_svg(dir / "t.svg", heat);
  plot::write_png(dir / "t.png", heat, 1.0);
  Xml x(dir / "t.svg");
  const auto* root = x.doc.RootElement();
  ASSERT_NE(root, nullptr);
  std::size_t cells = 0;
  for (const auto* rect : all(root, "rect")) {
    expect_finite_attributes(rect, {"x", "y", "width", "height"});
    if (rect->DoubleAttribute("width") == 52 && rect->DoubleAttribute("height") == 28) ++cells;
  }
  EXPECT_EQ(cells, 3u * 81u);  // model, paper, difference
  const Png png = read_png(dir / "t.png");
  EXPECT_EQ(png.width, static_cast<int>(std::lround(heat.width())));
  EXPECT_GT(png.non_white_fraction, 0.2);

  const auto j = table1_json(r);
  ASSERT_EQ(j["collision_force_ratio"].size(), 9u);
  ASSERT_EQ(j["collision_force_ratio"][0].size(), 9u);
  EXPECT_EQ(j["geometric_ratios"][8], 1e4);
  EXPECT_EQ(j["collision_force_ratio"][3][0], r.ratio[3][0]);  // rows g, columns mu
  fs::remove_all(dir);
}

TEST(ForcePlot, RunWritesTheSvgNextToTheCsv) {
  const fs::path dir = temp_dir("run");
  scene::Scene sc = scene::load_scene(std::string(IMPACTDECK_SOURCE_DIR) + "/samples/fig4_sweep.toml");
  ASSERT_TRUE(sc.outputs.force_plot_svg);
  scene::RunOptions ro;
  ro.out_dir = dir;
  const scene::RunReport rep = scene::run_scene(sc, ro);
  ASSERT_TRUE(rep.impacts.at(0).plot_path);
  const fs::path svg = *rep.impacts[0].plot_path;
  EXPECT_EQ(svg, dir / "force_fig4.svg");
  EXPECT_TRUE(fs::exists(dir / "force_fig4.csv"));
  Xml x(svg);
  const auto* root = x.doc.RootElement();
  ASSERT_NE(root, nullptr);
  // Two curves (compression, restitution) with 301 vertices each, then the two dashed marks.
  std::size_t curves = 0, marks = 0;
  for (const auto* p : all(root, "polyline")) {
    const std::string pts = p->Attribute("points");
    const std::size_t vertices = std::count(pts.begin(), pts.end(), ' ') + 1;
    if (vertices == 301) ++curves;
    if (p->Attribute("stroke-dasharray")) ++marks;
  }
  EXPECT_EQ(curves, 2u);
  EXPECT_EQ(marks, 2u);
  std::string texts;
  for (const auto* t : all(root, "text")) texts += std::string(t->GetText() ? t->GetText() : "") + "|";
  EXPECT_NE(texts.find("t_m = "), std::string::npos) << texts;
  EXPECT_NE(texts.find("end = "), std::string::npos);
  EXPECT_NE(texts.find("\xCE\xA0 = (1+R)"), std::string::npos);  // total impulse in the legend
  // The legend's total impulse is the core's, to the 4 digits shown.
  std::ostringstream pi;
  pi << plot::format_number(rep.impacts[0].result.history.impulse_total_Ns()) << " N s";
  EXPECT_NE(texts.find(pi.str()), std::string::npos) << pi.str();
  fs::remove_all(dir);
}

TEST(ForcePlot, SceneKeyIsCheckedAndUnknownKeysStillRejected) {
  const std::string base = R"(
length_unit = "m"
[materials.s]
youngs_modulus_Pa = 2e11
poisson_ratio = 0.3
density_kg_m3 = 7800
[[bodies]]
name = "a"
shape = "sphere"
radius = 0.05
material = "s"
velocity_m_s = [1, 0, 0]
[[bodies]]
name = "b"
shape = "sphere"
radius = 0.05
material = "s"
[[impacts]]
target = "b"
impactor = "a"
point = [-0.05, 0, 0]
restitution = 1.0
[outputs]
)";
  EXPECT_NO_THROW(scene::parse_scene(base + "force_plot_svg = \"f.svg\"\n", "ok.toml"));
  try {
    scene::parse_scene(base + "force_plot_svg = \"f.png\"\n", "bad.toml");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.toml"), std::string::npos) << m;
    EXPECT_NE(m.find("outputs.force_plot_svg"), std::string::npos) << m;
    EXPECT_NE(m.find(".svg"), std::string::npos) << m;
  }
  try {
    scene::parse_scene(base + "force_plot = \"f.svg\"\n", "typo.toml");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("unknown key"), std::string::npos) << m;
    EXPECT_NE(m.find("force_plot_svg"), std::string::npos) << m;  // listed among the allowed keys
  }
}

TEST(Drawing, SvgEscapesTextAndRejectsNonFinite) {
  plot::Drawing d(100, 50);
  d.text({1, 2}, "a < b & \"c\"", 10);
  const std::string s = plot::to_svg(d);
  EXPECT_NE(s.find("a &lt; b &amp; &quot;c&quot;"), std::string::npos);
  d.circle({std::nan(""), 1}, 2, plot::Style{});
  EXPECT_THROW(plot::to_svg(d), Error);
  EXPECT_EQ(plot::nice_ticks(0, 59.6, 5), (std::vector<double>{0, 20, 40}));
  EXPECT_EQ(plot::format_number(-0.0), "0");
}

}  // namespace
}  // namespace impactdeck::study
