#pragma once
// Numeric command-line arguments shared by the subcommands: parsed whole and
// locale-independently, with an error that names the option and quotes the text.

#include <string>

#include "scallop/geometry/vector.hpp"

namespace scallop::cli {

/// A positive finite number: the whole of `text` (std::from_chars: locale-independent, no
/// blanks, no trailing characters; one leading '+' allowed), or scallop::Error
/// "invalid <what> '<text>': ..." (`expected` describes what would have been accepted).
double parsePositive(const std::string& text, const char* what, const char* expected);

/// Any finite number, with the same rules and errors as parsePositive.
double parseFinite(const std::string& text, const char* what, const char* expected);

/// Parses "X,Y,Z" (three finite numbers, not all zero) for --normal.
Vec3 parseNormal(const std::string& text);

}  // namespace scallop::cli
