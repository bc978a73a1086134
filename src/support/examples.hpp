#pragma once
// Private to the library: a table of built-in examples (chains, surfaces) looked up by name.

#include <span>
#include <string>
#include <vector>
#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop::detail {

template <typename T>
struct Example {
  const char* name;
  T (*make)();
};

template <typename T>
std::vector<std::string> exampleNames(std::span<const Example<T>> examples) {
  std::vector<std::string> names;
  for (const Example<T>& example : examples) names.emplace_back(example.name);
  return names;
}

/// The example called `name`; throws scallop::Error listing the known names otherwise.
/// `kind` names what is looked up in the message ("chain", "surface").
template <typename T>
T makeExample(std::span<const Example<T>> examples, const std::string& name, const char* kind) {
  for (const Example<T>& example : examples) {
    if (name == example.name) return example.make();
  }
  throw Error(fmt::format("unknown example {} '{}' (known: {})", kind, name,
                          fmt::join(exampleNames(examples), ", ")));
}

}  // namespace scallop::detail
