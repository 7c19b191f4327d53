#pragma once
// A tomorig command running in the background with its stderr on a pipe, for end-to-end tests
// that must act while a command runs: read the endpoint it printed, wait for its "wrote set"
// lines, send it SIGINT. Tests synchronise on what the process prints and on its exit, never
// on sleeps. Every command started this way must end by itself (timeouts), so reading to the
// end of its output is bounded.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "temp_dir.h"

namespace tomorig::testing {

class TomorigProcess {
 public:
  // `program` is tomorig itself unless a test runs it through a launcher (mpirun).
  explicit TomorigProcess(const std::vector<std::string>& args, const std::string& program = TOMORIG_BINARY) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe2 failed");
    const std::string out_path = (out_dir_ / "stdout.txt").string();
    std::vector<std::string> argv_text{program};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_text) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {  // child: only async-signal-safe calls until exec
      const int in = open("/dev/null", O_RDONLY);
      const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (in < 0 || out < 0 || dup2(in, 0) < 0 || dup2(out, 1) < 0 || dup2(fds[1], 2) < 0) _exit(127);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(fds[1]);
    err_fd_ = fds[0];
  }
  ~TomorigProcess() {
    if (pid_ > 0 && !exit_code_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (err_fd_ >= 0) close(err_fd_);
  }
  TomorigProcess(const TomorigProcess&) = delete;
  TomorigProcess& operator=(const TomorigProcess&) = delete;

  // The next whole line of stderr (without '\n'; a status line rewritten with '\r' ends at
  // the '\r' too), or nullopt once the process closed stderr.
  std::optional<std::string> read_line() {
    for (;;) {
      const auto end = pending_.find_first_of("\r\n");
      if (end != std::string::npos) {
        std::string line = pending_.substr(0, end);
        pending_.erase(0, end + 1);
        return line;
      }
      char buffer[4096];
      const ssize_t n = read(err_fd_, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        if (pending_.empty()) return std::nullopt;
        std::string line;
        line.swap(pending_);
        return line;
      }
      pending_.append(buffer, static_cast<std::size_t>(n));
      err_.append(buffer, static_cast<std::size_t>(n));
    }
  }

  // Reads stderr until a line contains `text` and returns that line; nullopt at the end.
  std::optional<std::string> wait_for_line(std::string_view text) {
    while (auto line = read_line())
      if (line->find(text) != std::string::npos) return line;
    return std::nullopt;
  }

  void send_signal(int sig) { kill(pid_, sig); }

  // Drains stderr, waits for the exit and returns the exit code (-1 if a signal ended it).
  int wait() {
    if (exit_code_) return *exit_code_;
    while (read_line()) {
    }
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return *exit_code_;
  }

  const std::string& err() const { return err_; }  // all stderr read so far
  std::string out() const { return read_text_file(out_dir_ / "stdout.txt"); }

 private:
  TempDir out_dir_;
  pid_t pid_ = -1;
  int err_fd_ = -1;
  std::string pending_, err_;
  std::optional<int> exit_code_;
};

}  // namespace tomorig::testing
