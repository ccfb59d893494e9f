#pragma once
// Running the real `keyframe` binary with its standard output read as it comes, and a SIGINT sent after a
// number of evaluation lines (what a user's Ctrl-C does mid-run).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace kf::test {

// `keyframe ARGS` started in `dir`, its standard output on a pipe read as it comes.
struct KeyframeChild {
  pid_t pid = -1;
  FILE* out = nullptr;  // the child's standard output
};

inline KeyframeChild start_keyframe(const std::filesystem::path& dir, const std::vector<std::string>& args) {
  int fds[2];
  EXPECT_EQ(pipe(fds), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    if (chdir(dir.c_str()) != 0) _exit(120);
    std::vector<char*> argv{const_cast<char*>(KEYFRAME_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(KEYFRAME_BINARY, argv.data());
    _exit(127);
  }
  close(fds[1]);
  return {pid, fdopen(fds[0], "r")};
}

// Closes its output and waits for it: the exit code, or 128 + the signal that ended it.
inline int wait_for(KeyframeChild& child) {
  fclose(child.out);
  int status = 0;
  waitpid(child.pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Runs `keyframe ARGS` in `dir`; when interrupt_after > 0, sends SIGINT after that many evaluation lines.
// Returns the exit code, or 128 + the signal that ended it.
inline int run_keyframe_interrupted(const std::filesystem::path& dir, const std::vector<std::string>& args,
                                    int interrupt_after = 0) {
  KeyframeChild child = start_keyframe(dir, args);
  char line[4096];
  int lines = 0;
  while (fgets(line, sizeof line, child.out)) {
    const std::string l(line);
    if (l.find(" eval ") != std::string::npos || l.rfind("eval", 0) == 0) ++lines;
    if (interrupt_after > 0 && lines == interrupt_after) kill(child.pid, SIGINT);
  }
  return wait_for(child);
}

}  // namespace kf::test
