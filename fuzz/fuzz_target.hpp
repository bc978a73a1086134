#pragma once
// The shared frame of scallop's libFuzzer targets (one per reader, fuzz/*_fuzz.cpp): any bytes
// in, and the only acceptable outcomes are a result or scallop::Error (bad input's one error
// channel). Anything else — another exception, a crash, a sanitizer report, a hang — is a
// defect that libFuzzer reports with the input that caused it.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string_view>

#include "scallop/error.hpp"

namespace scallop::fuzz {

// Runs `work` on the input as text; scallop::Error is the expected failure.
template <typename Work>
int run(const std::uint8_t* data, std::size_t size, Work&& work) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    work(bytes);
  } catch (const Error&) {
    // Bad input, refused with a message: the contract.
  } catch (const std::exception& other) {
    std::fprintf(stderr, "fuzz: an exception other than scallop::Error escaped: %s\n", other.what());
    std::abort();
  }
  return 0;
}

}  // namespace scallop::fuzz
