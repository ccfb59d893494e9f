#include "core/dir_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.h"

namespace kf {

DirLock::DirLock(const std::filesystem::path& dir, Mode mode) {
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw OutputError(dir.string() + ": cannot lock (" + std::strerror(errno) + ")");
  if (::flock(fd_, (mode == Mode::kExclusive ? LOCK_EX : LOCK_SH) | LOCK_NB) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK)
      throw OutputError(dir.string() + ": in use by another keyframe command (" +
                        (mode == Mode::kExclusive ? "it is being written or rendered"
                                                  : "it is being rewritten") +
                        "); wait for it to finish or choose another directory");
    throw OutputError(dir.string() + ": cannot lock (" + std::strerror(err) + ")");
  }
}

DirLock& DirLock::operator=(DirLock&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = o.fd_;
    o.fd_ = -1;
  }
  return *this;
}

DirLock::~DirLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace kf
