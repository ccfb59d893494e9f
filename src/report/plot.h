#pragma once
// Line plots through gnuplot (Debian's gnuplot-nox), written whole or not at all.
#include <filesystem>
#include <string>
#include <vector>

namespace kf {

// Plots columns of a CSV (first row = names) against column `x_col` with a log-scaled y axis.
// Returns false with a message on stderr when gnuplot is not installed or fails.
bool plot_csv(const std::filesystem::path& csv, const std::filesystem::path& png, const std::string& title,
              int x_col, const std::vector<int>& y_cols, bool log_y = true, bool log_x = false);

// Bar chart: one group of bars per CSV row (labelled by the cells of `label_cols` joined with spaces), one bar
// per column of `y_cols`. Same failure behaviour as plot_csv.
bool bar_plot_csv(const std::filesystem::path& csv, const std::filesystem::path& png, const std::string& title,
                  const std::vector<int>& label_cols, const std::vector<int>& y_cols, bool log_y = true);

}  // namespace kf
