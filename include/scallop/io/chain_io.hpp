#pragma once
// Reading monotone chains from files.
//
// Text format: one vertex per line, "x z", separated by whitespace and/or one comma;
// '#' starts a comment; blank lines are skipped; the first non-comment line may be a header
// (a line whose fields are not numbers, e.g. "x,z"). JSON format: {"points": [[x, z], ...]}.
// The format is chosen by content: a document whose first non-blank character is '{' is JSON.
// Errors name the source, the line (text) or the point index (JSON), and the offending value.
// The chain is validated (see validateChain) before it is returned.

#include <string>
#include <string_view>

#include "scallop/paths/chain.hpp"

namespace scallop {

/// Parses a chain from `content`; `sourceName` (a file name, or "-" for standard input) is
/// used in error messages.
Chain parseChain(std::string_view content, const std::string& sourceName);

/// Reads and parses a chain from a file ("-" reads standard input).
Chain readChain(const std::string& path);

/// Names of the built-in example chains, and one of them by name (throws on an unknown name).
/// The examples, compiled in (no files needed), with a radius that shows them well:
///   "figure2"  27 vertices in the spirit of the paper's Figure 2: bumps, deep narrow pits the
///              circle cannot enter, a peak and a slope (r = 1);
///   "steps"    terraces joined by vertical edges up and down, and a narrow slot (r = 0.5);
///   "sawtooth" ten teeth, slow rise and steep fall (r = 0.5);
///   "sine"     z = sin(x) over two periods, 201 samples (r = 2 bridges each trough with a
///              lid; r < 1 follows the whole wave).
std::vector<std::string> exampleChainNames();
Chain exampleChain(const std::string& name);

}  // namespace scallop
