#pragma once
namespace tomorig::app {
// Documented in docs/cli.md; scripts rely on these.
enum ExitCode : int {
  kExitOk = 0,
  kExitRuntimeFailure = 1,
  kExitBadInput = 2,  // bad usage, bad flags, bad or missing input files
};
}  // namespace tomorig::app
