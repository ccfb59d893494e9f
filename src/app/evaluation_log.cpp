#include "app/evaluation_log.h"

#include <cmath>
#include <iomanip>
#include <iostream>

#include "core/atomic_file.h"

namespace kf {

namespace {

std::string format_record(int stage, const EvaluationRecord& r) {
  std::ostringstream os;
  os << (stage > 0 ? "stage " + std::to_string(stage) + " " : "") << "eval " << std::setw(4) << r.evaluation
     << "  phi " << std::scientific << std::setprecision(4) << r.phi << "  |g| " << r.grad_norm;
  for (const auto& [name, value] : r.terms) os << "  " << name << " " << value;
  os << std::fixed << std::setprecision(2) << "  " << r.seconds << " s"
     << (r.unstable ? "  (unstable)" : r.diverged ? "  (diverged)" : "");
  return os.str();
}

}  // namespace

void EvaluationLog::say(const std::string& line) {
  log_ << line << "\n";
  if (!quiet_) std::cout << line << std::endl;
}

void EvaluationLog::evaluation(int stage_id, int substeps, double seconds_before, const EvaluationRecord& r) {
  log_ << format_record(stage_id, r) << "\n";
  if (quiet_) {
    if (progress_) progress_->update(r.evaluation);
  } else {
    std::cout << format_record(stage_id, r) << std::endl;
  }
  history_.push_back({stage_id, substeps, seconds_before + r.seconds, r});
}

void write_history_csv(const std::filesystem::path& path, const std::vector<HistoryRow>& rows,
                       const std::vector<std::pair<std::string, double>>& names) {
  std::ostringstream os;
  os << "evaluation,seconds,phi,grad_norm,stage,substeps";
  for (const auto& t : names) os << "," << t.first;
  os << "\n" << std::setprecision(10);
  int k = 0;
  for (const auto& r : rows) {
    os << ++k << "," << r.seconds << "," << r.rec.phi << "," << r.rec.grad_norm << "," << r.stage << "," << r.substeps;
    // A diverged evaluation has no terms (and no output holds a non-finite value): its cells stay empty.
    for (size_t i = 0; i < names.size(); ++i) {
      os << ",";
      if (i < r.rec.terms.size() && !r.rec.diverged && std::isfinite(r.rec.terms[i].second)) os << r.rec.terms[i].second;
    }
    os << "\n";
  }
  write_file_atomic(path, os.str());
}

}  // namespace kf
