#include "output_directory.hpp"

#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop::cli {
namespace {

namespace fs = std::filesystem;

// Creates `directory` and any missing parents; returns those it created, deepest first, so
// that a failed run can remove them again.
std::vector<fs::path> createDirectories(const fs::path& directory) {
  std::vector<fs::path> missing;
  for (fs::path p = directory; !p.empty() && !fs::exists(p); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  std::error_code error;
  fs::create_directories(directory, error);
  if (error) {
    throw Error(fmt::format("cannot create directory '{}': {}", directory.string(),
                            error.message()));
  }
  return missing;
}

}  // namespace

void writeOutputs(const std::vector<OutputFile>& outputs, const std::string& directory) {
  const std::vector<fs::path> created =
      directory.empty() ? std::vector<fs::path>{} : createDirectories(directory);
  try {
    writeFilesAtomically(outputs);
  } catch (...) {
    std::error_code ignored;
    for (const fs::path& made : created) fs::remove(made, ignored);
    throw;
  }
}

}  // namespace scallop::cli
