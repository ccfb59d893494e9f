#include "scene/svg_path.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cctype>
#include <cstring>
#include <pugixml.hpp>
#include <set>
#include <utility>

namespace kf {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f'; }
bool is_command(char c) { return c != 0 && std::strchr("MmLlHhVvCcSsQqTtAaZz", c) != nullptr; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool starts_number(char c) { return is_digit(c) || c == '.' || c == '+' || c == '-'; }

std::string shown(char c) {
  if (c >= 0x20 && c < 0x7f) return std::string("'") + c + "'";
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02x", unsigned(static_cast<unsigned char>(c)));
  return buf;
}

// What each command's parameter set is, for messages.
const char* parameters_of(char cmd) {
  switch (cmd | 0x20) {
    case 'm': case 'l': case 't': return "x y";
    case 'h': return "x";
    case 'v': return "y";
    case 'c': return "x1 y1 x2 y2 x y";
    case 's': case 'q': return "x1 y1 x y";
    case 'a': return "rx ry x-axis-rotation large-arc-flag sweep-flag x y";
    default: return "";
  }
}

// Distance from q to the segment a-b.
double segment_distance(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 e = b - a;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0 ? std::clamp((q - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (q - (a + t * e)).norm();
}

class PathReader {
 public:
  PathReader(std::string_view d, double tolerance, size_t max_points)
      : d_(d), tol_(tolerance), max_points_(max_points) {}

  std::vector<SvgLoop> read() {
    skip();
    if (i_ == d_.size()) fail(i_, "expected M or m to begin the path, got an empty path");
    char cmd = 0;
    while (skip(), i_ < d_.size()) {
      const char c = d_[i_];
      if (is_command(c)) {
        cmd = c, cmd_at_ = i_++;
        if (loops_.empty() && !open_ && (cmd | 0x20) != 'm')
          fail(cmd_at_, "expected M or m to begin the path");
      } else if (cmd == 0) {
        fail(i_, "expected M or m to begin the path");
      } else if ((cmd | 0x20) == 'z' || !starts_number(c)) {
        fail(i_, "expected a command letter (M L H V C S Q T A Z, or lower case)" +
                     std::string((cmd | 0x20) == 'z' ? "" : " or a number"));
      }
      step(cmd);
      if (cmd == 'M') cmd = 'L';  // further pairs after a moveto are line-tos
      if (cmd == 'm') cmd = 'l';
    }
    end_subpath();
    return std::move(loops_);
  }

 private:
  [[noreturn]] void fail(size_t at, const std::string& what) const {
    if (at >= d_.size())
      throw SvgPathError(at, "end of the path (character " + std::to_string(at + 1) + "): " + what);
    throw SvgPathError(at, "character " + std::to_string(at + 1) + " (" + shown(d_[at]) + "): " + what);
  }

  void skip() {
    while (i_ < d_.size() && (is_space(d_[i_]) || d_[i_] == ',')) ++i_;
  }

  std::string expected_number(char cmd) const {
    return std::string("expected a number for ") + cmd + " (" + parameters_of(cmd) + ")";
  }

  double number(char cmd) {
    skip();
    const size_t at = i_;
    size_t j = i_;
    if (j < d_.size() && (d_[j] == '+' || d_[j] == '-')) ++j;
    size_t digits = 0;
    while (j < d_.size() && is_digit(d_[j])) ++j, ++digits;
    if (j < d_.size() && d_[j] == '.') {
      ++j;
      while (j < d_.size() && is_digit(d_[j])) ++j, ++digits;
    }
    if (digits == 0) fail(at, expected_number(cmd));
    if (j < d_.size() && (d_[j] == 'e' || d_[j] == 'E')) {
      size_t k = j + 1;
      if (k < d_.size() && (d_[k] == '+' || d_[k] == '-')) ++k;
      if (k < d_.size() && is_digit(d_[k])) {
        while (k < d_.size() && is_digit(d_[k])) ++k;
        j = k;
      }
    }
    double v = 0;
    const char* first = d_.data() + at + (d_[at] == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(first, d_.data() + j, v);
    if (ec != std::errc() || end != d_.data() + j || !std::isfinite(v) || std::abs(v) > 1e9)
      fail(at, "expected a number of magnitude at most 1e9 for " + std::string(1, cmd));
    i_ = j;
    return v;
  }

  bool flag(char cmd) {
    skip();
    if (i_ < d_.size() && (d_[i_] == '0' || d_[i_] == '1')) return d_[i_++] == '1';
    fail(i_, std::string("expected a flag, 0 or 1, for ") + cmd + " (" + parameters_of(cmd) + ")");
  }

  Vec2 point(char cmd, bool relative) {
    const double x = number(cmd);
    const double y = number(cmd);
    return relative ? cur_ + Vec2(x, y) : Vec2(x, y);
  }

  void add(const Vec2& p) {
    if (++count_ > max_points_)
      fail(cmd_at_, "the path flattens to more than " + std::to_string(max_points_) +
                        " points: raise the tolerance or simplify the path");
    loop_.points.push_back(p);
  }

  void begin(const Vec2& p) {
    open_ = true;
    loop_ = {{}, cmd_at_};
    start_ = p;
    loop_.points.push_back(p);
    ++count_;
  }

  void end_subpath() {
    if (!open_) return;
    open_ = false;
    std::vector<Vec2>& pts = loop_.points;
    auto same = [](const Vec2& a, const Vec2& b) { return (a - b).norm() <= 1e-12 * std::max(1.0, a.norm()); };
    pts.erase(std::unique(pts.begin(), pts.end(), same), pts.end());
    while (pts.size() > 1 && same(pts.front(), pts.back())) pts.pop_back();
    const std::string name = "the subpath beginning here";
    if (pts.size() < 3) fail(loop_.start, name + " has fewer than 3 distinct points");
    // All points on one line: the fan of triangles from the first point has no area (a figure eight's
    // lobes may cancel in the signed area, so the triangles count unsigned).
    double fan = 0, extent = 0;
    for (size_t k = 1; k + 1 < pts.size(); ++k) {
      const Vec2 a = pts[k] - pts[0], b = pts[k + 1] - pts[0];
      fan += std::abs(a.x() * b.y() - a.y() * b.x());
      extent = std::max(extent, std::max(a.norm(), b.norm()));
    }
    if (fan <= 1e-12 * extent * extent) fail(loop_.start, name + " encloses no area");
    loops_.push_back(std::move(loop_));
  }

  // Cubic Bézier from cur_: split in halves until both inner control points lie within the tolerance of the
  // chord; the curve lies in their convex hull, hence within the tolerance of the chord too.
  void cubic(const Vec2& p0, const Vec2& p1, const Vec2& p2, const Vec2& p3, int depth = 0) {
    if (depth >= 40 || (segment_distance(p1, p0, p3) <= tol_ && segment_distance(p2, p0, p3) <= tol_)) {
      add(p3);
      return;
    }
    const Vec2 a = 0.5 * (p0 + p1), b = 0.5 * (p1 + p2), c = 0.5 * (p2 + p3);
    const Vec2 ab = 0.5 * (a + b), bc = 0.5 * (b + c), mid = 0.5 * (ab + bc);
    cubic(p0, a, ab, mid, depth + 1);
    cubic(mid, bc, c, p3, depth + 1);
  }

  void quadratic(const Vec2& p0, const Vec2& p1, const Vec2& p2) {
    cubic(p0, p0 + 2.0 / 3.0 * (p1 - p0), p2 + 2.0 / 3.0 * (p1 - p2), p2);  // the same curve, exactly
  }

  // Elliptical arc from cur_ to `to` (SVG 1.1 implementation notes F.6.5 and F.6.6), flattened at equal
  // angle steps: the chord over a step h of an ellipse of radii <= r stays within r (1 - cos(h/2)).
  void arc(double rx, double ry, double phi_deg, bool large, bool sweep, const Vec2& to) {
    const Vec2 from = cur_;
    if ((to - from).norm() == 0) return;  // an arc to its own start is left out
    rx = std::abs(rx), ry = std::abs(ry);
    if (rx == 0 || ry == 0) {
      add(to);
      return;
    }
    const double phi = phi_deg * M_PI / 180.0, cp = std::cos(phi), sp = std::sin(phi);
    const Vec2 h = 0.5 * (from - to);
    const Vec2 p(cp * h.x() + sp * h.y(), -sp * h.x() + cp * h.y());
    const double lambda = p.x() * p.x() / (rx * rx) + p.y() * p.y() / (ry * ry);
    if (lambda > 1) rx *= std::sqrt(lambda), ry *= std::sqrt(lambda);
    const double num = rx * rx * ry * ry - rx * rx * p.y() * p.y() - ry * ry * p.x() * p.x();
    const double den = rx * rx * p.y() * p.y() + ry * ry * p.x() * p.x();
    const double coef = (large != sweep ? 1 : -1) * std::sqrt(std::max(0.0, num / den));
    const Vec2 c1(coef * rx * p.y() / ry, -coef * ry * p.x() / rx);
    const Vec2 mid = 0.5 * (from + to);
    const Vec2 center(cp * c1.x() - sp * c1.y() + mid.x(), sp * c1.x() + cp * c1.y() + mid.y());
    const Vec2 u((p.x() - c1.x()) / rx, (p.y() - c1.y()) / ry), v((-p.x() - c1.x()) / rx, (-p.y() - c1.y()) / ry);
    const double theta1 = std::atan2(u.y(), u.x());
    double dtheta = std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v));
    if (!sweep && dtheta > 0) dtheta -= 2 * M_PI;
    if (sweep && dtheta < 0) dtheta += 2 * M_PI;
    const double r = std::max(rx, ry);
    const double step = tol_ < r ? 2 * std::acos(1 - tol_ / r) : M_PI;
    // The step count in double precision first: a tolerance far below the radius makes it overflow an int
    // (or the step round to 0).
    const double steps = std::max(1.0, std::ceil(std::abs(dtheta) / step));
    if (!(steps <= double(max_points_)))
      fail(cmd_at_, "the path flattens to more than " + std::to_string(max_points_) +
                        " points: raise the tolerance or simplify the path");
    const int n = int(steps);
    for (int k = 1; k < n; ++k) {
      const double t = theta1 + dtheta * k / n;
      const Vec2 e(rx * std::cos(t), ry * std::sin(t));
      add(center + Vec2(cp * e.x() - sp * e.y(), sp * e.x() + cp * e.y()));
    }
    add(to);  // exactly the end point
  }

  // One parameter set of `cmd` (none for Z).
  void step(char cmd) {
    const bool rel = cmd >= 'a';
    const char kind = char(cmd | 0x20);
    Vec2 next_ctrl = cur_;  // the control point a following S or T reflects (none: the current point)
    char next_kind = 0;
    if (kind != 'm' && kind != 'z' && !open_) begin(cur_);  // drawing on after Z starts a subpath there
    switch (kind) {
      case 'm': {
        const Vec2 p = point(cmd, rel);  // a first "m" is relative to (0, 0): absolute, as SVG says
        end_subpath();
        cur_ = p;
        begin(p);
        break;
      }
      case 'l': cur_ = point(cmd, rel), add(cur_); break;
      case 'h': cur_.x() = number(cmd) + (rel ? cur_.x() : 0.0), add(cur_); break;
      case 'v': cur_.y() = number(cmd) + (rel ? cur_.y() : 0.0), add(cur_); break;
      case 'c': case 's': {
        const Vec2 p1 = kind == 'c' ? point(cmd, rel) : (last_kind_ == 'c' ? 2 * cur_ - last_ctrl_ : cur_);
        const Vec2 p2 = point(cmd, rel), p3 = point(cmd, rel);
        cubic(cur_, p1, p2, p3);
        next_ctrl = p2, next_kind = 'c', cur_ = p3;
        break;
      }
      case 'q': case 't': {
        const Vec2 p1 = kind == 'q' ? point(cmd, rel) : (last_kind_ == 'q' ? 2 * cur_ - last_ctrl_ : cur_);
        const Vec2 p2 = point(cmd, rel);
        quadratic(cur_, p1, p2);
        next_ctrl = p1, next_kind = 'q', cur_ = p2;
        break;
      }
      case 'a': {
        const double rx = number(cmd), ry = number(cmd), rot = number(cmd);
        const bool large = flag(cmd), sweep = flag(cmd);
        const Vec2 to = point(cmd, rel);
        arc(rx, ry, rot, large, sweep, to);
        cur_ = to;
        break;
      }
      case 'z':
        if (open_) add(start_);
        end_subpath();
        cur_ = start_;
        break;
    }
    last_ctrl_ = next_ctrl, last_kind_ = next_kind;
  }

  std::string_view d_;
  double tol_;
  size_t max_points_;
  size_t i_ = 0, cmd_at_ = 0, count_ = 0;
  Vec2 cur_ = Vec2::Zero(), start_ = Vec2::Zero(), last_ctrl_ = Vec2::Zero();
  char last_kind_ = 0;
  bool open_ = false;
  SvgLoop loop_;
  std::vector<SvgLoop> loops_;
};

}  // namespace

std::vector<SvgLoop> svg_path_loops(std::string_view d, double tolerance, size_t max_points) {
  if (!(tolerance > 0)) throw SvgPathError(0, "the flattening tolerance must be positive");
  return PathReader(d, tolerance, max_points).read();
}

namespace {

int line_at(const std::string& text, size_t at) {
  return 1 + int(std::count(text.begin(), text.begin() + std::min(at, text.size()), '\n'));
}

[[noreturn]] void fail_at(const std::string& text, size_t at, const std::string& what) {
  throw std::runtime_error("line " + std::to_string(line_at(text, at)) + ": " + what);
}

std::string local_name(const char* name) {
  const char* colon = std::strrchr(name, ':');
  return colon ? colon + 1 : name;
}

// Whether a style attribute ("fill: red; transform: rotate(5deg)") sets the CSS transform property.
bool style_has_transform(std::string_view style) {
  for (size_t at = 0; at <= style.size();) {
    const size_t end = std::min(style.find(';', at), style.size());
    std::string_view decl = style.substr(at, end - at);
    decl = decl.substr(0, decl.find(':'));
    while (!decl.empty() && is_space(decl.front())) decl.remove_prefix(1);
    while (!decl.empty() && is_space(decl.back())) decl.remove_suffix(1);
    std::string name(decl);
    for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (name == "transform") return true;
    at = end + 1;
  }
  return false;
}

// Refuses what this reader would otherwise misread in one element's attributes: a repeated attribute (XML
// forbids it; readers disagree on which one counts), a transform as an attribute or in its style, and an
// entity reference in a path's d.
void check_attributes(const std::string& text, const pugi::xml_node& node) {
  const std::string name = local_name(node.name());
  const size_t at = size_t(node.offset_debug());
  std::set<std::string> seen;
  for (const pugi::xml_attribute& a : node.attributes()) {
    const std::string attr = a.name();
    if (!seen.insert(attr).second) fail_at(text, at, "<" + name + "> has the attribute " + attr + " twice");
    const std::string local = local_name(attr.c_str());
    if (local == "transform" || local == "patternTransform" || local == "gradientTransform" ||
        (local == "style" && style_has_transform(a.value())))
      fail_at(text, at, "<" + name + "> has a " + (local == "style" ? "\"transform\" in its style" : "\"" + attr + "\" attribute") +
              ", which is not applied: flatten the transforms into the path data first (in Inkscape: Path > Object "
              "to Path, then ungroup)");
    if (name == "path" && local == "d" && std::strchr(a.value(), '&'))
      fail_at(text, at, "<path>'s d holds an entity reference (&...;)");
  }
}

}  // namespace

std::vector<SvgPathElement> svg_document_paths(const std::string& text) {
  pugi::xml_document doc;
  // Entities left unexpanded (a d holding one is refused) and the document type kept, to refuse it.
  const unsigned options = (pugi::parse_default & ~pugi::parse_escapes) | pugi::parse_doctype;
  const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size(), options, pugi::encoding_utf8);
  if (!parsed) fail_at(text, size_t(std::max<ptrdiff_t>(parsed.offset, 0)), std::string("not well-formed XML: ") + parsed.description());
  std::vector<SvgPathElement> paths;
  std::vector<pugi::xml_node> stack = {doc};
  while (!stack.empty()) {
    const pugi::xml_node node = stack.back();
    stack.pop_back();
    if (node.type() == pugi::node_doctype)
      fail_at(text, size_t(node.offset_debug()), "the document type declaration (<!DOCTYPE ...>) is refused: its "
              "entities could add to or hide the shape");
    if (node.type() == pugi::node_element) {
      check_attributes(text, node);
      if (local_name(node.name()) == "path") {
        const pugi::xml_attribute d = node.attribute("d");
        if (!d) fail_at(text, size_t(node.offset_debug()), "<path> without a \"d\" attribute");
        paths.push_back({d.value(), line_at(text, size_t(node.offset_debug()))});
      }
    }
    // Children in reverse so that the stack visits them in document order.
    std::vector<pugi::xml_node> children(node.begin(), node.end());
    stack.insert(stack.end(), children.rbegin(), children.rend());
  }
  if (paths.empty()) throw std::runtime_error("no <path d=\"...\"> element (shapes such as <rect> and text "
                                              "are not read: convert them to paths first)");
  return paths;
}

}  // namespace kf
