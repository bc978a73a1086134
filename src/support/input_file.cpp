#include "support/input_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop::detail {
namespace {

std::string readStream(std::FILE* stream, const std::string& name) {
  std::string content;
  char buffer[1 << 16];
  std::size_t count = 0;
  errno = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, stream)) > 0) content.append(buffer, count);
  if (std::ferror(stream) != 0) {
    throw Error(fmt::format("cannot read '{}': {}", name, std::strerror(errno != 0 ? errno : EIO)));
  }
  return content;
}

}  // namespace

std::string readInputFile(const std::string& path) {
  if (path == "-") return readStream(stdin, "<stdin>");
  errno = 0;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw Error(
        fmt::format("cannot open '{}': {}", path, std::strerror(errno != 0 ? errno : ENOENT)));
  }
  try {
    std::string content = readStream(file, path);
    std::fclose(file);
    return content;
  } catch (...) {
    std::fclose(file);
    throw;
  }
}

}  // namespace scallop::detail
