#include "config/diagnostic.hpp"

#include <algorithm>

namespace facet::config {

std::string format(const SourceLocation& where) {
  std::string out = where.file.string();
  // Appended piecewise: GCC 12 warns (-Wrestrict, falsely) about ":" + std::to_string(...).
  if (where.line > 0) {
    out += ':';
    out += std::to_string(where.line);
    if (where.column > 0) {
      out += ':';
      out += std::to_string(where.column);
    }
  }
  return out;
}

std::string format(const Diagnostic& d) {
  std::string out = format(d.where) + ": ";
  if (d.severity == Severity::Warning) out += "warning: ";
  return out + d.message;
}

void Diagnostics::error(SourceLocation where, std::string message) {
  items_.push_back({std::move(where), Severity::Error, std::move(message)});
}

void Diagnostics::warning(SourceLocation where, std::string message) {
  items_.push_back({std::move(where), Severity::Warning, std::move(message)});
}

void Diagnostics::append(const Diagnostics& other) {
  items_.insert(items_.end(), other.items_.begin(), other.items_.end());
}

bool Diagnostics::hasErrors() const {
  return errorCount() > 0;
}

std::size_t Diagnostics::errorCount() const {
  return static_cast<std::size_t>(
      std::count_if(items_.begin(), items_.end(),
                    [](const Diagnostic& d) { return d.severity == Severity::Error; }));
}

std::string Diagnostics::text() const {
  std::string out;
  for (const auto& d : items_) out += format(d) + "\n";
  return out;
}

}  // namespace facet::config
