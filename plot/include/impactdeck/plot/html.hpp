#pragma once
// Self-contained HTML report pages (`run`'s and `campaign collect`'s report.html): one file with
// inline CSS, pictures as inline SVG or PNG data URIs, no script, no external resource. All text
// given to the page is escaped; only the page's own markup and our own SVG drawings go in raw.
#include <string>
#include <string_view>
#include <vector>

namespace impactdeck::plot {

/// Text as HTML character data or attribute value (also XML, for SVG): & < > " ' escaped, NUL as
/// U+FFFD, other control characters but tab, newline and carriage return as their visible symbols
/// (U+2401..U+241F, DEL as U+2421), which XML 1.0 and HTML allow.
std::string html_escape(std::string_view text);

/// RFC 4648 base64 of `bytes` (for data: URIs).
std::string base64(std::string_view bytes);

/// An SVG document (as plot::to_svg writes it) as an inline <svg> element: the XML prolog,
/// doctype and comments before the root element are dropped. A document with no <svg> root, or
/// with a <script> or <foreignObject> element or an on...= handler, gives an escaped note instead.
std::string inline_svg(std::string_view svg);

/// A PNG as <img src="data:image/png;base64,..."> with its alt text (escaped).
std::string png_img(std::string_view png_bytes, std::string_view alt);

/// The page: a title, then blocks of HTML in order. `text` arguments are escaped; `html`
/// arguments are markup the caller built from these helpers.
class HtmlPage {
 public:
  explicit HtmlPage(std::string title);
  void heading(std::string_view text, int level = 2);
  void paragraph(std::string_view text, std::string_view css_class = "");
  void html(std::string markup);
  /// A table: header cells and rows of cells, all text (escaped). A row cell starting with the
  /// marker kPass / kFail is shown as a coloured check outcome.
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
  /// A <pre> block of text (escaped), folded in a <details> element under `summary`.
  void preformatted(std::string_view summary, std::string_view text);
  /// A figure: `picture_html` (inline_svg / png_img) with its caption (escaped).
  void figure(std::string picture_html, std::string_view caption);
  std::string str() const;

  static constexpr const char* kPass = "\x01pass:";
  static constexpr const char* kFail = "\x01" "fail:";

 private:
  std::string title_;
  std::string body_;
};

}  // namespace impactdeck::plot
