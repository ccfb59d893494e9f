#include "render/export/checked_io.h"

#include <assimp/IOStream.hpp>

#include <cstring>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf::render {

namespace {
// Collects a file's bytes and writes them atomically when assimp is done with it. Assimp's exporters
// delete their streams themselves (not always through IOSystem::Close), so the write is in the destructor,
// and its failure goes to `error`.
class MemoryWriteStream final : public Assimp::IOStream {
 public:
  MemoryWriteStream(std::string path, std::string& error) : path_(std::move(path)), error_(error) {}
  ~MemoryWriteStream() override {
    try {
      write_file_atomic(path_, bytes_);
    } catch (const OutputError& e) {
      if (error_.empty()) error_ = e.what();
    }
  }
  size_t Read(void*, size_t, size_t) override { return 0; }
  size_t Write(const void* buffer, size_t size, size_t count) override {
    const size_t n = size * count;
    if (pos_ + n > bytes_.size()) bytes_.resize(pos_ + n);
    std::memcpy(bytes_.data() + pos_, buffer, n);
    pos_ += n;
    return count;
  }
  aiReturn Seek(size_t offset, aiOrigin origin) override {
    const size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? pos_ : bytes_.size();
    if (base + offset > bytes_.size()) return aiReturn_FAILURE;
    pos_ = base + offset;
    return aiReturn_SUCCESS;
  }
  size_t Tell() const override { return pos_; }
  size_t FileSize() const override { return bytes_.size(); }
  void Flush() override {}

 private:
  std::string path_, bytes_;
  std::string& error_;
  size_t pos_ = 0;
};
}  // namespace

bool CheckedIOSystem::Exists(const char* file) const { return std::filesystem::exists(file); }

Assimp::IOStream* CheckedIOSystem::Open(const char* file, const char* mode) {
  if (!mode || !std::strchr(mode, 'w')) {
    if (first_error_.empty()) first_error_ = std::string(file) + ": export tried to read a file";
    return nullptr;
  }
  return new MemoryWriteStream(file, first_error_);
}

void CheckedIOSystem::Close(Assimp::IOStream* stream) { delete stream; }

}  // namespace kf::render
