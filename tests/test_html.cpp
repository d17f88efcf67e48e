// plot/html.hpp: the report pages' building blocks (issue 18).
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/plot/html.hpp"
#include "impactdeck/plot/part_drawing.hpp"

using namespace impactdeck::plot;

TEST(Html, Base64MatchesRfc4648Vectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\x00\xff\xfe", 3)), "AP/+");  // bytes above 127, and NUL
}

TEST(Html, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(html_escape("<script>alert('x')</script> & \"q\""),
            "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;q&quot;");
  EXPECT_EQ(html_escape(std::string("a\0b", 3)), "a\xEF\xBF\xBD" "b");
}

TEST(Html, InlineSvgDropsTheXmlPrologAndRefusesActiveContent) {
  Drawing d(100, 50);
  d.text({10, 20}, "<script>alert(1)</script> onload=alert(2)", 12);
  const std::string svg = inline_svg(to_svg(d));
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << svg.substr(0, 80);
  EXPECT_EQ(svg.find("<script"), std::string::npos);  // the text is escaped, the picture kept
  EXPECT_NE(svg.find("&lt;script&gt;"), std::string::npos);
  for (const char* bad : {"<svg><script>alert(1)</script></svg>", "<svg onload=\"alert(1)\"></svg>",
                          "<svg><a href=\"javascript:alert(1)\">x</a></svg>",
                          "<svg><foreignObject><p>x</p></foreignObject></svg>", "<html>not svg</html>"}) {
    EXPECT_EQ(inline_svg(bad).find("<svg"), std::string::npos) << bad;
  }
}

TEST(Html, PageIsSelfContainedAndEscapesItsText) {
  HtmlPage p("title <b>");
  p.heading("h & h");
  p.table({"a"}, {{std::string(HtmlPage::kPass) + "ok <1>"}, {std::string(HtmlPage::kFail) + "no"}, {"<i>"}});
  p.figure(png_img(std::string("\x89PNG", 4), "alt \"x\""), "caption <c>");
  const std::string s = p.str();
  EXPECT_NE(s.find("<title>title &lt;b&gt;</title>"), std::string::npos);
  EXPECT_NE(s.find("<td class=\"pass\">ok &lt;1&gt;</td>"), std::string::npos);
  EXPECT_NE(s.find("<td class=\"fail\">no</td>"), std::string::npos);
  EXPECT_NE(s.find("<td>&lt;i&gt;</td>"), std::string::npos);
  EXPECT_NE(s.find("<img alt=\"alt &quot;x&quot;\" src=\"data:image/png;base64,iVBORw==\">"), std::string::npos);
  EXPECT_NE(s.find("default-src 'none'"), std::string::npos);
  EXPECT_EQ(s.find("<script"), std::string::npos);
  EXPECT_EQ(s.find("://"), std::string::npos);  // no external resource
}

namespace {

// The bytes XML 1.0 forbids (its Char production): C0 controls but tab, newline and carriage
// return. tinyxml2 does not check this itself, so the test does; "" when there is none.
std::string forbidden_xml_bytes(const std::string& s) {
  std::string bad;
  for (char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u < 0x20 && c != '\t' && c != '\n' && c != '\r') bad += "\\x" + std::to_string(u) + " ";
  }
  return bad;
}

}  // namespace

TEST(Html, ControlCharactersInNamesGiveWellFormedSvgAndHtml) {
  // An impact or body name with every C0 control character (issue 29): written as its visible
  // symbol U+2401..U+241F, so the SVG and the page stay well-formed XML / valid HTML.
  std::string name = "hit";
  for (char c = 1; c < 0x20; ++c) name += c;
  name += '\x7f';
  Drawing d(100, 50);
  d.text({10, 20}, name, 12);
  const std::string svg = to_svg(d);
  EXPECT_EQ(forbidden_xml_bytes(svg), "");
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(svg.c_str(), svg.size()), tinyxml2::XML_SUCCESS) << doc.ErrorStr();
  EXPECT_NE(svg.find("hit\xE2\x90\x81\xE2\x90\x82"), std::string::npos);  // U+2401 U+2402
  EXPECT_NE(svg.find("\xE2\x90\x9F\xE2\x90\xA1"), std::string::npos);  // U+241F, DEL as U+2421
  HtmlPage p(name);
  p.heading(name);
  p.table({name}, {{name}});
  EXPECT_EQ(forbidden_xml_bytes(p.str()), "");
  EXPECT_EQ(html_escape("a\tb\nc"), "a\tb\nc");  // white space kept
}

// Issue 32: the part drawing's work is bounded whatever the mesh: a fine sphere (a UV grid of
// 2 x 96 x 192 = 36,864 triangles) is decimated by vertex clustering to at most max_triangles,
// stays a closed-looking surface (most of the triangles kept), and the drawing's four views hold
// at most 4 x max_triangles polygons (front faces only), the markers and legend on top.
TEST(PartDrawing, DecimatesABigMeshToTheBoundAndDrawsFourViews) {
  impactdeck::plot::PartSurface s;
  const int rings = 96, segments = 192;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double th = M_PI * i / rings, ph = 2 * M_PI * j / segments;
      s.vertices.emplace_back(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
    }
  auto v = [&](int i, int j) { return i * segments + (j % segments); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      s.triangles.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
      s.triangles.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
    }
  ASSERT_GT(s.triangles.size(), 36000u);
  const std::size_t bound = 3000;
  const impactdeck::plot::PartSurface d = impactdeck::plot::decimate(s, bound);
  EXPECT_LE(d.triangles.size(), bound);
  EXPECT_GT(d.triangles.size(), bound / 4);  // a coarser sphere, not a handful of triangles

  impactdeck::plot::PartMarkers m;
  m.contact_point = Eigen::Vector3d(0, 0, -1);
  m.normal = Eigen::Vector3d(0, 0, -1);
  m.force = Eigen::Vector3d(0, 0, 1);
  m.floor_normal = Eigen::Vector3d(0, 0, 1);
  impactdeck::plot::PartDrawingOptions o;
  o.max_triangles = bound;
  const std::string svg = impactdeck::plot::to_svg(impactdeck::plot::part_drawing(s, m, o));
  std::size_t polygons = 0;
  for (std::size_t k = svg.find("<polygon"); k != std::string::npos; k = svg.find("<polygon", k + 1)) ++polygons;
  EXPECT_GT(polygons, 4 * bound / 8);        // every view shows the sphere's front half
  EXPECT_LE(polygons, 4 * bound + 16);       // plus the arrowheads
  for (const char* label : {"front: x right, z up", "side: y right, z up", "top: x right, y up", "isometric", "floor"})
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
}
