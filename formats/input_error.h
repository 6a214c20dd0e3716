// Exceptions that cross library boundaries. Libraries throw; only the mains print and exit.
#pragma once

#include <stdexcept>
#include <string>

namespace femb {

/// Bad user input or unreadable/unwritable file. The message names the file (and line, key or
/// entity), the offending value and the rule, in one line. Mains map it to exit code 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// A request refused because it would exceed a resource limit (memory, element count); the
/// message gives the estimate and the limit. Mains map it to exit code 4.
class ResourceLimitError : public std::runtime_error {
 public:
  explicit ResourceLimitError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace femb
