#pragma once
// A vector drawing built once and written two ways: as SVG text (our own writer, so that the file
// stays small and readable: <circle>, <polyline>, <text>) and as PNG through cairo. Figures
// (the Fig. 4-like force map, the Table 1 heat map, the force-time plot) only build a Drawing.
// Coordinates are in pixels of the SVG canvas, origin top left, y down.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "impactdeck/common/number_text.hpp"

namespace impactdeck::plot {

/// sRGB colour, each component in [0, 1].
struct Colour {
  double r = 0, g = 0, b = 0;
  std::string hex() const;  ///< "#rrggbb"
};

inline constexpr Colour kBlack{0, 0, 0};
inline constexpr Colour kWhite{1, 1, 1};

/// Viridis (perceptually uniform, dark violet at 0, yellow at 1), t clamped to [0, 1].
Colour viridis(double t);
/// Diverging blue - white - red for t in [-1, 1] (clamped).
Colour diverging(double t);
/// Linear mix a + (b - a) t.
Colour mix(const Colour& a, const Colour& b, double t);

struct Point2 {
  double x = 0, y = 0;
};

/// How a primitive is painted. A negative stroke width means "no stroke"; fill_opacity 0 means
/// "no fill".
struct Style {
  Colour stroke = kBlack;
  double stroke_width = 1.0;
  double stroke_opacity = 1.0;
  Colour fill = kWhite;
  double fill_opacity = 0.0;
  double dash = 0.0;  ///< dash length in px; 0 = solid
};

enum class Anchor { start, middle, end };

struct Primitive {
  enum class Kind { polyline, polygon, circle, rect, text } kind = Kind::polyline;
  Style style;
  std::vector<Point2> points;  ///< polyline / polygon vertices
  double x = 0, y = 0;         ///< circle centre, rect corner, text anchor point
  double w = 0, h = 0;         ///< rect size; circle radius in w
  std::string text;            ///< UTF-8
  double font_size = 12;
  Anchor anchor = Anchor::start;
  bool bold = false;
  double rotate_deg = 0;       ///< text rotation about (x, y), counter-clockwise positive
};

class Drawing {
 public:
  Drawing(double width_px, double height_px) : width_(width_px), height_(height_px) {}
  double width() const { return width_; }
  double height() const { return height_; }
  const std::vector<Primitive>& primitives() const { return items_; }

  void line(Point2 a, Point2 b, const Style& s);
  void polyline(std::vector<Point2> pts, const Style& s);
  void polygon(std::vector<Point2> pts, const Style& s);
  void circle(Point2 c, double radius, const Style& s);
  void rect(double x, double y, double w, double h, const Style& s);
  void text(Point2 at, std::string text, double size, Anchor anchor = Anchor::start,
            const Colour& colour = kBlack, bool bold = false, double rotate_deg = 0);

 private:
  double width_, height_;
  std::vector<Primitive> items_;
};

/// SVG 1.1 document (UTF-8). Throws Error(internal) if a coordinate is not finite.
std::string to_svg(const Drawing& d);
/// Writes the SVG atomically.
void write_svg(const std::filesystem::path& path, const Drawing& d);
/// Renders with cairo (antialiased, white background) at `scale` pixels per SVG pixel and writes
/// a PNG atomically.
void write_png(const std::filesystem::path& path, const Drawing& d, double scale = 1.0);

/// A tick of a chart axis: its position (px) along the axis and its label.
struct Tick {
  double px = 0;
  std::string label;
};

/// The frame of a 2-D chart in the box [left, right] x [top, bottom] (px): light grid lines and
/// labelled ticks along the bottom (x) and left (y) axes, the two axes, and the axis titles (the
/// y title turned by 90 degrees). Figures draw their curves on top.
void chart_frame(Drawing& d, double left, double top, double right, double bottom, const std::vector<Tick>& x,
                 const std::vector<Tick>& y, const std::string& x_title, const std::string& y_title);

/// About `count` "nice" tick values (1, 2, 5 x 10^k steps) covering [lo, hi].
std::vector<double> nice_ticks(double lo, double hi, int count = 5);

/// Short number for labels (common/number_text.hpp): up to `digits` significant digits, no
/// trailing zeros, no "-0".
using impactdeck::format_number;

}  // namespace impactdeck::plot
