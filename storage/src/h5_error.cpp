#include "h5_error.h"

#include <vector>

namespace tomorig::storage::h5 {
namespace {

// HDF5 1.10 registers an exit handler that closes every file still open, and a file whose
// flush failed on a full disk (which writers leave open on purpose: closing it again is what
// fails) makes that handler crash the process after the error has been reported. tomorig
// closes its files itself (RAII handles), so the handler has nothing else to do: it is turned
// off before the first HDF5 call, from this file, which every HDF5 user in tomorig links.
[[maybe_unused]] const herr_t kExitHandlerOff = H5dont_atexit();

}  // namespace

void silence_errors() {
  thread_local bool silenced = false;
  if (silenced) return;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  silenced = true;
}

namespace {
herr_t collect(unsigned /*n*/, const H5E_error2_t* error, void* client) {
  auto* messages = static_cast<std::vector<std::string>*>(client);
  if (error->desc != nullptr && *error->desc != '\0') messages->emplace_back(error->desc);
  return 0;
}
}  // namespace

std::string error_stack_text() {
  std::vector<std::string> messages;  // outermost (the API call) first
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, collect, &messages);
  if (messages.empty()) return std::string(kNoReason);
  const std::string& outer = messages.front();
  const std::string& inner = messages.back();
  return messages.size() == 1 || outer == inner ? inner : outer + " (" + inner + ")";
}

void fail(std::string_view action, std::string_view object) {
  std::string message(action);
  if (!object.empty()) message.append(" ").append(object);
  message.append(": ").append(error_stack_text());
  throw Failure(message);
}

}  // namespace tomorig::storage::h5
