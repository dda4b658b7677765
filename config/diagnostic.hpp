#pragma once
// Problems found in a configuration file, each pinned to a place in the file.
//
// Everything that reads station configs and recipes collects Diagnostics instead of throwing, so
// that one run reports every problem at once, each printed as `file:line:column: message`
// (warnings as `file:line:column: warning: message`), like a compiler.

#include <filesystem>
#include <string>
#include <vector>

namespace facet::config {

// A place in a text file. Lines and columns count from 1; 0 means "unknown" (then the message is
// printed with the file name only).
struct SourceLocation {
  std::filesystem::path file;
  int line = 0;
  int column = 0;
};

enum class Severity { Error, Warning };

struct Diagnostic {
  SourceLocation where;
  Severity severity = Severity::Error;
  std::string message;
};

// `file:line:column` (or `file:line`, or `file`, as far as known).
std::string format(const SourceLocation& where);

// `file:line:column: message` (or `file: message` when the line is unknown).
std::string format(const Diagnostic& diagnostic);

// An ordered collection of problems; keeps them in the order they were found.
class Diagnostics {
 public:
  void error(SourceLocation where, std::string message);
  void warning(SourceLocation where, std::string message);
  void append(const Diagnostics& other);

  [[nodiscard]] bool hasErrors() const;
  [[nodiscard]] std::size_t errorCount() const;
  [[nodiscard]] bool empty() const { return items_.empty(); }
  [[nodiscard]] const std::vector<Diagnostic>& items() const { return items_; }
  // Every diagnostic formatted, one per line.
  [[nodiscard]] std::string text() const;

 private:
  std::vector<Diagnostic> items_;
};

}  // namespace facet::config
