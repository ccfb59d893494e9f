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

}  // namespace kf
