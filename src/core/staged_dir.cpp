#include "core/staged_dir.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.h"

namespace kf {
namespace fs = std::filesystem;

namespace {
std::string staging_prefix(const fs::path& target) { return "." + target.filename().string() + ".new-"; }

// Staging directories of processes that no longer run (killed before they committed or cleaned up).
void remove_abandoned(const fs::path& parent, const std::string& prefix) {
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    char* tail = nullptr;
    const long pid = std::strtol(name.c_str() + prefix.size(), &tail, 10);
    if (pid <= 0 || *tail != '\0' || pid == ::getpid()) continue;
    if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
}
}  // namespace

StagedDir::StagedDir(fs::path target) : target_(std::move(target)) {
  if (!target_.empty() && target_.filename().empty()) target_ = target_.parent_path();  // "run/" -> "run"
  const std::string name = target_.filename().string();
  if (target_.empty() || name == "." || name == "..")
    throw InputError("\"" + target_.string() + "\" names no directory of its own; name a run directory such as out/run");
  const fs::path parent = target_.parent_path();  // may be empty: the current directory
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(target_, ec);
  existed_ = fs::exists(st);
  if (existed_ && !fs::is_directory(fs::status(target_, ec)))
    throw OutputError(target_.string() + ": cannot create directory: " + std::make_error_code(std::errc::file_exists).message());
  if (existed_ && fs::is_symlink(st))
    throw OutputError(target_.string() + ": is a symbolic link; name the directory it points to");
  ec.clear();
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec || (!parent.empty() && !fs::is_directory(parent)))
    throw OutputError(target_.string() + ": cannot create directory: " +
                      (ec ? ec.message() : std::make_error_code(std::errc::not_a_directory).message()));
  if (existed_) lock_ = DirLock(target_, DirLock::Mode::kExclusive);
  remove_abandoned(parent.empty() ? fs::path(".") : parent, staging_prefix(target_));
  staging_ = parent / (staging_prefix(target_) + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  if (::mkdir(staging_.c_str(), 0777) != 0)
    throw OutputError(target_.string() + ": cannot create directory: " + std::strerror(errno));
}

StagedDir::~StagedDir() {
  std::error_code ec;
  if (!committed_) fs::remove_all(staging_, ec);
}

void StagedDir::copy_from_target(const std::function<bool(const std::string&)>& keep) {
  if (!existed_) return;
  std::error_code ec;
  for (fs::directory_iterator it(target_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code type_ec;
    if (name.empty() || name[0] == '.' || !it->is_regular_file(type_ec) || !keep(name)) continue;
    std::error_code copy_ec;
    fs::copy_file(it->path(), staging_ / name, fs::copy_options::overwrite_existing, copy_ec);
    if (copy_ec) throw OutputError((target_ / name).string() + ": cannot copy for the new run: " + copy_ec.message());
  }
  if (ec) throw OutputError(target_.string() + ": cannot list: " + ec.message());
}

void StagedDir::commit() {
  const int flags = existed_ ? RENAME_EXCHANGE : RENAME_NOREPLACE;
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), unsigned(flags)) != 0) {
    const int err = errno;
    if (!existed_ && (err == EEXIST || err == ENOTEMPTY))
      throw OutputError(target_.string() + ": created by another command meanwhile; nothing of this run was kept");
    throw OutputError(target_.string() + ": cannot put the new directory in place: " + std::strerror(err));
  }
  committed_ = true;
  // After the exchange the staging path holds the old contents.
  std::error_code ec;
  if (existed_) fs::remove_all(staging_, ec);
}

std::string StagedDir::public_message(const std::string& message) const {
  std::string out = message;
  const std::string from = staging_.string(), to = target_.string();
  for (size_t pos = out.find(from); pos != std::string::npos; pos = out.find(from, pos + to.size()))
    out.replace(pos, from.size(), to);
  return out;
}

}  // namespace kf
