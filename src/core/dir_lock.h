#pragma once
// An advisory lock on a run directory (flock on the directory itself, so no lock file appears in it):
// exclusive for a command that replaces the directory or its frames, shared for one that adds single files
// beside others (farm render tasks, each a range of frames). It never waits: a second command gets an
// error at once instead of queueing behind a long optimisation.
#include <filesystem>

namespace kf {

class DirLock {
 public:
  enum class Mode { kShared, kExclusive };
  DirLock() = default;
  // Throws OutputError "DIR: in use by another keyframe command (...)" when the directory is locked
  // incompatibly, or "DIR: cannot lock (...)" when it cannot be opened.
  DirLock(const std::filesystem::path& dir, Mode mode);
  DirLock(DirLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  DirLock& operator=(DirLock&& o) noexcept;
  DirLock(const DirLock&) = delete;
  DirLock& operator=(const DirLock&) = delete;
  ~DirLock();

 private:
  int fd_ = -1;
};

}  // namespace kf
