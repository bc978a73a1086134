#pragma once
// scallop's one error channel: every failure the library detects (bad input, malformed
// files, violated preconditions) is thrown as scallop::Error. The CLI catches it once.

#include <stdexcept>
#include <string>

namespace scallop {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace scallop
