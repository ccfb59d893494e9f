#include "scene/run_name.h"

#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/file_name.h"

namespace kf {
namespace fs = std::filesystem;

std::optional<RunName> read_run_name(const fs::path& run_dir) {
  const fs::path file = run_dir / "scene_name.txt";
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  if (!fs::is_regular_file(file, ec)) throw InputError(file.string() + ": not a file");
  if (fs::file_size(file, ec) > 8192) throw InputError(file.string() + ": longer than 8192 bytes (expected two lines)");
  std::ifstream in(file, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string lines[2];
  size_t start = 0;
  for (int k = 0; k < 2 && start < text.size(); ++k) {
    const size_t end = text.find('\n', start);
    lines[k] = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    start = end == std::string::npos ? text.size() : end + 1;
  }
  if (start < text.size()) throw InputError(file.string() + ": more than two lines (expected the scene's name and its directory)");
  RunName r{lines[0], lines[1]};
  if (const std::string why = file_name_problem(r.name); !why.empty())
    throw InputError(file.string() + ": line 1: the scene's name " + why + ", got \"" + printable(r.name) +
                     "\" (it names files inside the run directory)");
  if (has_control_character(lines[1]))
    throw InputError(file.string() + ": line 2: the scene's directory contains a control character, got \"" +
                     printable(lines[1]) + "\"");
  return r;
}

}  // namespace kf
