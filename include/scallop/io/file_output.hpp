#pragma once
// Writing output files all or nothing: the content goes to a temporary file beside the
// target, which is renamed over the target only once it is complete, so a failure never
// leaves a partial output file.

#include <span>
#include <string>
#include <string_view>

namespace scallop {

/// Writes `content` to `path` atomically ("-" writes to standard output). Throws
/// scallop::Error naming the path if it cannot be written.
void writeFileAtomically(const std::string& path, std::string_view content);

/// One output of a run: where it goes ("-" = standard output) and what it holds.
struct OutputFile {
  std::string path;
  std::string content;
};

/// Writes several outputs all or nothing: every file is first written to its temporary,
/// then all temporaries are renamed over their targets, then standard output ("-") is
/// written. If any step fails, the temporaries and the targets this call already put in
/// place are removed (targets that existed before and were not yet replaced are left
/// untouched), and scallop::Error names the failing path and the reason. Throws also if
/// two outputs name the same path.
void writeFilesAtomically(std::span<const OutputFile> files);

}  // namespace scallop
