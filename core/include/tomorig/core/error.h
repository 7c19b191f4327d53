#pragma once
// Errors that reach a user. Library code throws tomorig::Error; the CLI maps the kind to an
// exit code in exactly one place (apps/src/exit_codes.h), so a message written here is what
// the user reads. A message names what was wrong and, where possible, how to fix it.
#include <stdexcept>
#include <string>

namespace tomorig {

enum class ErrorKind {
  bad_input,  // the user's input (file, flag, config, data) is wrong: exit code 2
  runtime,    // the input was fine but something failed while running: exit code 1
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const noexcept { return kind_; }

 private:
  ErrorKind kind_;
};

// Shorthands that read well at the throw site: throw bad_input("grid.nx must be > 0").
inline Error bad_input(const std::string& message) { return Error(ErrorKind::bad_input, message); }
inline Error runtime_error(const std::string& message) { return Error(ErrorKind::runtime, message); }

}  // namespace tomorig
