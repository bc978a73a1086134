#pragma once
// Private to the library: the layout of scallop's JSON outputs (orient_output.cpp,
// paths_output.cpp): objects expanded one key per line, indented by two per level; arrays
// kept on one line. Numbers are nlohmann's shortest round-trip form (full double precision).

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

namespace scallop::json {

inline void dumpValue(const nlohmann::ordered_json& value, std::size_t indent, std::string& out) {
  if (value.is_array()) {
    out += '[';
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (i > 0) out += ", ";
      out += value[i].dump();
    }
    out += ']';
    return;
  }
  if (!value.is_object() || value.empty()) {
    out += value.dump();
    return;
  }
  out += "{\n";
  bool first = true;
  for (const auto& [key, item] : value.items()) {
    out += first ? "" : ",\n";
    first = false;
    out.append(indent + 2, ' ');
    out += nlohmann::ordered_json(key).dump();
    out += ": ";
    dumpValue(item, indent + 2, out);
  }
  out += '\n';
  out.append(indent, ' ');
  out += '}';
}

/// The document, laid out as above, with a final newline.
inline std::string format(const nlohmann::ordered_json& document) {
  std::string out;
  dumpValue(document, 0, out);
  return out + "\n";
}

}  // namespace scallop::json
