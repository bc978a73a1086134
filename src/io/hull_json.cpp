#include "scallop/io/hull_json.hpp"

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace scallop {
namespace {

// ordered_json keeps keys in the documented order instead of sorting them.
using Json = nlohmann::ordered_json;

Json pointJson(const Point2& p) { return Json::array({p.x, p.z}); }

// JSON has no infinity: an infinite radius (the convex-hull limit) is written as null.
Json radiusJson(double radius) { return std::isfinite(radius) ? Json(radius) : Json(nullptr); }

Json hullElementJson(const HullElement& element) {
  Json json;
  const bool isLink = element.kind == HullElementKind::link;
  json["kind"] = isLink ? "link" : "lid";
  json["start"] = pointJson(element.start);
  json["end"] = pointJson(element.end);
  if (isLink) {
    json["edge"] = element.edge;
  } else if (!element.straight) {
    json["center"] = pointJson(element.center);
  }
  return json;
}

Json pathElementJson(const PathElement& element) {
  Json json;
  const bool isArc = element.kind == PathElementKind::arc;
  json["kind"] = isArc ? "arc" : "line";
  json["start"] = pointJson(element.start);
  json["end"] = pointJson(element.end);
  if (isArc) {
    json["center"] = pointJson(element.center);
    json["radius"] = element.radius;
    json["clockwise"] = element.clockwise;
  }
  return json;
}

Json statsJson(const ScallopHull& result, std::size_t vertexCount) {
  std::size_t links = 0;
  for (const HullElement& element : result.hull) {
    links += element.kind == HullElementKind::link ? 1 : 0;
  }
  Json json;
  json["vertices"] = vertexCount;
  json["links"] = links;
  json["lids"] = result.hull.size() - links;
  json["stack_pushes"] = result.stats.pushes;
  json["stack_pops"] = result.stats.pops;
  json["comparisons"] = result.stats.comparisons;
  json["exact_steps"] = result.stats.exactSteps;
  return json;
}

Json documentJson(const ScallopHull& result, std::size_t vertexCount,
                  std::optional<std::span<const Point2>> polyline) {
  Json document;
  document["radius"] = radiusJson(result.radius);
  Json& hull = document["hull"] = Json::array();
  for (const HullElement& element : result.hull) hull.push_back(hullElementJson(element));
  Json& toolpath = document["toolpath"] = Json::array();
  for (const PathElement& element : result.toolpath) toolpath.push_back(pathElementJson(element));
  document["toolpath_length"] = pathLength(result.toolpath);
  if (polyline) {
    Json& points = document["polyline"] = Json::array();
    for (const Point2& p : *polyline) points.push_back(pointJson(p));
  }
  document["stats"] = statsJson(result, vertexCount);
  return document;
}

// Indented like nlohmann's dump(2) at the top level, but with each array element (a hull
// element, a path element, a polyline point) compact on one line: a file of thousands of
// points stays readable and diffs line by line. Numbers are nlohmann's shortest
// round-trip form either way.
std::string dumpOneElementPerLine(const Json& document) {
  std::string out = "{\n";
  bool firstKey = true;
  for (const auto& [key, value] : document.items()) {
    out += firstKey ? "  " : ",\n  ";
    firstKey = false;
    out += Json(key).dump();
    out += ": ";
    if (value.is_array() && !value.empty()) {
      out += "[\n";
      for (std::size_t i = 0; i < value.size(); ++i) {
        out += "    ";
        out += value[i].dump();
        out += i + 1 < value.size() ? ",\n" : "\n";
      }
      out += "  ]";
    } else {
      out += value.dump();
    }
  }
  out += "\n}\n";
  return out;
}

}  // namespace

std::string hullToJson(const ScallopHull& result, std::size_t vertexCount) {
  return dumpOneElementPerLine(documentJson(result, vertexCount, std::nullopt));
}

std::string hullToJson(const ScallopHull& result, std::size_t vertexCount, std::span<const Point2> polyline) {
  return dumpOneElementPerLine(documentJson(result, vertexCount, polyline));
}

}  // namespace scallop
