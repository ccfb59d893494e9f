// Decisions outside src/scene/ read types, not text: no file under src/ but the scene layer compares a
// control kind's name, an optimiser's status text, a strategy's (or split schedule's) name, a solver choice
// (the cloth adjoint, the CG preconditioner), the effort term's name or a keyframe judgement's text. The names
// are read once in src/scene/ into enums (ControlKind, StagingStrategy, SplitSchedule, AdjointKind,
// CgPreconditioner), the optimiser gives a StopReason beside its status text, the effort is told by its place
// in the breakdown (opt/term_breakdown.h), and a keyframe's judgement says what its error is
// (KeyframeJudgement::from_target). A line-based scan: each pattern below is one way such a comparison is
// written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace kf {
namespace {

namespace fs = std::filesystem;

const char* const kControlKinds =
    "per_step|per_frame|initial_velocity|initial_rigid_velocity|initial_lattice_velocity|per_frame_lattice";
// optimizer.adjoint and cloth.cg_preconditioner (scene/solver_choices.h; "auto" is left out: the benchmarks'
// own --solver tokens use it), and the effort term's name in Problem::breakdown().
const char* const kChoiceNames = "exact|swap|incomplete_cholesky|multigrid|block_jacobi|effort";
const char* const kStatusWords =
    "converged|stopped|interrupted|evaluation limit|time limit|limit reached|keyframes reached|line search|"
    "no optimisation";

const std::vector<std::regex>& patterns() {
  static const std::vector<std::regex> p = [] {
    const std::string kinds = std::string(kControlKinds) + "|" + kChoiceNames, statuses = kStatusWords;
    return std::vector<std::regex>{
        // a == "per_frame", a != std::string("initial_velocity"), name == "multigrid", name != "effort"
        std::regex("(==|!=)\\s*(std::string\\()?\"(" + kinds + ")\""),
        std::regex("\"(" + kinds + ")\"\\s*(==|!=)"),
        // s.rfind("initial", 0), status.find("limit reached"), s.compare("converged"), s.starts_with("per_")
        std::regex("\\.(r?find|compare|starts_with|ends_with)\\(\\s*\"(initial|per_|" + kinds + "|" + statuses + ")"),
        // status == "...", res.status != kKeyframesReached, o.strategy == "single", split_schedule == "held"
        std::regex("\\b(status|strategy|split_schedule)\\w*(\\(\\))?\\s*(==|!=)\\s*(\"|std::string|k[A-Z])"),
        std::regex("\"(" + statuses + ")[^\"]*\"\\s*(==|!=)"),
        std::regex("(==|!=)\\s*kKeyframesReached"),
        // a keyframe judged by its text: worst.tolerance.find("inside"), k.error_after.rfind("rank", 0)
        std::regex("\\b(tolerance|error_before|error_after)\\.(r?find|compare|starts_with|ends_with)\\("),
    };
  }();
  return p;
}

// The lines of `text` (1-based numbers) that compare a name by text.
std::vector<int> string_decisions(const std::string& text) {
  std::vector<int> found;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const size_t comment = line.find("//");
    const std::string code = comment == std::string::npos ? line : line.substr(0, comment);
    for (const std::regex& r : patterns())
      if (std::regex_search(code, r)) {
        found.push_back(n);
        break;
      }
  }
  return found;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(StringDecisions, ScanFindsEachWayOfComparingByName) {
  // Lines of the kind the strategy, the problem and the throw search once decided by.
  const std::vector<std::string> bad = {
      R"(if (res.status.rfind("stopped: line search", 0) != 0 || left < 3) break;)",
      R"(f.budget = status.find("limit reached") != std::string::npos;)",
      R"(single.status.rfind("converged", 0) == 0)",
      R"(for (; job.status != kKeyframesReached; ++s))",
      R"(if (std::string(controls_.kind()).rfind("initial", 0) == 0) return 1.0;)",
      R"(if (problem.controls().kind() != std::string("initial_rigid_velocity")))",
      R"(if (problem.last_diverged() || (kind != "per_step" && kind != "per_frame")) return 0;)",
      R"(if (o.strategy == "single" || !scene.cloth) return plan;)",
      R"(job.hold_splits = scene.cloth && scene.optimizer.split_schedule == "held";)",
      R"(if (worst.tolerance.find("inside") != std::string::npos))",
      // the solver choices and the effort term, as the cloth system, the strategy and the report decided
      R"(if (name == "multigrid" || (name == "auto" && particles >= kMultigridFrom)) return Preconditioner::kMultigrid;)",
      R"(if (name == "block_jacobi") return Preconditioner::kBlockJacobi;)",
      R"(if (name == "exact") return AdjointKind::kExact;)",
      R"(if (name == "swap") return AdjointKind::kSwap;)",
      R"(if (terms.empty() || terms.back().first != "effort") return INFINITY;)",
      R"(if (name != "effort") sum += value;)",
      R"(if (name == "effort") effort_end = value;)",
  };
  for (const std::string& line : bad) EXPECT_EQ(string_decisions(line).size(), 1u) << line;
  const std::vector<std::string> good = {
      R"(if (res.reason != StopReason::kLineSearchStalled || left < 3) break;)",
      R"(if (o.strategy == StagingStrategy::kSingle) return plan;)",
      R"(os << "status " << r.status;  // "converged" == "converged")",
      R"(if (!worst.from_target))",
      R"(sys->set_adjoint(scene.optimizer.adjoint);)",
      R"(if (!last_effort(problem)) return INFINITY;)",
      R"(os << adjoint_name(adjoint_) << " adjoint";)",
      R"(case Preconditioner::kBlockJacobi: return "block_jacobi";)",
      R"(breakdown_.emplace_back("effort", e);)",
  };
  for (const std::string& line : good) EXPECT_TRUE(string_decisions(line).empty()) << line;
}

TEST(StringDecisions, NoNameIsComparedOutsideTheSceneLayer) {
  const fs::path root = fs::path(KEYFRAME_SOURCE_DIR) / "src";
  ASSERT_TRUE(fs::is_directory(root)) << root;
  std::vector<fs::path> paths;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file() && (e.path().extension() == ".cpp" || e.path().extension() == ".h") &&
        fs::relative(e.path(), root).begin()->string() != "scene")
      paths.push_back(e.path());
  std::sort(paths.begin(), paths.end());
  EXPECT_GT(paths.size(), 100u);  // the scan saw the sources
  std::string list;
  for (const fs::path& p : paths)
    for (int line : string_decisions(read_text(p)))
      list += "\n  " + fs::relative(p, root.parent_path()).string() + ":" + std::to_string(line);
  EXPECT_TRUE(list.empty()) << "names compared as text outside src/scene/ (read them into a type there):" << list;
}

}  // namespace
}  // namespace kf
