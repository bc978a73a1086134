#pragma once
// What the tests of error messages share: a message must name every expected part.

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace scallop::test {

// Non-empty (the input was refused) and containing each of `parts`; `context` names the case.
inline void expectMessageContains(const std::string& message, const std::vector<std::string>& parts,
                                  const std::string& context) {
  ASSERT_FALSE(message.empty()) << "accepted: " << context;
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "message '" << message << "' lacks '" << part << "' for: " << context;
  }
}

}  // namespace scallop::test
