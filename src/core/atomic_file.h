#pragma once
// Files are written whole or not at all: write to a temporary beside the target, flush, rename.
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string_view>

namespace kf {

// Writes `bytes` to `path` atomically. Throws OutputError on any failure (nothing is left behind).
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);

// Calls `fill(stream)` on a temporary file, then renames it to `path`. Throws OutputError on failure.
void write_stream_atomic(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& fill);

// Creates `dir` (and parents). Throws OutputError naming the directory if it cannot.
void ensure_directory(const std::filesystem::path& dir);

}  // namespace kf
