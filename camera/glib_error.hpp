#pragma once
// A GError out-parameter that frees itself and turns into a message.

#include <glib.h>

#include <string>

namespace facet {

struct ErrorSlot {
  GError* error = nullptr;
  ~ErrorSlot() { g_clear_error(&error); }
  GError** operator&() { return &error; }
  explicit operator bool() const { return error != nullptr; }
  std::string message() const { return error ? error->message : std::string(); }
};

}  // namespace facet
