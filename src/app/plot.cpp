#include "app/plot.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <iostream>
#include <vector>

namespace kf {
namespace fs = std::filesystem;

namespace {
// A gnuplot single-quoted string: a quote inside is written twice.
std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

// The name of column `col` (1-based) in the CSV's header row, or "" if it has none.
std::string column_name(const fs::path& csv, int col) {
  std::ifstream in(csv);
  std::string header, name;
  std::getline(in, header);
  std::istringstream cells(header);
  for (int k = 1; std::getline(cells, name, ','); ++k)
    if (k == col) return name;
  return "";
}
}  // namespace

bool plot_csv(const fs::path& csv, const fs::path& png, const std::string& title, int x_col,
              const std::vector<int>& y_cols, bool log_y, bool log_x) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
    std::cerr << "keyframe: note: gnuplot is not installed; skipped " << png.string() << "\n";
    return false;
  }
  const fs::path tmp = png.parent_path() / ("." + png.filename().string() + ".tmp.png");
  std::string script = "set terminal pngcairo size 900,540 font 'DejaVu Sans,11'\n";
  script += "set output " + quoted(tmp.string()) + "\n";
  // Plain text labels: column names such as grad_norm must not turn into subscripts.
  script += "set termoption noenhanced\nset datafile separator ','\nset key autotitle columnhead\nset grid\n";
  script += "set title " + quoted(title) + "\nset xlabel " + quoted(column_name(csv, x_col)) + "\n";
  if (log_y) script += "set logscale y\nset format y '%.0e'\n";
  if (log_x) script += "set logscale x\n";
  script += "plot ";
  for (size_t k = 0; k < y_cols.size(); ++k)
    script += (k ? ", " : "") + (quoted(csv.string()) + " using " + std::to_string(x_col) + ":" +
                                 std::to_string(y_cols[k]) + " with linespoints lw 2 pt 7 ps 0.8");
  script += "\n";
  FILE* gp = popen("gnuplot 2>/dev/null", "w");
  if (!gp) return false;
  std::fwrite(script.data(), 1, script.size(), gp);
  const int rc = pclose(gp);
  std::error_code ec;
  if (rc != 0 || !fs::exists(tmp)) {
    fs::remove(tmp, ec);
    std::cerr << "keyframe: note: gnuplot failed; skipped " << png.string() << "\n";
    return false;
  }
  fs::rename(tmp, png, ec);
  return !ec;
}

}  // namespace kf
