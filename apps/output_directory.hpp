#pragma once
// Writing a command's outputs all or nothing when some go into a directory the command
// creates: the directory (and missing parents) is created first and removed again if the
// files cannot all be written, so a failed run leaves nothing behind.

#include <string>
#include <vector>

#include "scallop/file_output.hpp"

namespace scallop::cli {

/// Writes `outputs` with writeFilesAtomically, creating `directory` first unless it is
/// empty; on failure removes the directories this call created, then rethrows.
void writeOutputs(const std::vector<OutputFile>& outputs, const std::string& directory);

}  // namespace scallop::cli
