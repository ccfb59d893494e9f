#include "farm/slurm.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <regex>

#include "core/error.h"
#include "core/file_name.h"
#include "render/clip/make_clip.h"

extern char** environ;

namespace kf::slurm {
namespace fs = std::filesystem;

namespace {

// Runs `program ARGS`, stdout and stderr into `output`; returns the exit status (127: could not start).
int run_capture(const fs::path& program, const std::vector<std::string>& args, std::string& output) {
  std::vector<std::string> all{program.string()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  int fd[2];
  if (pipe(fd) != 0) return 127;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fd[1], 1);
  posix_spawn_file_actions_adddup2(&actions, fd[1], 2);
  posix_spawn_file_actions_addclose(&actions, fd[0]);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fd[1]);
  char buf[4096];
  ssize_t n;
  while ((n = read(fd[0], buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR))
    if (n > 0) output.append(buf, size_t(n));
  close(fd[0]);
  if (spawned != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

}  // namespace

void check(const JobOptions& o) {
  const std::pair<const char*, const std::string*> named[] = {
      {"--partition", &o.partition}, {"--account", &o.account}, {"--time", &o.time},
      {"--mem", &o.mem},             {"--constraint", &o.constraint}};
  for (const auto& [name, value] : named)
    if (value->find_first_of("\n\r") != std::string::npos)
      throw InputError(std::string(name) + ": expected one line, got a line break");
    else
      check_script_text(name, *value);
  for (const auto& e : o.extra)
    if (e.size() < 2 || e[0] != '-' || has_control_character(e))
      throw InputError("--sbatch: expected one sbatch option such as --qos=high, got \"" + printable(e) + "\"");
}

void check_script_text(const std::string& option, const std::string& value) {
  if (has_control_character(value))
    throw InputError(option + ": contains a control character, got \"" + printable(value) +
                     "\" (a job script cannot hold it)");
}

std::string sbatch_lines(const JobOptions& o) {
  std::string s;
  const std::pair<const char*, const std::string*> named[] = {
      {"partition", &o.partition}, {"account", &o.account}, {"time", &o.time},
      {"mem", &o.mem},             {"constraint", &o.constraint}};
  for (const auto& [name, value] : named)
    if (!value->empty()) s += "#SBATCH --" + std::string(name) + "=" + *value + "\n";
  for (const auto& e : o.extra) s += "#SBATCH " + e + "\n";
  return s;
}

std::string job_name(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_' ? c : '_';
  return out;
}

std::string shell_quote(const std::string& word) {
  static const std::regex plain(R"([A-Za-z0-9_@%+=:,./-]+)");
  if (std::regex_match(word, plain)) return word;
  std::string q = "'";
  for (char c : word) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

fs::path require_sbatch() {
  fs::path sbatch = render::find_program("sbatch");
  if (sbatch.empty())
    throw InputError("no Slurm here: sbatch is not on PATH (install Slurm's client commands, e.g. Debian's "
                     "slurm-client, or use --dry-run to print the scripts); nothing submitted");
  return sbatch;
}

std::string submit(const fs::path& sbatch, const std::vector<std::string>& args, const fs::path& script) {
  std::vector<std::string> all{"--parsable"};
  all.insert(all.end(), args.begin(), args.end());
  all.push_back(script.string());
  std::string out;
  const int status = run_capture(sbatch, all, out);
  // --parsable prints "JOBID" or "JOBID;CLUSTER" (after any warnings).
  std::smatch m;
  static const std::regex id(R"((?:^|\n)(\d+)(?:;[^\n]*)?\n?$)");
  if (status != 0 || !std::regex_search(out, m, id))
    throw OutputError("sbatch refused " + script.string() + " (status " + std::to_string(status) + "): " +
                      one_line(out));
  return m[1];
}

void cancel(const fs::path& sbatch, const std::string& id) {
  const fs::path scancel = sbatch.parent_path() / "scancel";
  std::string out;
  if (!id.empty() && access(scancel.c_str(), X_OK) == 0) run_capture(scancel, {id}, out);
}

}  // namespace kf::slurm
