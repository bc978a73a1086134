#pragma once
// Private to the library: reading a whole input file (or standard input, named "-").

#include <string>

namespace scallop::detail {

/// The whole content of `path` ("-" reads standard input). Throws scallop::Error naming the
/// file and the reason when it cannot be opened or read.
std::string readInputFile(const std::string& path);

}  // namespace scallop::detail
