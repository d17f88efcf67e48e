#include "impactdeck/plot/drawing.hpp"

#include "impactdeck/plot/html.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include <cairo.h>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::plot {

std::string Colour::hex() const {
  auto c = [](double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c(r), c(g), c(b));
  return buf;
}

Colour mix(const Colour& a, const Colour& b, double t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

namespace {

Colour from_hex(unsigned v) {
  return {((v >> 16) & 0xff) / 255.0, ((v >> 8) & 0xff) / 255.0, (v & 0xff) / 255.0};
}

template <std::size_t N>
Colour interpolate(const std::array<unsigned, N>& stops, double t) {
  if (!(t > 0.0)) return from_hex(stops.front());  // also NaN
  if (t >= 1.0) return from_hex(stops.back());
  const double u = t * (N - 1);
  const auto i = static_cast<std::size_t>(u);
  return mix(from_hex(stops[i]), from_hex(stops[i + 1]), u - static_cast<double>(i));
}

}  // namespace

Colour viridis(double t) {
  // Viridis sampled at 9 equally spaced points (matplotlib's table), interpolated linearly.
  static constexpr std::array<unsigned, 9> stops = {0x440154, 0x472c7a, 0x3b518b, 0x2c718e, 0x21908d,
                                                    0x27ad81, 0x5cc863, 0xaadc32, 0xfde725};
  return interpolate(stops, t);
}

Colour diverging(double t) {
  // ColorBrewer RdBu, reversed: blue for negative, red for positive.
  static constexpr std::array<unsigned, 7> stops = {0x2166ac, 0x67a9cf, 0xd1e5f0, 0xf7f7f7,
                                                    0xfddbc7, 0xef8a62, 0xb2182b};
  return interpolate(stops, 0.5 * (std::clamp(t, -1.0, 1.0) + 1.0));
}

void Drawing::line(Point2 a, Point2 b, const Style& s) { polyline({a, b}, s); }

void Drawing::polyline(std::vector<Point2> pts, const Style& s) {
  Primitive p;
  p.kind = Primitive::Kind::polyline;
  p.points = std::move(pts);
  p.style = s;
  items_.push_back(std::move(p));
}

void Drawing::polygon(std::vector<Point2> pts, const Style& s) {
  Primitive p;
  p.kind = Primitive::Kind::polygon;
  p.points = std::move(pts);
  p.style = s;
  items_.push_back(std::move(p));
}

void Drawing::circle(Point2 c, double radius, const Style& s) {
  Primitive p;
  p.kind = Primitive::Kind::circle;
  p.x = c.x;
  p.y = c.y;
  p.w = radius;
  p.style = s;
  items_.push_back(std::move(p));
}

void Drawing::rect(double x, double y, double w, double h, const Style& s) {
  Primitive p;
  p.kind = Primitive::Kind::rect;
  p.x = x;
  p.y = y;
  p.w = w;
  p.h = h;
  p.style = s;
  items_.push_back(std::move(p));
}

void Drawing::text(Point2 at, std::string t, double size, Anchor anchor, const Colour& colour,
                   bool bold, double rotate_deg) {
  Primitive p;
  p.kind = Primitive::Kind::text;
  p.x = at.x;
  p.y = at.y;
  p.text = std::move(t);
  p.font_size = size;
  p.anchor = anchor;
  p.bold = bold;
  p.rotate_deg = rotate_deg;
  p.style.fill = colour;
  p.style.fill_opacity = 1.0;
  items_.push_back(std::move(p));
}

// ---------------------------------------------------------------------------------------------
// SVG

namespace {

std::string num(double v) {
  if (!std::isfinite(v)) throw Error(ExitCode::internal_error, "drawing: non-finite coordinate");
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s(buf);
  // Trim "12.50" -> "12.5", "3.00" -> "3", and never "-0".
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

std::string escape(const std::string& t) { return html_escape(t); }  // XML needs the same

std::string style_attrs(const Style& s) {
  std::ostringstream o;
  if (s.fill_opacity > 0.0) {
    o << " fill=\"" << s.fill.hex() << "\"";
    if (s.fill_opacity < 1.0) o << " fill-opacity=\"" << num(s.fill_opacity) << "\"";
  } else {
    o << " fill=\"none\"";
  }
  if (s.stroke_width > 0.0) {
    o << " stroke=\"" << s.stroke.hex() << "\" stroke-width=\"" << num(s.stroke_width) << "\"";
    if (s.stroke_opacity < 1.0) o << " stroke-opacity=\"" << num(s.stroke_opacity) << "\"";
    if (s.dash > 0.0) o << " stroke-dasharray=\"" << num(s.dash) << " " << num(s.dash) << "\"";
  }
  return o.str();
}

}  // namespace

void chart_frame(Drawing& d, double left, double top, double right, double bottom, const std::vector<Tick>& x,
                 const std::vector<Tick>& y, const std::string& x_title, const std::string& y_title) {
  Style grid;
  grid.stroke = {0.85, 0.85, 0.85};
  grid.stroke_width = 0.8;
  Style axis;
  axis.stroke_width = 1.2;
  for (const Tick& t : x) {
    d.line({t.px, top}, {t.px, bottom}, grid);
    d.line({t.px, bottom}, {t.px, bottom + 5}, axis);
    d.text({t.px, bottom + 20}, t.label, 12, Anchor::middle);
  }
  for (const Tick& t : y) {
    d.line({left, t.px}, {right, t.px}, grid);
    d.line({left - 5, t.px}, {left, t.px}, axis);
    d.text({left - 9, t.px + 4}, t.label, 12, Anchor::end);
  }
  d.polyline({{left, top}, {left, bottom}, {right, bottom}}, axis);
  d.text({0.5 * (left + right), bottom + 44}, x_title, 13, Anchor::middle);
  d.text({24, 0.5 * (top + bottom)}, y_title, 13, Anchor::middle, kBlack, false, 90);
}

std::string to_svg(const Drawing& d) {
  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << num(d.width())
    << "\" height=\"" << num(d.height()) << "\" viewBox=\"0 0 " << num(d.width()) << " "
    << num(d.height()) << "\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n"
    << "<rect x=\"0\" y=\"0\" width=\"" << num(d.width()) << "\" height=\"" << num(d.height())
    << "\" fill=\"#ffffff\"/>\n";
  for (const Primitive& p : d.primitives()) {
    switch (p.kind) {
      case Primitive::Kind::polyline:
      case Primitive::Kind::polygon: {
        o << (p.kind == Primitive::Kind::polyline ? "<polyline" : "<polygon") << " points=\"";
        for (std::size_t i = 0; i < p.points.size(); ++i) {
          o << (i ? " " : "") << num(p.points[i].x) << "," << num(p.points[i].y);
        }
        o << "\"" << style_attrs(p.style) << " stroke-linejoin=\"round\"/>\n";
        break;
      }
      case Primitive::Kind::circle:
        o << "<circle cx=\"" << num(p.x) << "\" cy=\"" << num(p.y) << "\" r=\"" << num(p.w) << "\""
          << style_attrs(p.style) << "/>\n";
        break;
      case Primitive::Kind::rect:
        o << "<rect x=\"" << num(p.x) << "\" y=\"" << num(p.y) << "\" width=\"" << num(p.w)
          << "\" height=\"" << num(p.h) << "\"" << style_attrs(p.style) << "/>\n";
        break;
      case Primitive::Kind::text: {
        const char* anchor = p.anchor == Anchor::start ? "start" : p.anchor == Anchor::middle ? "middle" : "end";
        o << "<text x=\"" << num(p.x) << "\" y=\"" << num(p.y) << "\" font-size=\"" << num(p.font_size)
          << "\" text-anchor=\"" << anchor << "\" fill=\"" << p.style.fill.hex() << "\"";
        if (p.bold) o << " font-weight=\"bold\"";
        if (p.rotate_deg != 0.0) {
          o << " transform=\"rotate(" << num(-p.rotate_deg) << " " << num(p.x) << " " << num(p.y) << ")\"";
        }
        o << ">" << escape(p.text) << "</text>\n";
        break;
      }
    }
  }
  o << "</svg>\n";
  return o.str();
}

void write_svg(const std::filesystem::path& path, const Drawing& d) {
  write_file_atomically(path, to_svg(d));
}

// ---------------------------------------------------------------------------------------------
// PNG through cairo

namespace {

void set_colour(cairo_t* cr, const Colour& c, double alpha) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

void paint(cairo_t* cr, const Style& s, double scale) {
  if (s.fill_opacity > 0.0) {
    set_colour(cr, s.fill, s.fill_opacity);
    if (s.stroke_width > 0.0) cairo_fill_preserve(cr); else cairo_fill(cr);
  }
  if (s.stroke_width > 0.0) {
    set_colour(cr, s.stroke, s.stroke_opacity);
    cairo_set_line_width(cr, s.stroke_width * scale);
    if (s.dash > 0.0) {
      const double dash = s.dash * scale;
      cairo_set_dash(cr, &dash, 1, 0.0);
    } else {
      cairo_set_dash(cr, nullptr, 0, 0.0);
    }
    cairo_stroke(cr);
  }
  cairo_new_path(cr);
}

void render(cairo_t* cr, const Drawing& d, double k) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (const Primitive& p : d.primitives()) {
    switch (p.kind) {
      case Primitive::Kind::polyline:
      case Primitive::Kind::polygon:
        if (p.points.empty()) break;
        cairo_move_to(cr, p.points[0].x * k, p.points[0].y * k);
        for (std::size_t i = 1; i < p.points.size(); ++i) cairo_line_to(cr, p.points[i].x * k, p.points[i].y * k);
        if (p.kind == Primitive::Kind::polygon) cairo_close_path(cr);
        paint(cr, p.style, k);
        break;
      case Primitive::Kind::circle:
        cairo_new_sub_path(cr);
        cairo_arc(cr, p.x * k, p.y * k, p.w * k, 0.0, 2.0 * M_PI);
        paint(cr, p.style, k);
        break;
      case Primitive::Kind::rect:
        cairo_rectangle(cr, p.x * k, p.y * k, p.w * k, p.h * k);
        paint(cr, p.style, k);
        break;
      case Primitive::Kind::text: {
        cairo_save(cr);
        cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                               p.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
        cairo_set_font_size(cr, p.font_size * k);
        cairo_translate(cr, p.x * k, p.y * k);
        cairo_rotate(cr, -p.rotate_deg * M_PI / 180.0);
        cairo_text_extents_t ext;
        cairo_text_extents(cr, p.text.c_str(), &ext);
        double dx = 0.0;
        if (p.anchor == Anchor::middle) dx = -0.5 * ext.x_advance;
        if (p.anchor == Anchor::end) dx = -ext.x_advance;
        cairo_move_to(cr, dx, 0.0);
        set_colour(cr, p.style.fill, 1.0);
        cairo_show_text(cr, p.text.c_str());
        cairo_restore(cr);
        break;
      }
    }
  }
}

cairo_status_t to_stream(void* closure, const unsigned char* data, unsigned int length) {
  auto* os = static_cast<std::ostream*>(closure);
  os->write(reinterpret_cast<const char*>(data), length);
  return *os ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

}  // namespace

void write_png(const std::filesystem::path& path, const Drawing& d, double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw InputError(path.string(), "png scale", "must be positive");
  }
  const int w = std::max(1, static_cast<int>(std::lround(d.width() * scale)));
  const int h = std::max(1, static_cast<int>(std::lround(d.height() * scale)));
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h), &cairo_surface_destroy);
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    throw Error(ExitCode::internal_error, "cairo: cannot create a " + std::to_string(w) + "x" +
                                              std::to_string(h) + " image surface");
  }
  {
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), &cairo_destroy);
    render(cr.get(), d, scale);
    if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) {
      throw Error(ExitCode::internal_error,
                  std::string("cairo: drawing failed: ") + cairo_status_to_string(cairo_status(cr.get())));
    }
  }
  cairo_surface_flush(surface.get());
  write_file_atomically(path, [&](std::ostream& os) {
    const cairo_status_t st = cairo_surface_write_to_png_stream(surface.get(), &to_stream, &os);
    if (st != CAIRO_STATUS_SUCCESS) {
      throw InputError(path.string(), "png", std::string("cannot write: ") + cairo_status_to_string(st));
    }
  });
}

// ---------------------------------------------------------------------------------------------

std::vector<double> nice_ticks(double lo, double hi, int count) {
  std::vector<double> t;
  if (!std::isfinite(lo) || !std::isfinite(hi) || count < 1) return t;
  if (hi < lo) std::swap(lo, hi);
  if (hi == lo) {
    t.push_back(lo);
    return t;
  }
  const double raw = (hi - lo) / count;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (double v = first; v <= hi + 1e-9 * step; v += step) t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

}  // namespace impactdeck::plot
