#pragma once
// RAII for the GLib objects Aravis hands out, and GError to std::string.
#include <arv.h>

#include <memory>
#include <string>

namespace tomorig::acquisition::detail {

struct GObjectUnref {
  void operator()(gpointer object) const {
    if (object != nullptr) g_object_unref(object);
  }
};
template <typename T>
using GObjectPtr = std::unique_ptr<T, GObjectUnref>;

// Owns a GError* out-parameter; message() is empty when no error was set.
class GErrorSlot {
 public:
  GErrorSlot() = default;
  GErrorSlot(const GErrorSlot&) = delete;
  GErrorSlot& operator=(const GErrorSlot&) = delete;
  ~GErrorSlot() { g_clear_error(&error_); }
  GError** out() {
    g_clear_error(&error_);
    return &error_;
  }
  explicit operator bool() const { return error_ != nullptr; }
  std::string message() const { return error_ != nullptr && error_->message != nullptr ? error_->message : ""; }

 private:
  GError* error_ = nullptr;
};

}  // namespace tomorig::acquisition::detail
