#pragma once
// Runs the built `tomorig` binary for end-to-end tests and captures exit code and output.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "temp_dir.h"

namespace tomorig::testing {

struct CliResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// `text` quoted for a POSIX shell, e.g. a path with spaces or quotes.
inline std::string shell_quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Whether the tomorig binary exists: a partial build of one suite may not have it, and then
// CLI tests skip and say so.
inline bool tomorig_built() { return std::filesystem::exists(TOMORIG_BINARY); }

// `args` is appended to the binary path verbatim (the caller quotes what needs quoting).
inline CliResult run_tomorig(const std::string& args) {
  TempDir tmp;
  const auto out = tmp / "stdout.txt";
  const auto err = tmp / "stderr.txt";
  const std::string cmd = shell_quoted(TOMORIG_BINARY) + " " + args + " >" + shell_quoted(out.string()) + " 2>" +
                          shell_quoted(err.string()) + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = read_text_file(out);
  result.err = read_text_file(err);
  return result;
}

}  // namespace tomorig::testing
