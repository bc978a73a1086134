#include "scallop/io/file_output.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {
namespace {

constexpr const char* kStandardOutput = "-";

std::string errnoReason(int error) { return std::strerror(error); }

// The temporary file lives beside the target so that the final rename stays within one
// file system (and is therefore atomic); the process id keeps concurrent runs apart.
std::string temporaryPathFor(const std::string& path) {
  return fmt::format("{}.tmp-{}", path, static_cast<long>(::getpid()));
}

// Best effort: used only on error paths, where the original error is what gets reported.
void removeQuietly(const std::string& path) {
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

[[noreturn]] void throwWriteError(const std::string& path, const std::string& reason) {
  throw Error(fmt::format("cannot write '{}': {}", path, reason));
}

// Writes the whole of `content` to `file`, then flushes the C library buffer and asks the
// kernel to put the data on disk, so that a later rename never exposes an empty file after
// a crash. Returns 0 on success, or the errno of the first failure.
int writeAndSync(std::FILE* file, std::string_view content) {
  if (!content.empty() && std::fwrite(content.data(), 1, content.size(), file) != content.size()) {
    return errno != 0 ? errno : EIO;
  }
  if (std::fflush(file) != 0) {
    return errno != 0 ? errno : EIO;
  }
  if (::fsync(::fileno(file)) != 0 && errno != EINVAL && errno != EROFS) {
    return errno;  // EINVAL/EROFS: the file (e.g. a pipe or special file) cannot be synced
  }
  return 0;
}

// Writes `content` to a fresh temporary file beside `path` and returns the temporary's
// name. On failure the temporary is removed and Error names `path` and the reason.
std::string writeTemporary(const std::string& path, std::string_view content) {
  const std::string temporary = temporaryPathFor(path);
  errno = 0;
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    throwWriteError(path, errnoReason(errno));
  }
  errno = 0;
  int error = writeAndSync(file, content);
  errno = 0;
  if (std::fclose(file) != 0 && error == 0) {
    error = errno != 0 ? errno : EIO;
  }
  if (error != 0) {
    removeQuietly(temporary);
    throwWriteError(path, errnoReason(error));
  }
  return temporary;
}

void renameOver(const std::string& temporary, const std::string& path) {
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    removeQuietly(temporary);
    throwWriteError(path, error.message());
  }
}

void writeStandardOutput(std::string_view content) {
  errno = 0;
  if ((!content.empty() &&
       std::fwrite(content.data(), 1, content.size(), stdout) != content.size()) ||
      std::fflush(stdout) != 0) {
    throw Error(
        fmt::format("cannot write to standard output: {}", errnoReason(errno != 0 ? errno : EIO)));
  }
}

// An existing target that is not a regular file (a device such as /dev/null, a FIFO, a
// terminal) cannot be replaced by renaming: renaming over it would turn /dev/null into a
// plain file. Such a target is written directly, last, like standard output.
bool isStreamTarget(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  return !error && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status) &&
         !std::filesystem::is_directory(status);
}

void writeStream(const std::string& path, std::string_view content) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) throwWriteError(path, errnoReason(errno));
  const bool ok = (content.empty() || std::fwrite(content.data(), 1, content.size(), file) == content.size());
  const int saved = errno;
  if (std::fclose(file) != 0 || !ok) throwWriteError(path, errnoReason(saved != 0 ? saved : EIO));
}

// Whether two paths name the same file, as far as can be told without the file existing
// ("out.json" and "./out.json" do; symbolic links are not followed).
bool sameLocation(const std::string& a, const std::string& b) {
  std::error_code firstError;
  std::error_code secondError;
  const std::filesystem::path first = std::filesystem::absolute(a, firstError).lexically_normal();
  const std::filesystem::path second = std::filesystem::absolute(b, secondError).lexically_normal();
  return firstError || secondError ? a == b : first == second;
}

}  // namespace

void writeFileAtomically(const std::string& path, std::string_view content) {
  if (path.empty()) {
    throwWriteError(path, "empty file name");
  }
  if (path == kStandardOutput) {
    writeStandardOutput(content);
    return;
  }
  if (isStreamTarget(path)) {
    writeStream(path, content);
    return;
  }
  renameOver(writeTemporary(path, content), path);
}

void writeFilesAtomically(std::span<const OutputFile> files) {
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (files[i].path.empty()) {
      throwWriteError(files[i].path, "empty file name");
    }
    // Two outputs to one file would share a temporary and overwrite each other.
    for (std::size_t j = 0; j < i; ++j) {
      if (files[i].path != kStandardOutput && files[j].path != kStandardOutput &&
          sameLocation(files[i].path, files[j].path)) {
        throwWriteError(files[i].path, "the same file is given for two outputs");
      }
    }
  }

  // Phase 1: every file's content into its temporary. Nothing visible has changed yet, so
  // a failure only has to remove the temporaries written so far.
  std::vector<std::string> temporaries(files.size());
  std::vector<bool> stream(files.size());
  for (std::size_t i = 0; i < files.size(); ++i) {
    stream[i] = files[i].path == kStandardOutput || isStreamTarget(files[i].path);
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (stream[i]) {
      continue;
    }
    try {
      temporaries[i] = writeTemporary(files[i].path, files[i].content);
    } catch (...) {
      for (const std::string& temporary : temporaries) {
        if (!temporary.empty()) removeQuietly(temporary);
      }
      throw;
    }
  }

  // Phase 2: rename the temporaries over the targets, then write standard output last,
  // since it is the one output that cannot be taken back. On failure, remove what this
  // call has put in place and the temporaries still pending.
  std::vector<std::string> committed;
  try {
    for (std::size_t i = 0; i < files.size(); ++i) {
      if (stream[i]) continue;
      const std::string temporary = std::exchange(temporaries[i], std::string());
      renameOver(temporary, files[i].path);
      committed.push_back(files[i].path);
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      if (!stream[i]) continue;
      if (files[i].path == kStandardOutput) {
        writeStandardOutput(files[i].content);
      } else {
        writeStream(files[i].path, files[i].content);
      }
    }
  } catch (...) {
    for (const std::string& temporary : temporaries) {
      if (!temporary.empty()) removeQuietly(temporary);
    }
    for (const std::string& path : committed) {
      removeQuietly(path);
    }
    throw;
  }
}

}  // namespace scallop
