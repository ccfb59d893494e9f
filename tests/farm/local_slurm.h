#pragma once
// A one-node Slurm cluster on localhost for tests: munged, slurmctld and slurmd from Debian's packages,
// started as root in the foreground as children of the test, everything (key, slurm.conf, state, spool,
// logs, munge socket) in one private directory, on free ports. The destructor cancels the cluster's jobs
// and stops exactly the three daemons it started, even when the test failed.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "../reliability/cli_harness.h"

extern char** environ;

namespace kf::testing {
namespace fs = std::filesystem;

class LocalSlurm {
 public:
  // Starts the cluster in a new private directory and waits until its node is idle. Throws std::runtime_error with
  // what went wrong (and the end of the daemon's log) within about `timeout_s` seconds; whatever was
  // started by then is stopped again.
  explicit LocalSlurm(int timeout_s = 40) {
    // A short private directory: munged's socket path must fit in a sockaddr_un (108 bytes).
    fs::path base = fs::temp_directory_path();
    if (base.string().size() > 60) base = "/tmp";
    std::string templ = (base / "kf-slurm-XXXXXX").string();
    if (!mkdtemp(templ.data())) throw std::runtime_error("local Slurm: cannot create a directory in " + base.string());
    dir_ = templ;
    try {
      start(timeout_s);
    } catch (...) {
      stop();
      throw;
    }
  }
  // Stops the cluster; its directory (configuration, logs) is kept only when the test failed.
  ~LocalSlurm() {
    stop();
    std::error_code ec;
    if (!::testing::Test::HasFailure()) fs::remove_all(dir_, ec);
  }
  const fs::path& dir() const { return dir_; }
  LocalSlurm(const LocalSlurm&) = delete;
  LocalSlurm& operator=(const LocalSlurm&) = delete;

  // Prefix for shell commands that talk to this cluster ("SLURM_CONF=... ").
  std::string env() const { return "SLURM_CONF='" + conf_.string() + "' "; }
  // Runs a Slurm client command (sinfo, squeue, scontrol, ...) against this cluster, at most `timeout_s`.
  reliability::CliResult client(const std::string& command, int timeout_s = 15) const {
    return shell(env() + "timeout " + std::to_string(timeout_s) + " " + command);
  }
  // The daemons' process ids, in start order (munged, slurmctld, slurmd); empty once stopped.
  const std::vector<pid_t>& pids() const { return pids_; }
  std::string log_tail(const std::string& name, size_t lines = 8) const {
    std::ifstream in(dir_ / name);
    std::vector<std::string> all;
    for (std::string line; std::getline(in, line);) all.push_back(line);
    std::string out;
    for (size_t k = all.size() > lines ? all.size() - lines : 0; k < all.size(); ++k) out += "  " + all[k] + "\n";
    return out;
  }

  // Cancels every job of this cluster, then stops the daemons (SIGTERM, SIGKILL after 10 s each).
  void stop() {
    if (pids_.size() >= 2) {  // slurmctld is up: jobs may still run
      client("scancel --user=root", 10);
      for (int k = 0; k < 40 && !client("squeue -h", 5).output.empty(); ++k)
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
    for (auto it = pids_.rbegin(); it != pids_.rend(); ++it) terminate(*it);
    pids_.clear();
  }

  static reliability::CliResult shell(const std::string& command) {
    FILE* p = popen((command + " 2>&1").c_str(), "r");
    std::string out;
    char buf[4096];
    while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = pclose(p);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
  }

 private:
  // Two ports nobody listens on, below Linux's ephemeral range (32768+) so that client connections made
  // meanwhile cannot take them; both are held while the second is found.
  static std::pair<int, int> free_ports() {
    std::mt19937 pick(std::random_device{}());
    std::vector<int> held, ports;
    for (int attempt = 0; attempt < 200 && ports.size() < 2; ++attempt) {
      const int port = 20000 + int(pick() % 12000);
      const int s = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_addr.s_addr = htonl(INADDR_ANY);
      a.sin_port = htons(uint16_t(port));
      if (s >= 0 && bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
        held.push_back(s);
        ports.push_back(port);
      } else if (s >= 0) {
        close(s);
      }
    }
    for (int s : held) close(s);
    if (ports.size() < 2) throw std::runtime_error("local Slurm: cannot find two free TCP ports");
    return {ports[0], ports[1]};
  }

  // Forks `argv` with stdout/stderr into `log`; the child gets SIGTERM if the test process dies.
  pid_t spawn(const std::vector<std::string>& argv, const std::string& log) {
    const int fd = ::open((dir_ / log).c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) throw std::runtime_error("local Slurm: cannot write " + (dir_ / log).string());
    std::vector<std::string> args = argv;
    std::vector<char*> cargs;
    for (auto& a : args) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    // The environment is built before fork: the child only calls async-signal-safe functions.
    std::vector<std::string> env{"SLURM_CONF=" + conf_.string()};
    for (char** e = environ; *e; ++e)
      if (std::string(*e).rfind("SLURM_CONF=", 0) != 0) env.push_back(*e);
    std::vector<char*> cenv;
    for (auto& e : env) cenv.push_back(e.data());
    cenv.push_back(nullptr);
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (getppid() != parent) _exit(127);
      dup2(fd, 1);
      dup2(fd, 2);
      execve(cargs[0], cargs.data(), cenv.data());
      _exit(127);
    }
    close(fd);
    if (pid < 0) throw std::runtime_error("local Slurm: fork failed");
    pids_.push_back(pid);
    return pid;
  }

