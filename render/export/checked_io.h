#pragma once
// An assimp IOSystem whose every file is written whole or not at all and whose failures are kept: assimp's
// own exporters report success when a write fails (a full disk left 0-byte OBJ files behind "exported").
#include <assimp/IOSystem.hpp>
#include <string>

namespace kf::render {

class CheckedIOSystem final : public Assimp::IOSystem {
 public:
  bool Exists(const char* file) const override;
  char getOsSeparator() const override { return '/'; }
  // Write modes only ("w", "wb", "wt"): the stream collects the bytes and writes them atomically when it is
  // closed or deleted.
  Assimp::IOStream* Open(const char* file, const char* mode = "rb") override;
  void Close(Assimp::IOStream* stream) override;
  // The first failure ("FILE: write failed (...)"), empty when every file was written.
  const std::string& first_error() const { return first_error_; }

 private:
  std::string first_error_;
};

}  // namespace kf::render
