// A finished staged run's evaluation tape (evaluations.bin), changed after it was written, through the real
// binary: `optimize --resume` refuses a flipped byte (its checksum), a non-finite objective, gradient or
// term written with a matching checksum, and a stage the run's plan does not give: exit 3, one line naming
// the file, and the run directory left as it was.
#include <cmath>
#include <cstring>
#include <limits>

#include "cli_harness.h"

namespace kf::reliability {
namespace {

// A 6 x 6 sheet dropped on a sphere with per-frame forces: lattice windows, then one force per particle.
const char* const kDrop = R"({"time": {"fps": 30, "frames": 12},
  "cloth": {"nx": 6, "ny": 6, "width": 1.0, "height": 1.0, "mass": 0.3, "origin": [-0.5, 0.9, -0.5],
            "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
            "colliders": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.3}, {"type": "ground"}]},
  "objectives": [{"type": "center_of_mass", "frame": 12, "target": [0.1, 0.5, 0]}],
  "controls": {"kind": "per_frame"},
  "optimizer": {"max_evaluations": 12}})";

// Where things are in the tape, read by the layout evaluation_tape.h documents (not by its reader).
struct TapeLayout {
  std::vector<std::uint64_t> stage_controls;
  size_t stage_table = 16;  // the first stage's entry (20 bytes each)
  struct Record {
    std::uint32_t stage = 0;
    size_t phi = 0, first_term_value = 0, gradient = 0;
    std::uint32_t terms = 0;
  };
  std::vector<Record> records;
};

template <class T>
T at(const std::string& b, size_t offset) {
  T v;
  std::memcpy(&v, b.data() + offset, sizeof v);
  return v;
}

TapeLayout layout_of(const std::string& b) {
  TapeLayout t;
  const auto stages = at<std::uint64_t>(b, 8);
  for (std::uint64_t s = 0; s < stages; ++s) t.stage_controls.push_back(at<std::uint64_t>(b, 16 + 20 * s));
  size_t p = 16 + 20 * stages;
  const auto count = at<std::uint64_t>(b, p);
  p += 8;
  for (std::uint64_t k = 0; k < count; ++k) {
    TapeLayout::Record r;
    r.stage = at<std::uint32_t>(b, p);
    r.phi = p + 4;
    r.terms = at<std::uint32_t>(b, p + 21);
    p += 25;
    for (std::uint32_t term = 0; term < r.terms; ++term) {
      p += 4 + at<std::uint32_t>(b, p);
      if (term == 0) r.first_term_value = p;
      p += 8;
    }
    const size_t n = t.stage_controls.at(r.stage);
    r.gradient = p + 8 * n;
    p += 16 * n;
    t.records.push_back(r);
  }
  EXPECT_EQ(p + 8, b.size()) << "the tape's layout is not the documented one";
  return t;
}

// The tape's bytes without its checksum, with a FNV-1a checksum that matches them.
std::string with_matching_checksum(std::string b) {
  b.resize(b.size() - 8);
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : b) h = (h ^ std::uint8_t(c)) * 0x100000001b3ULL;
  b.append(reinterpret_cast<const char*>(&h), 8);
  return b;
}

void put_double(std::string& b, size_t offset, double v) { std::memcpy(b.data() + offset, &v, 8); }

