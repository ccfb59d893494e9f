#include "scene/svg_shape_spec.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "core/file_name.h"
#include "core/ground_region.h"
#include "scene/svg_path.h"

namespace kf {

namespace {

// At most this many points in all: the shape terms visit every edge for every agent.
constexpr size_t kMaxPoints = 20'000;
constexpr off_t kMaxSvgBytes = 16 << 20;

double signed_area(const std::vector<Vec2>& loop) {
  double a = 0;
  for (size_t k = 0; k < loop.size(); ++k) {
    const Vec2& p = loop[k];
    const Vec2& q = loop[(k + 1) % loop.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

// The SVG file's text: only a regular file (a FIFO would wait for a writer, /dev/zero never end) of at
// most kMaxSvgBytes. Opened without blocking, then checked as opened.
std::string read_svg_file(const Block& b, const std::filesystem::path& file) {
  const std::string shown = printable(file.string());
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) b.fail("file", "cannot open the SVG file " + shown);
  struct stat st {};
  std::string problem;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) problem = ": not a regular file";
  else if (st.st_size > kMaxSvgBytes) problem = ": larger than the 16 MiB an SVG file may be";
  std::string text;
  while (problem.empty()) {
    char buf[1 << 16];
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) problem = std::string(": cannot read it: ") + std::strerror(errno);
    if (n <= 0) break;
    text.append(buf, size_t(n));
    if (text.size() > size_t(kMaxSvgBytes)) problem = ": larger than the 16 MiB an SVG file may be";  // it grew
  }
  ::close(fd);
  if (!problem.empty()) b.fail("file", shown + problem);
  return text;
}

// Each subpath's loop in path units, and its name for messages ("subpath 2 at character 31").
struct NamedLoops {
  std::vector<SvgLoop> loops;
  std::vector<std::string> names;
};

// The subpaths of the path data `d` (`context` prefixes its errors) or of the SVG file's <path> elements,
// flattened to `tolerance` path units. Errors name `key`.
NamedLoops read_loops(const Block& b, const std::string& key, const std::string& source, double tolerance,
                      const std::filesystem::path& scene_dir) {
  NamedLoops out;
  size_t points = 0;
  auto read_path = [&](const std::string& d, const std::string& where, const std::string& context) {
    std::vector<SvgLoop> more;
    try {
      more = svg_path_loops(d, tolerance, kMaxPoints);
    } catch (const SvgPathError& e) {
      b.fail(key, context + e.what());
    }
    for (SvgLoop& l : more) {
      out.names.push_back("subpath " + std::to_string(out.names.size()) + " at " + where + "character " +
                          std::to_string(l.start + 1));
      points += l.points.size();
      out.loops.push_back(std::move(l));
    }
    if (points > kMaxPoints)
      b.fail(key, context + "the shape flattens to more than " + std::to_string(kMaxPoints) +
                      " points: raise \"tolerance\" or simplify the path");
  };
  if (key == "d") {
    read_path(source, "", "");
    return out;
  }
  const std::filesystem::path file = scene_dir / source;
  const std::string shown = printable(file.string());
  const std::string text = read_svg_file(b, file);
  std::vector<SvgPathElement> elements;
  try {
    elements = svg_document_paths(text);
  } catch (const std::runtime_error& e) {
    b.fail("file", shown + ": " + printable(e.what()));
  }
  for (size_t k = 0; k < elements.size(); ++k) {
    const std::string where = "<path> " + std::to_string(k) + " at line " + std::to_string(elements[k].line);
    read_path(elements[k].d, where + ", ", shown + ": " + where + ": d: ");
  }
  return out;
}

}  // namespace

ShapeLoops parse_svg_shape(Block b, const std::filesystem::path& scene_dir) {
  if (b.has("d") == b.has("file"))
    b.fail_here("expected one of \"d\" (SVG path data, \"M 0 0 L 4 0 L 4 3 Z\") or \"file\" (an SVG file)");
  const std::string key = b.has("d") ? "d" : "file";
  const std::string source = b.string(key);
  const double scale = b.number("scale", 1.0, 1e-9, 1e9);
  Vec2 offset = Vec2::Zero();
  if (b.has("offset")) {
    const std::vector<double> o = b.numbers("offset", 2, -1e6, 1e6);
    if (o.size() != 2) b.fail("offset", "expected [x, z]");
    offset = {o[0], o[1]};
  }
  const double tolerance = b.number("tolerance", 0.01, 1e-6, 1e3);
  b.finish();
  const NamedLoops read = read_loops(b, key, source, tolerance / scale, scene_dir);

  // On the ground, the largest loop is the outline and the others its holes.
  std::vector<std::vector<Vec2>> ground;
  size_t outer = 0;
  for (size_t k = 0; k < read.loops.size(); ++k) {
    std::vector<Vec2> g;
    for (const Vec2& p : read.loops[k].points) g.push_back(offset + scale * p);
    if (std::abs(signed_area(g)) > std::abs(signed_area(ground.empty() ? g : ground[outer]))) outer = k;
    ground.push_back(std::move(g));
  }
  ShapeLoops s;
  std::vector<std::string> hole_names;
  for (size_t k = 0; k < ground.size(); ++k) {
    if (k == outer) continue;
    s.holes.push_back(ground[k]);
    hole_names.push_back(read.names[k]);
  }
  s.outer = std::move(ground[outer]);
  if (const std::string problem = region_problem(GroundRegion(s.outer, s.holes), hole_names); !problem.empty())
    b.fail(key, "the subpaths are one outline, the largest (" + read.names[outer] +
                    "), and holes inside it that do not overlap: " + problem);
  return s;
}

}  // namespace kf
