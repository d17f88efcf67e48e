// Self-contained HTML pages (see html.hpp).
#include "impactdeck/plot/html.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>

#include "impactdeck/common/version.hpp"
#include "impactdeck/common/xml_text.hpp"

namespace impactdeck::plot {

std::string html_escape(std::string_view t) { return xml_escape(t); }

std::string base64(std::string_view bytes) {
  static const char* const k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  o.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    o += k[(v >> 18) & 63];
    o += k[(v >> 12) & 63];
    o += k[(v >> 6) & 63];
    o += k[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    o += k[(v >> 18) & 63];
    o += k[(v >> 12) & 63];
    o += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    o += '=';
  }
  return o;
}

namespace {

std::string lower(std::string_view s) {
  std::string o(s);
  std::transform(o.begin(), o.end(), o.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return o;
}

// Whether an SVG's markup could run code or fetch something: inside its tags (text is escaped, so
// every '<' opens a tag) a script or foreignObject element, an event handler attribute (on...=),
// a javascript: URL or any href. Our drawings have none.
bool active_content(std::string_view svg) {
  const std::string s = lower(svg);
  for (std::size_t open = s.find('<'); open != std::string::npos; open = s.find('<', open + 1)) {
    const std::size_t close = s.find('>', open);
    const std::string tag = s.substr(open, close == std::string::npos ? std::string::npos : close - open);
    if (tag.rfind("<script", 0) == 0 || tag.rfind("<foreignobject", 0) == 0 || tag.find("javascript:") != std::string::npos ||
        tag.find("href") != std::string::npos) {
      return true;
    }
    for (std::size_t k = tag.find("on"); k != std::string::npos; k = tag.find("on", k + 2)) {
      if (k == 0 || !std::isspace(static_cast<unsigned char>(tag[k - 1]))) continue;
      std::size_t e = k + 2;
      while (e < tag.size() && std::isalpha(static_cast<unsigned char>(tag[e]))) ++e;
      while (e < tag.size() && std::isspace(static_cast<unsigned char>(tag[e]))) ++e;
      if (e > k + 2 && e < tag.size() && tag[e] == '=') return true;
    }
    if (close == std::string::npos) break;
    open = close;
  }
  return false;
}

}  // namespace

std::string inline_svg(std::string_view svg) {
  const std::size_t root = svg.find("<svg");
  if (root == std::string_view::npos || active_content(svg)) {
    return "<p class=\"fail\">(picture left out: not a plain SVG drawing)</p>";
  }
  return std::string(svg.substr(root));
}

std::string png_img(std::string_view png, std::string_view alt) {
  return "<img alt=\"" + html_escape(alt) + "\" src=\"data:image/png;base64," + base64(png) + "\">";
}

HtmlPage::HtmlPage(std::string title) : title_(std::move(title)) {}

void HtmlPage::heading(std::string_view text, int level) {
  level = std::clamp(level, 1, 4);
  const std::string h = "h" + std::to_string(level);
  body_ += "<" + h + ">" + html_escape(text) + "</" + h + ">\n";
}

void HtmlPage::paragraph(std::string_view text, std::string_view css_class) {
  body_ += css_class.empty() ? "<p>" : "<p class=\"" + html_escape(css_class) + "\">";
  body_ += html_escape(text) + "</p>\n";
}

void HtmlPage::html(std::string markup) { body_ += markup + "\n"; }

void HtmlPage::table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::string t = "<table>\n<tr>";
  for (const auto& h : header) t += "<th>" + html_escape(h) + "</th>";
  t += "</tr>\n";
  const std::size_t marker = std::strlen(kPass);
  for (const auto& row : rows) {
    t += "<tr>";
    for (const auto& c : row) {
      if (c.rfind(kPass, 0) == 0) {
        t += "<td class=\"pass\">" + html_escape(c.substr(marker)) + "</td>";
      } else if (c.rfind(kFail, 0) == 0) {
        t += "<td class=\"fail\">" + html_escape(c.substr(marker)) + "</td>";
      } else {
        t += "<td>" + html_escape(c) + "</td>";
      }
    }
    t += "</tr>\n";
  }
  body_ += t + "</table>\n";
}

void HtmlPage::preformatted(std::string_view summary, std::string_view text) {
  body_ += "<details><summary>" + html_escape(summary) + "</summary>\n<pre>" + html_escape(text) + "</pre></details>\n";
}

void HtmlPage::figure(std::string picture_html, std::string_view caption) {
  body_ += "<figure>" + picture_html + "<figcaption>" + html_escape(caption) + "</figcaption></figure>\n";
}

std::string HtmlPage::str() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; style-src 'unsafe-inline'; "
         "img-src data:\">\n"
         "<meta name=\"generator\" content=\"impactdeck " + std::string(kVersion) + "\">\n"
         "<title>" + html_escape(title_) + "</title>\n<style>\n"
         "body{font-family:DejaVu Sans,Arial,sans-serif;margin:2em auto;max-width:1100px;color:#222}\n"
         "table{border-collapse:collapse;margin:0.5em 0 1em}\n"
         "th,td{border:1px solid #bbb;padding:3px 8px;text-align:left;vertical-align:top}\n"
         "th{background:#eee}\n"
         ".pass{background:#e3f4e3}\n.fail{background:#f8dada;font-weight:bold}\n"
         ".verdict{font-size:1.4em;padding:0.5em;border:2px solid #444}\n"
         ".warning{background:#fff4d6;padding:0.3em}\n"
         "figure{margin:1em 0}\nfigure svg,figure img{max-width:100%;height:auto;border:1px solid #ddd}\n"
         "pre{background:#f6f6f6;padding:0.5em;overflow-x:auto}\n"
         ".governing{font-size:1.1em;margin-top:-0.3em}\n"
         "figcaption{font-size:0.9em;color:#444}\n"
         ".wide{overflow-x:auto}\ntable.cases{font-size:0.85em}\n"
         "details>ul{margin:0.2em 0;padding-left:1.2em}\n"
         // Printed (or saved as PDF): full width, pictures and tables not split across pages, the
         // headings kept with what follows (folded blocks print folded).
         "@media print{body{max-width:none;margin:0;font-size:10pt}figure,table,.verdict,.warning{break-inside:avoid}"
         "h2,h3{break-after:avoid}a{color:inherit;text-decoration:none}"
         ".verdict{border-width:3px}}\n"
         "</style>\n</head>\n<body>\n<h1>" + html_escape(title_) + "</h1>\n" + body_ + "</body>\n</html>\n";
}

}  // namespace impactdeck::plot
