// SVG shape files and shape sizes a hostile or unlucky user could give, through the real `keyframe` binary:
// every limit is checked when the scene is read (`inspect`, `simulate` and `optimize` alike), with one line
// naming the scene file and the JSON pointer, exit 3 and nothing written.
#include <sys/stat.h>

#include "cli_harness.h"

namespace kf::reliability {
namespace {

std::string flock_scene(const std::string& shape, int agents = 10) {
  return R"({"time": {"frames": 10}, "flock": {"agents": )" + std::to_string(agents) +
         R"(, "spawn": {"radius": 4}}, "objectives": [{"type": "shape", "frame": 10, )" + shape +
         R"(}], "optimizer": {"max_evaluations": 3}})";
}

const char* kSquare = R"(<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 H 4 V 4 H 0 Z"/></svg>)";

class UntrustedSvg : public TempDirTest {
 protected:
  // `inspect`, `simulate` and `optimize` of s.json: exit 3, exactly "keyframe: error: s.json: " + message
  // on one line, and nothing left beside the inputs.
  void expect_refused(const std::string& scene, const std::string& message) {
    write("s.json", scene);
    const std::vector<std::string> before = list_tree(dir_);
    for (const char* command : {"inspect s.json", "simulate s.json --out run", "optimize s.json --out run"}) {
      const CliResult r = run_bounded(command, dir_);
      EXPECT_EQ(r.code, 3) << command << ": " << r.output;
      EXPECT_EQ(r.output, "keyframe: error: s.json: " + message + "\n") << command;
      EXPECT_EQ(list_tree(dir_), before) << command;
    }
  }
};

TEST_F(UntrustedSvg, HugeSquareWithCoverageIsRefusedAtParseTime) {
  expect_refused(flock_scene(R"("svg_path": {"d": "M 0 0 H 2 V 2 H 0 Z", "scale": 1e9}, "coverage": {"weight": 1})"),
                 "/objectives/0/coverage/spacing: the coverage grid over the shape's bounding box would have 7.11e+18 "
                 "samples (at most 100,000): raise \"spacing\"");
}

TEST_F(UntrustedSvg, CoverageGridOverTheLimitIsRefusedAtParseTime) {
  expect_refused(flock_scene(R"("polygon": [[0, 0], [40, 0], [40, 40], [0, 40]], "coverage": {"weight": 1, "spacing": 0.1})"),
                 "/objectives/0/coverage/spacing: the coverage grid over the shape's bounding box would have 1.6e+05 "
                 "samples (at most 100,000): raise \"spacing\"");
}

TEST_F(UntrustedSvg, ArcWhoseStepCountWouldOverflowIsRefusedAtEveryScale) {
  // The radius is raised to half the chord (5e8): at 1 mm on the ground the steps are far too many, and at
  // scale 1e6 the angle step rounds to 0 (their count would overflow an int and the arc become its chord).
  for (const char* scale : {"1", "1000", "1e6"})
    expect_refused(flock_scene(std::string(R"("svg_path": {"d": "M 0 0 A 1 1 0 0 1 1e9 0 L 0 1e9 Z", "tolerance": 1e-3, "scale": )") +
                               scale + "}"),
                   "/objectives/0/svg_path/d: character 7 ('A'): the path flattens to more than 20000 points: raise "
                   "the tolerance or simplify the path");
}

TEST_F(UntrustedSvg, DoctypeAndEntitiesAreRefused) {
  write("e.svg", "<!DOCTYPE svg [<!ENTITY p \"<path d='M 0 0 H 9 V 9 H 0 Z'/>\">]>\n<svg>&p;" + std::string(kSquare) + "</svg>");
  expect_refused(flock_scene(R"("svg_path": {"file": "e.svg"})"),
                 "/objectives/0/svg_path/file: " + std::string("e.svg") +
                     ": line 1: the document type declaration (<!DOCTYPE ...>) is refused: its entities could add to or "
                     "hide the shape");
}

TEST_F(UntrustedSvg, DuplicateAttributeIsRefused) {
  write("d.svg", "<svg>\n<path d=\"M 0 0 H 4 V 4 H 0 Z\" d=\"M 0 0 H 9 V 9 H 0 Z\"/></svg>");
  expect_refused(flock_scene(R"("svg_path": {"file": "d.svg"})"),
                 "/objectives/0/svg_path/file: " + std::string("d.svg") + ": line 2: <path> has the attribute d twice");
}

TEST_F(UntrustedSvg, TransformInAStyleIsRefusedLikeTheAttribute) {
  write("t.svg", "<svg>\n<g style=\"fill: red; Transform : scale(2)\">" + std::string(kSquare) + "</g></svg>");
  expect_refused(flock_scene(R"("svg_path": {"file": "t.svg"})"),
                 "/objectives/0/svg_path/file: " + std::string("t.svg") +
                     ": line 2: <g> has a \"transform\" in its style, which is not applied: flatten the transforms "
                     "into the path data first (in Inkscape: Path > Object to Path, then ungroup)");
}

TEST_F(UntrustedSvg, FifoDeviceAndOversizedFilesAreRefusedWithoutReading) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe.svg").c_str(), 0600), 0);
  expect_refused(flock_scene(R"("svg_path": {"file": "pipe.svg"})"),
                 "/objectives/0/svg_path/file: " + std::string("pipe.svg") + ": not a regular file");
  expect_refused(flock_scene(R"("svg_path": {"file": "/dev/zero"})"),
                 "/objectives/0/svg_path/file: /dev/zero: not a regular file");
  write("big.svg", "");
  fs::resize_file(dir_ / "big.svg", (16u << 20) + 1);
  expect_refused(flock_scene(R"("svg_path": {"file": "big.svg"})"),
                 "/objectives/0/svg_path/file: " + std::string("big.svg") +
                     ": larger than the 16 MiB an SVG file may be");
}

TEST_F(UntrustedSvg, ControlBytesFromTheFileAreEscaped) {
  write("c.svg", "<svg>\n<path d=\"M 0 0 H 4 V 4 H 0 Z \x1b[2J\"/></svg>");
  expect_refused(flock_scene(R"("svg_path": {"file": "c.svg"})"),
                 "/objectives/0/svg_path/file: " + std::string("c.svg") +
                     ": <path> 0 at line 2: d: character 21 (0x1b): expected a command letter (M L H V C S Q T A Z, "
                     "or lower case)");
}

}  // namespace
}  // namespace kf::reliability
