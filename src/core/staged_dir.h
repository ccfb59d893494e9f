#pragma once
// A directory replaced whole or not at all: a command writes its new contents into a hidden directory
// beside the target (".NAME.new-PID") and swaps it in only when everything was written (renameat2
// RENAME_EXCHANGE, one atomic step), so readers see the old directory or the new one, never a mix, and a
// command that fails leaves the old one as it was. The target is locked (DirLock, exclusive) meanwhile.
#include <filesystem>
#include <functional>
#include <string>

#include "core/dir_lock.h"

namespace kf {

class StagedDir {
 public:
  // Locks `target` when it exists and creates the empty staging directory beside it (and the parents).
  // Removes staging directories that killed commands left beside the target. Throws OutputError
  // ("TARGET: cannot create directory: ...", "TARGET: in use by another keyframe command ...") and
  // InputError when `target` names no directory of its own ("." or "..").
  explicit StagedDir(std::filesystem::path target);
  ~StagedDir();  // removes the staging directory unless committed
  StagedDir(const StagedDir&) = delete;
  StagedDir& operator=(const StagedDir&) = delete;

  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  bool target_existed() const { return existed_; }

  // Copies the target's regular top-level files whose names `keep` accepts into the staging directory
  // (a resumed run continues from its own files). Throws OutputError.
  void copy_from_target(const std::function<bool(const std::string&)>& keep);
  // Puts the staging directory in the target's place and removes the old contents. Throws OutputError.
  void commit();
  // `message` with the staging directory's path replaced by the target's, so errors name what the user named.
  std::string public_message(const std::string& message) const;

 private:
  std::filesystem::path target_, staging_;
  bool existed_ = false, committed_ = false;
  DirLock lock_;
};

}  // namespace kf
