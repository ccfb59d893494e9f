#pragma once
// The names a test of the real `keyframe` binary works with (tests/reliability/cli_harness.h: a temp
// directory per test, the command's exit code and output, files read back), for `using namespace
// cli_test;` inside the test's namespace.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "../reliability/cli_harness.h"

namespace kf::cli_test {
namespace fs = std::filesystem;
using Json = nlohmann::json;
using reliability::read_text;
using reliability::run_keyframe;
using reliability::TempDirTest;
}  // namespace kf::cli_test
