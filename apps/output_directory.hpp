#pragma once
// Writing a command's outputs all or nothing when some go into a directory: either files
// into a directory that may hold others (writeOutputs: the directory, and missing parents,
// created first and removed again if the files cannot all be written), or a directory the
// command owns, replaced whole (replaceDirectory: `scallop plan --out`).

#include <set>
#include <string>
#include <vector>

#include "scallop/io/file_output.hpp"

namespace scallop::cli {

/// Writes `outputs` with writeFilesAtomically, creating `directory` first unless it is
/// empty; on failure removes the directories this call created, then rethrows.
void writeOutputs(const std::vector<OutputFile>& outputs, const std::string& directory);

/// The names a command writes into a directory it owns (`scallop plan --out`).
using OwnedNames = std::set<std::string>;

/// Refuses (scallop::Error naming the directory and the file) an existing `directory` that is
/// not a directory or holds anything but regular files named in `owned`: replacing it would
/// lose that. Called before the work starts, and again by replaceDirectory.
void checkReplaceableDirectory(const std::string& directory, const OwnedNames& owned);

/// Puts `files` (names within the directory, each in `owned`, with their contents) in place
/// as the whole of `directory`, all or nothing even under a kill: they are written into a
/// fresh hidden sibling ".<name>.tmp-<pid>", which one rename makes `directory` (when it is
/// new) or one atomic exchange swaps with the old one (renameat2 RENAME_EXCHANGE), whose
/// files (all the command's own, checkReplaceableDirectory) are then removed. A kill can
/// leave that sibling (the new files before the swap, the old ones after it), never a mix
/// in `directory`. Missing parents are created (and removed again on failure).
void replaceDirectory(const std::string& directory, const std::vector<OutputFile>& files, const OwnedNames& owned);

}  // namespace scallop::cli
