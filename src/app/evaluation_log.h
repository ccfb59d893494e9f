#pragma once
// What `optimize` says and what it evaluates: every line goes to log.txt and, unless quiet, to stdout (a
// quiet run shows a progress line instead); every evaluation also goes to the history (iterations.csv).
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/progress.h"
#include "opt/strategy.h"

namespace kf {

struct HistoryRow {
  int stage, substeps;
  double seconds;
  EvaluationRecord rec;
};

class EvaluationLog final : public StrategyLog {
 public:
  EvaluationLog(bool quiet, std::string label) : quiet_(quiet), label_(std::move(label)) {}
  void say(const std::string& line) override;
  void evaluation(int stage_id, int substeps, double seconds_before, const EvaluationRecord& r) override;
  void stage_started(int max_evaluations) override { progress_.emplace(label_, max_evaluations); }
  void stage_finished() override {
    if (progress_) progress_->finish();
  }
  const std::vector<HistoryRow>& history() const { return history_; }
  std::string text() const { return log_.str(); }

 private:
  bool quiet_;
  std::string label_;  // the progress line's
  std::ostringstream log_;
  std::vector<HistoryRow> history_;
  std::optional<Progress> progress_;
};

// iterations.csv: one row per evaluation, with each term named in `names` (NaN where the trial diverged).
void write_history_csv(const std::filesystem::path& path, const std::vector<HistoryRow>& rows,
                       const std::vector<std::pair<std::string, double>>& names);

}  // namespace kf
