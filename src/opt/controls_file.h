#pragma once
// controls.bin: the optimisation variables z of a run, so a run can be resumed or re-simulated.
// Format: 8-byte magic "KFCTRL01", uint64 count, uint32 substeps they were made for, then count float64.
#include <filesystem>

#include "core/types.h"

namespace kf {

void save_controls(const std::filesystem::path& path, const VecX& z, int substeps);
// Throws InputError naming the file when it is missing, truncated or not a controls file.
VecX load_controls(const std::filesystem::path& path, int* substeps = nullptr);

}  // namespace kf
