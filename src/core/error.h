#pragma once
// Errors that reach the user as one line and a documented exit code.
#include <stdexcept>
#include <string>

namespace kf {

// Exit codes of the keyframe command (documented in README.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitDifferent = 1,    // keyframe compare: some frame differs from its reference beyond the thresholds
  kExitUsage = 2,        // bad command line
  kExitInput = 3,        // bad scene file, asset or run directory
  kExitOutput = 4,       // an output could not be written
  kExitNotReady = 5,     // a subcommand that is not available yet
  kExitInterrupted = 6,  // stopped by SIGINT, SIGTERM, SIGHUP or SIGQUIT after saving what it had
  kExitNotReached = 7,   // optimize, run: the keyframes were not reached (run directory written, report.json says why)
  kExitInternal = 10,    // a bug: an unexpected exception
};

// A problem with what the user gave us: "file: /json/pointer: what was expected".
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A problem writing results (disk full, directory not writable).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace kf
