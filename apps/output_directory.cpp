#include "output_directory.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
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

// Removes `directory` and the regular files in it (the command's own: checked before).
void removeOwnDirectory(const fs::path& directory) {
  std::error_code ignored;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ignored)) fs::remove(entry.path(), ignored);
  fs::remove(directory, ignored);
}

}  // namespace

void checkReplaceableDirectory(const std::string& directory, const OwnedNames& owned) {
  const fs::path normal = fs::path(directory).lexically_normal();
  const std::string last = (normal.filename().empty() ? normal.parent_path() : normal).filename().string();
  if (last.empty() || last == "." || last == "..")
    throw Error(fmt::format("'{}' names no directory of its own: the outputs replace the whole directory, so give "
                            "a new one (or one this command wrote)",
                            directory));
  std::error_code error;
  const fs::file_status status = fs::symlink_status(directory, error);
  if (error || !fs::exists(status)) return;  // a new directory
  if (!fs::is_directory(status))
    throw Error(fmt::format("'{}' exists and is not a directory: give a new directory (or one this command wrote)",
                            directory));
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, error)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || entry.is_symlink() || owned.count(name) == 0)
      throw Error(fmt::format("'{}' holds '{}', which this command does not write: its outputs replace the whole "
                              "directory, so give a new one (or one it wrote)",
                              directory, name));
  }
  if (error) throw Error(fmt::format("cannot read directory '{}': {}", directory, error.message()));
}

void replaceDirectory(const std::string& directory, const std::vector<OutputFile>& files, const OwnedNames& owned) {
  checkReplaceableDirectory(directory, owned);
  const fs::path target = fs::path(directory).lexically_normal();
  const fs::path name = target.filename().empty() ? target.parent_path().filename() : target.filename();
  const fs::path where = target.filename().empty() ? target.parent_path() : target;
  const fs::path parent = where.has_parent_path() ? where.parent_path() : fs::path(".");
  const std::vector<fs::path> created = createDirectories(parent);
  const fs::path staging = parent / fmt::format(".{}.tmp-{}", name.string(), static_cast<long>(::getpid()));
  std::error_code ignored;
  try {
    removeOwnDirectory(staging);  // left by a killed run of the same process id
    if (!fs::create_directory(staging, ignored))
      throw Error(fmt::format("cannot create directory '{}': {}", staging.string(), ignored.message()));
    std::vector<OutputFile> staged;
    for (const OutputFile& file : files) staged.push_back({(staging / file.path).string(), file.content});
    writeFilesAtomically(staged);
    if (!fs::exists(fs::symlink_status(where, ignored))) {
      if (std::rename(staging.c_str(), where.c_str()) != 0)
        throw Error(fmt::format("cannot rename '{}' to '{}': {}", staging.string(), where.string(), std::strerror(errno)));
      return;
    }
    // Swap the two in one step; the old files then leave with the staging name.
    if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, where.c_str(), RENAME_EXCHANGE) != 0) {
      const int reason = errno;
      if (reason != EINVAL && reason != ENOSYS)
        throw Error(fmt::format("cannot put '{}' in place of '{}': {}", staging.string(), where.string(),
                                std::strerror(reason)));
      // A file system without the exchange: the old directory aside, then the new one in.
      const fs::path old = parent / fmt::format(".{}.old-{}", name.string(), static_cast<long>(::getpid()));
      removeOwnDirectory(old);
      if (std::rename(where.c_str(), old.c_str()) != 0)
        throw Error(fmt::format("cannot replace '{}': {}", where.string(), std::strerror(errno)));
      if (std::rename(staging.c_str(), where.c_str()) != 0) {
        const int failed = errno;
        std::rename(old.c_str(), where.c_str());  // the old directory back, as it was
        throw Error(fmt::format("cannot replace '{}': {}", where.string(), std::strerror(failed)));
      }
      removeOwnDirectory(old);
      return;
    }
    removeOwnDirectory(staging);
  } catch (...) {
    removeOwnDirectory(staging);
    for (const fs::path& made : created) fs::remove(made, ignored);
    throw;
  }
}

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
