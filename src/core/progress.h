#pragma once
// A one-line progress display on stderr for long work; silent when stderr is not a terminal.
#include <chrono>
#include <string>

namespace kf {

class Progress {
 public:
  Progress(std::string label, long total);
  ~Progress();
  void update(long done, const std::string& detail = {});
  void finish();
  static void set_enabled(bool on);  // force off (tests) or on

 private:
  std::string label_;
  long total_;
  bool active_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace kf
