#include "report/plot.h"

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

namespace {

// Runs a gnuplot script that writes `tmp`, then renames it to `png` (whole or not at all).
bool run_gnuplot(const std::string& script, const fs::path& tmp, const fs::path& png) {
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

bool have_gnuplot(const fs::path& png) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) return true;
  std::cerr << "keyframe: note: gnuplot is not installed; skipped " << png.string() << "\n";
  return false;
}

fs::path temporary_for(const fs::path& png) { return png.parent_path() / ("." + png.filename().string() + ".tmp.png"); }

// Terminal, output and the settings every plot shares.
std::string preamble(const fs::path& tmp, const std::string& title, bool log_y) {
  std::string script = "set terminal pngcairo size 900,540 font 'DejaVu Sans,11'\n";
  script += "set output " + quoted(tmp.string()) + "\n";
  // Plain text labels: column names such as grad_norm must not turn into subscripts.
  script += "set termoption noenhanced\nset datafile separator ','\nset key autotitle columnhead\nset grid\n";
  script += "set title " + quoted(title) + "\n";
  if (log_y) script += "set logscale y\nset format y '%.0e'\n";
  return script;
}

}  // namespace

bool plot_csv(const fs::path& csv, const fs::path& png, const std::string& title, int x_col,
              const std::vector<int>& y_cols, bool log_y, bool log_x) {
  if (!have_gnuplot(png)) return false;
  const fs::path tmp = temporary_for(png);
  std::string script = preamble(tmp, title, log_y);
  script += "set xlabel " + quoted(column_name(csv, x_col)) + "\n";
  if (log_x) script += "set logscale x\n";
  script += "plot ";
  for (size_t k = 0; k < y_cols.size(); ++k)
    script += (k ? ", " : "") + (quoted(csv.string()) + " using " + std::to_string(x_col) + ":" +
                                 std::to_string(y_cols[k]) + " with linespoints lw 2 pt 7 ps 0.8");
  script += "\n";
  return run_gnuplot(script, tmp, png);
}

bool bar_plot_csv(const fs::path& csv, const fs::path& png, const std::string& title,
                  const std::vector<int>& label_cols, const std::vector<int>& y_cols, bool log_y) {
  if (!have_gnuplot(png)) return false;
  const fs::path tmp = temporary_for(png);
  std::string script = preamble(tmp, title, log_y);
  script += "set style data histograms\nset style histogram clustered gap 1\nset style fill solid 0.8 border -1\n";
  script += "set xtics rotate by -30\nset boxwidth 0.9\n";
  std::string label;
  for (size_t k = 0; k < label_cols.size(); ++k)
    label += (k ? ".' '." : "") + std::string("stringcolumn(") + std::to_string(label_cols[k]) + ")";
  script += "plot ";
  for (size_t k = 0; k < y_cols.size(); ++k)
    script += (k ? ", " : "") + quoted(csv.string()) + " using " + std::to_string(y_cols[k]) +
              (k == 0 ? ":xtic(" + label + ")" : "");
  script += "\n";
  return run_gnuplot(script, tmp, png);
}

}  // namespace kf
