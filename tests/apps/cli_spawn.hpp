#pragma once
// Starts processes in the background for the CLI tests that signal them (the stereoguard binary,
// Xvfb, xwd): fork and exec, without a shell in between, so the pid is the program's.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace sg::test {

/// Runs `argv` (argv[0] a path, or a name looked up in PATH) in `dir` with stdout and stderr
/// written to `out` and `err` (empty = /dev/null) and `env` (NAME=value) added to the
/// environment, "NAME=" removing NAME. SIGINT and SIGTERM take their default action in the child.
/// Descriptors without close-on-exec are inherited. Returns its pid.
inline pid_t spawn(const std::vector<std::string>& argv, const std::filesystem::path& dir,
                   const std::filesystem::path& out, const std::filesystem::path& err,
                   const std::vector<std::string>& env = {}) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  // Child: only async-signal-safe work would be strictly allowed; the test process is
  // single-threaded here, so setenv and friends are fine.
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  if (chdir(dir.c_str()) != 0) _exit(126);
  auto redirect = [](const std::filesystem::path& p, int fd) {
    const int f = open(p.empty() ? "/dev/null" : p.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (f >= 0) dup2(f, fd);
  };
  redirect(out, 1);
  redirect(err, 2);
  for (const std::string& e : env) {
    const auto eq = e.find('=');
    if (eq + 1 == e.size()) {
      unsetenv(e.substr(0, eq).c_str());
    } else {
      setenv(e.substr(0, eq).c_str(), e.substr(eq + 1).c_str(), 1);
    }
  }
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execvp(args[0], args.data());
  _exit(127);
}

/// Waits up to `timeout` for `pid` to end. Returns its exit status (128 + n when signal n killed
/// it), or nullopt after killing it (SIGKILL) when it did not end in time.
inline std::optional<int> wait_exit(pid_t pid, std::chrono::seconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int raw = 0;
    if (waitpid(pid, &raw, WNOHANG) == pid) {
      return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
    }
    if (std::chrono::steady_clock::now() > end) {
      kill(pid, SIGKILL);
      waitpid(pid, &raw, 0);
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

/// True when `pid` (a child) has not ended yet.
inline bool running(pid_t pid) {
  siginfo_t info{};
  return waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
         info.si_pid == 0;
}

/// Complete lines (ending in '\n') of a file being written.
inline int complete_lines(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  int n = 0;
  for (char c; in.get(c);) n += c == '\n';
  return n;
}

/// Polls until `p` holds at least `lines` complete lines, while `pid` runs, for up to `timeout`.
inline bool wait_lines(const std::filesystem::path& p, int lines, pid_t pid,
                       std::chrono::seconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (complete_lines(p) >= lines) return true;
    if (!running(pid)) return complete_lines(p) >= lines;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

}  // namespace sg::test