  // Throws with the end of `log` if `pid` has exited.
  void require_running(pid_t pid, const std::string& name, const std::string& log) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      pids_.erase(std::find(pids_.begin(), pids_.end(), pid));
      const std::string how = WIFEXITED(status) ? "exit code " + std::to_string(WEXITSTATUS(status))
                                                : "signal " + std::to_string(WTERMSIG(status));
      throw std::runtime_error("local Slurm: " + name + " stopped at start (" + how + "); end of " +
                               (dir_ / log).string() + ":\n" + log_tail(log));
    }
  }

  template <class Ready>
  void wait_for(const std::string& what, pid_t pid, const std::string& name, const std::string& log,
                std::chrono::steady_clock::time_point deadline, Ready ready) {
    while (!ready()) {
      require_running(pid, name, log);
      if (std::chrono::steady_clock::now() > deadline)
        throw std::runtime_error("local Slurm: timed out waiting for " + what + "; end of " + (dir_ / log).string() +
                                 ":\n" + log_tail(log));
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }

  void start(int timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_s);
    if (geteuid() != 0)
      throw std::runtime_error("local Slurm: must run as root (slurmd starts jobs as their users), as CI does");
    for (const char* p : {"/usr/sbin/munged", "/usr/sbin/slurmctld", "/usr/sbin/slurmd", "/usr/bin/sbatch"})
      if (access(p, X_OK) != 0)
        throw std::runtime_error(std::string("local Slurm: ") + p +
                                 " is missing (scripts/setup installs slurm-wlm and munge)");
    fs::create_directories(dir_ / "state");
    fs::create_directories(dir_ / "spool");
    fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_exec | fs::perms::others_exec);
    // A private munge key: jobs of this cluster authenticate with nothing else.
    {
      std::random_device rd;
      std::string key(128, '\0');
      for (char& c : key) c = char(rd());
      std::ofstream(dir_ / "munge.key", std::ios::binary) << key;
      fs::permissions(dir_ / "munge.key", fs::perms::owner_read | fs::perms::owner_write);
    }
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    std::string node(host);
    node = node.substr(0, node.find('.'));
    const std::string d = dir_.string();
    const int nproc = int(std::max(1u, std::thread::hardware_concurrency()));
    const auto ports = free_ports();
    conf_ = dir_ / "slurm.conf";
    std::ofstream(conf_) << "ClusterName=kftest\n"
                         << "SlurmctldHost=" << node << "(127.0.0.1)\n"
                         << "SlurmctldPort=" << ports.first << "\nSlurmdPort=" << ports.second << "\n"
                         << "SlurmUser=root\nSlurmdUser=root\n"
                         << "AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket=" << d << "/munge.socket\n"
                         << "StateSaveLocation=" << d << "/state\nSlurmdSpoolDir=" << d << "/spool\n"
                         << "SlurmctldPidFile=" << d << "/slurmctld.pid\nSlurmdPidFile=" << d << "/slurmd.pid\n"
                         << "SlurmctldLogFile=" << d << "/slurmctld.log\nSlurmdLogFile=" << d << "/slurmd.log\n"
                         << "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nSwitchType=switch/none\n"
                         << "MpiDefault=none\nReturnToService=2\nSchedulerType=sched/backfill\n"
                         << "SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n"
                         << "JobCompType=jobcomp/none\nAccountingStorageType=accounting_storage/none\n"
                         << "NodeName=" << node << " NodeAddr=127.0.0.1 CPUs=" << nproc
                         << " RealMemory=1000 State=UNKNOWN\n"
                         << "PartitionName=debug Nodes=" << node << " Default=YES MaxTime=INFINITE State=UP\n";

    const pid_t munged = spawn({"/usr/sbin/munged", "--foreground", "--force", "--socket=" + d + "/munge.socket",
                                "--key-file=" + d + "/munge.key", "--pid-file=" + d + "/munged.pid",
                                "--log-file=" + d + "/munged.log", "--seed-file=" + d + "/munged.seed"},
                               "munged.out");
    wait_for("munged's socket", munged, "munged", "munged.out", deadline,
             [&] { return fs::exists(dir_ / "munge.socket"); });
    const pid_t ctld = spawn({"/usr/sbin/slurmctld", "-D", "-f", conf_.string()}, "slurmctld.out");
    const pid_t slurmd = spawn({"/usr/sbin/slurmd", "-D", "-f", conf_.string()}, "slurmd.out");
    wait_for("slurmctld to answer", ctld, "slurmctld", "slurmctld.out", deadline,
             [&] { return client("sinfo -h", 5).code == 0; });
    wait_for("the node to become idle", slurmd, "slurmd", "slurmd.out", deadline,
             [&] { return client("sinfo -h -o %T", 5).output.find("idle") != std::string::npos; });
  }

  // SIGTERM, then SIGKILL after 10 s; reaps the child so its pid cannot be mistaken for another process.
  static void terminate(pid_t pid) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return;
    kill(pid, SIGTERM);
    for (int k = 0; k < 100; ++k) {
      if (waitpid(pid, &status, WNOHANG) == pid) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }

  fs::path dir_, conf_;
  std::vector<pid_t> pids_;
};

}  // namespace kf::testing
