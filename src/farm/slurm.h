#pragma once
// Slurm from keyframe's side: #SBATCH lines for the user's options, submitting scripts with sbatch.
#include <filesystem>
#include <string>
#include <vector>

namespace kf::slurm {

// What every job of one submission asks of the cluster; empty fields are left to the cluster's defaults.
struct JobOptions {
  std::string partition, account, time, mem, constraint;
  std::vector<std::string> extra;  // further sbatch options, verbatim ("--qos=high", "--gres=gpu:1")
};

// Throws InputError for an option that cannot be an #SBATCH line (not starting with '-', a line break or
// another control character).
void check(const JobOptions& options);

// Throws InputError "OPTION: contains a control character, got \"...\" (a job script cannot hold it)" when
// `value` (a path or name written into a job script) holds a newline or another control character: a
// newline would end the comment or #SBATCH line it is on and start a command of its own.
void check_script_text(const std::string& option, const std::string& value);

// One "#SBATCH --option=value\n" line per option given, in a fixed order, the extras last.
std::string sbatch_lines(const JobOptions& options);

// `name` as a job name: letters, digits, '.', '_', '-' kept, anything else (spaces, quotes) as '_'.
std::string job_name(const std::string& name);

// A word quoted for bash when it needs to be ('...' with ' written as '\'').
std::string shell_quote(const std::string& word);

// The sbatch program on PATH. Throws InputError (nothing submitted) when Slurm's commands are missing.
std::filesystem::path require_sbatch();

// Submits `script` through `sbatch --parsable ARGS SCRIPT` and returns the job id. Throws OutputError with
// sbatch's own message when it refuses the job.
std::string submit(const std::filesystem::path& sbatch, const std::vector<std::string>& args,
                   const std::filesystem::path& script);

// Cancels job `id` with scancel beside `sbatch` (best effort: when a dependent submission failed).
void cancel(const std::filesystem::path& sbatch, const std::string& id);

}  // namespace kf::slurm