class TapeTrust : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    write("scene.json", kDrop);
    const CliResult r = run_bounded("optimize scene.json --out run", dir_);
    ASSERT_TRUE(r.code == 0 || r.code == 7) << r.output;
    tape_ = read_text(dir_ / "run/evaluations.bin");
    layout_ = layout_of(tape_);
    ASSERT_GE(layout_.stage_controls.size(), 2u);
    ASSERT_NE(layout_.stage_controls[0], layout_.stage_controls.back());  // stages of different sizes
  }
  // The first record of the last stage the run reached (a later stage than the first).
  const TapeLayout::Record& later_record() const {
    for (const auto& r : layout_.records)
      if (r.stage > 0) return r;
    ADD_FAILURE() << "the run recorded nothing after its first stage";
    return layout_.records.front();
  }
  // `optimize --resume run` with the tape replaced by `bytes`: exit 3, one line on stderr naming the file
  // and containing `why`, and the run directory exactly as before.
  void expect_resume_refused(const std::string& bytes, const std::string& why) {
    write_text(dir_ / "run/evaluations.bin", bytes);
    const std::vector<std::string> before = list_tree(dir_);
    const std::string controls = read_text(dir_ / "run/controls.bin");
    const std::string report = read_text(dir_ / "run/report.json");
    // stderr only (a stage mismatch is found when that stage begins, after the earlier stages' replay lines).
    const CliResult r = run_in("( timeout -s KILL 60 '" KEYFRAME_BINARY "' optimize --resume run 2>&1 >/dev/null )", dir_);
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(r.output.rfind("keyframe: error: run/evaluations.bin: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
    EXPECT_EQ(list_tree(dir_), before);
    EXPECT_TRUE(read_text(dir_ / "run/controls.bin") == controls);
    EXPECT_TRUE(read_text(dir_ / "run/report.json") == report);
    EXPECT_TRUE(read_text(dir_ / "run/evaluations.bin") == bytes);
  }
  std::string tape_;
  TapeLayout layout_;
};

TEST_F(TapeTrust, OneFlippedByteOfAFinishedStagedRunIsRefusedByItsChecksum) {
  // A byte of a later stage's objective, point or gradient: the file still decodes, only the checksum sees it.
  const auto& rec = later_record();
  for (const size_t offset : {rec.phi + 2, rec.gradient - 5, rec.gradient + 3, tape_.size() - 9}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    std::string b = tape_;
    b[offset] ^= 0x10;
    expect_resume_refused(b, "checksum mismatch");
  }
  // A byte of the structure (the stage count, a stage's kind, a record's stage, a term count, the checksum
  // itself): refused too, as soon as the reader meets it.
  for (const size_t offset : {size_t(8), layout_.stage_table + 20 + 9, rec.phi - 4, rec.phi + 21, tape_.size() - 1}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    std::string b = tape_;
    b[offset] ^= 0x10;
    expect_resume_refused(b, "");
  }
}

TEST_F(TapeTrust, NonFiniteObjectiveGradientOrTermWithAMatchingChecksumIsRefused) {
  const auto& rec = later_record();
  ASSERT_GT(rec.terms, 0u);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const auto& [offset, value] : std::vector<std::pair<size_t, double>>{
           {rec.phi, nan}, {rec.phi, inf}, {rec.gradient, -inf}, {rec.gradient + 8, nan},
           {rec.first_term_value, nan}, {rec.first_term_value, inf}}) {
    SCOPED_TRACE("offset " + std::to_string(offset) + " value " + std::to_string(value));
    std::string b = tape_;
    put_double(b, offset, value);
    expect_resume_refused(with_matching_checksum(b), "non-finite");
  }
}

TEST_F(TapeTrust, AStageThePlanDoesNotGiveIsRefused) {
  // Stage 2's first frame and then its substeps changed, checksum matching: the records still decode (the
  // control count is unchanged) but the run's plan gives stage 2 another definition.
  for (const size_t field : {size_t(12), size_t(16)}) {
    std::string b = tape_;
    const size_t offset = layout_.stage_table + 20 + field;
    b[offset] = char(b[offset] + 1);
    expect_resume_refused(with_matching_checksum(b), "stage 2 was recorded with");
  }
  // A record moved to a stage the table does not define.
  std::string b = tape_;
  const std::uint32_t beyond = std::uint32_t(layout_.stage_controls.size());
  std::memcpy(b.data() + layout_.records.back().phi - 4, &beyond, 4);
  expect_resume_refused(with_matching_checksum(b), "which it does not define");
}

}  // namespace
}  // namespace kf::reliability
