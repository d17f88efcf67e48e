// plot/html.hpp: the report pages' building blocks (issue 18).
#include <string>

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/plot/html.hpp"

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
