#include "scallop/io/verify_output.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scallop/error.hpp"
#include "io/json_format.hpp"
#include "io/svg_format.hpp"

namespace scallop {
namespace {

using Json = nlohmann::ordered_json;
using svg::lengthLabel;
using svg::px;

Json pointJson(const std::optional<Vec3>& p) {
  if (!p) return nullptr;
  return Json::array({p->x, p->y, p->z});
}

// Viridis in 10 steps for the scallop, reds for gouges (no red in viridis), grey off the
// surface.
constexpr std::array<const char*, 10> kScallopColours = {"#440154", "#482878", "#3e4989", "#31688e", "#26828e",
                                                         "#1f9e89", "#35b779", "#6ece58", "#b5de2b", "#fde725"};
constexpr std::array<const char*, 5> kGougeColours = {"#fcbba1", "#fc9272", "#fb6a4a", "#de2d26", "#a50f15"};
constexpr const char* kNoSurface = "#e6e6e6";
constexpr std::size_t kMaxBlocks = 200;

std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += (static_cast<unsigned char>(c) < 0x20) ? ' ' : c;
    }
  }
  return out;
}

// The colour index of a block: 0..9 scallop, 10..14 gouge, 15 no surface, 16 beyond the
// tool's reach (cut_simulation.hpp's Reach).
constexpr int kNoSurfaceIndex = 15;
constexpr int kUnreachableIndex = 16;
constexpr const char* kUnreachable = "#f781bf";

const char* colourOf(int index) {
  if (index < 10) return kScallopColours[static_cast<std::size_t>(index)];
  if (index < 15) return kGougeColours[static_cast<std::size_t>(index - 10)];
  return index == kUnreachableIndex ? kUnreachable : kNoSurface;
}

}  // namespace

std::string verifyToJson(const SimulationReport& r, const VerifySources& sources) {
  Json document;
  document["surface"] = sources.surface;
  document["program"] = sources.program;
  document["units"] = std::string(unitsName(r.units));
  document["tool_radius"] = r.toolRadius;
  document["scallop_height"] = r.scallopHeight;
  document["gouge_tolerance"] = r.gougeTolerance;
  document["stock_top"] = r.stockTop;
  Json grid;
  grid["origin"] = Json::array({r.design.x0, r.design.y0});
  grid["spacing"] = r.design.spacing;
  grid["columns"] = r.design.columns;
  grid["rows"] = r.design.rows;
  grid["points"] = r.design.columns * r.design.rows;
  grid["surface_points"] = r.surfacePoints;
  grid["height_error_bound"] = r.heightErrorBound;
  document["grid"] = grid;
  Json moves;
  moves["total"] = r.moves;
  moves["rapids"] = r.rapids;
  moves["arcs"] = r.arcs;
  moves["rapids_cutting"] = r.rapidsCutting;
  moves["first_rapid_cut_line"] = r.rapidsCutting > 0 ? Json(r.firstRapidCutLine) : Json(nullptr);
  moves["unknown_start"] = sources.unknownStartMoves;
  moves["max_arc_radius_mismatch"] = sources.maxArcRadiusMismatch;
  document["moves"] = moves;
  Json gouge;
  gouge["max"] = r.maxGouge;
  gouge["at"] = pointJson(r.maxGougeAt);
  gouge["points"] = r.gougePoints;
  gouge["area"] = r.gougeArea;
  gouge["over_tolerance"] = r.maxGouge > r.gougeTolerance;
  // Vertical walls the ball only grazed (cut_simulation.hpp): out of the figures above.
  gouge["cleared_points"] = r.clearedGougePoints;
  gouge["max_cleared"] = r.maxClearedGouge;
  gouge["clearance_checks"] = r.clearanceChecks;
  gouge["clearance_budget_exhausted"] = r.clearanceBudgetExhausted;
  document["gouge"] = gouge;
  Json scallop;
  scallop["max"] = r.maxScallop;
  scallop["at"] = pointJson(r.maxScallopAt);
  scallop["p99"] = r.scallopP99;
  scallop["mean"] = r.meanScallop;
  scallop["uncut_points"] = r.uncutPoints;
  scallop["uncut_area"] = r.uncutArea;
  document["scallop"] = scallop;
  Json reach;
  reach["unreachable_points"] = r.unreachablePoints;
  reach["unreachable_area"] = r.unreachableArea;
  reach["max_material_left"] = r.maxUnreachableScallop;
  reach["at"] = pointJson(r.maxUnreachableAt);
  reach["points_classified"] = r.reachChecks;
  reach["budget_exhausted"] = r.reachBudgetExhausted;
  document["beyond_reach"] = reach;
  document["swept_point_visits"] = r.sweptPointVisits;
  return json::format(document);
}

std::string verifySvg(const SimulationReport& r, const VerifySources& sources) {
  const HeightGrid& design = r.design;
  const HeightGrid& stock = r.stock;
  if (design.columns == 0 || design.rows == 0 || design.z.size() != stock.z.size() ||
      r.designNormalZ.size() != design.z.size())
    throw Error("cannot draw the cut simulation: the grids are empty or differ");
  const std::string units(unitsName(r.units));
  const std::size_t block = std::max<std::size_t>(1, (std::max(design.columns, design.rows) + kMaxBlocks - 1) / kMaxBlocks);
  const std::size_t bx = (design.columns + block - 1) / block, by = (design.rows + block - 1) / block;

  // Each block's worst point.
  const double h = r.scallopHeight;
  // Gouges on a logarithmic scale from the tolerance (or 1e-9 of the tool radius) to the
  // deepest: thousandths and tenths both show.
  const double floorGouge = std::max(r.gougeTolerance, 1e-9 * r.toolRadius);
  // Without a gouge beyond the tolerance the bar still spans a decade, so that its labels
  // read as a scale (no block takes its colours then).
  const double gougeScaleTop = std::max(r.maxGouge, 10.0 * floorGouge);
  const double gougeSpan = std::log(gougeScaleTop / floorGouge);
  std::vector<int> colour(bx * by, kNoSurfaceIndex);
  for (std::size_t b = 0; b < by; ++b) {
    for (std::size_t a = 0; a < bx; ++a) {
      double worstGouge = -1.0, worstScallop = -1.0;
      bool unreachable = false;
      for (std::size_t j = b * block; j < std::min(design.rows, (b + 1) * block); ++j) {
        for (std::size_t i = a * block; i < std::min(design.columns, (a + 1) * block); ++i) {
          const std::size_t k = j * design.columns + i;
          if (design.z[k] == -std::numeric_limits<double>::infinity()) continue;
          const double difference = stock.z[k] - design.z[k];
          const bool cleared = k < r.clearedGouge.size() && r.clearedGouge[k];
          if (-difference > r.gougeTolerance && !cleared) worstGouge = std::max(worstGouge, -difference);
          if (k < r.unreachable.size() && r.unreachable[k]) {
            unreachable = true;
            continue;
          }
          worstScallop = std::max(worstScallop, std::max(0.0, difference) * r.designNormalZ[k]);
        }
      }
      int index = kNoSurfaceIndex;
      if (worstGouge >= 0.0) {
        index = 10 + std::clamp(static_cast<int>(std::log(std::max(worstGouge, floorGouge) / floorGouge) / gougeSpan * 5.0), 0, 4);
      } else if (unreachable) {
        index = kUnreachableIndex;
      } else if (worstScallop >= 0.0) {
        index = std::clamp(static_cast<int>(worstScallop / (2.0 * h) * 10.0), 0, 9);
      }
      colour[b * bx + a] = index;
    }
  }

  // Page layout: the map scaled to fit 600 x 600 px, bars on the right.
  constexpr double kMargin = 40.0, kTop = 96.0, kMapSize = 600.0, kBarX = 60.0;
  const double width = static_cast<double>(design.columns) * design.spacing;
  const double height = static_cast<double>(design.rows) * design.spacing;
  const double scale = kMapSize / std::max(width, height);
  const double mapW = width * scale, mapH = height * scale;
  const double pageW = std::max(kMargin + mapW + kBarX + 200.0, 1000.0), pageH = kTop + mapH + 60.0;
  const double cell = static_cast<double>(block) * design.spacing * scale;
  // Block (a, b) covers x from x0 - d/2 + a block d; rows drawn top down (y up).
  auto pageX = [&](double x) { return kMargin + (x - (design.x0 - 0.5 * design.spacing)) * scale; };
  auto pageY = [&](double y) { return kTop + mapH - (y - (design.y0 - 0.5 * design.spacing)) * scale; };

  const std::string title = fmt::format("scallop verify: {} cut by {}", sources.surface, sources.program);
  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n",
      px(pageW), px(pageH));
  out += fmt::format("<title>{}</title>\n", escaped(title));
  out += "<style>\ntext { font-family: sans-serif; font-size: 13px; fill: #222222; }\n"
         ".title { font-size: 15px; font-weight: bold; }\n</style>\n";
  out += fmt::format("<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>\n", px(pageW), px(pageH));
  out += fmt::format("<text class=\"title\" x=\"{}\" y=\"22\">{}</text>\n", px(kMargin), escaped(title));
  out += fmt::format(
      "<text x=\"{}\" y=\"42\">R = {} {}, H = {} {}; deepest gouge {} {} (vertical), {} points beyond {} {} ({} {}&#178;)</text>\n",
      px(kMargin), lengthLabel(r.toolRadius), units, lengthLabel(h), units, lengthLabel(r.maxGouge), units,
      r.gougePoints, lengthLabel(r.gougeTolerance), units, lengthLabel(r.gougeArea), units);
  out += fmt::format(
      "<text x=\"{}\" y=\"60\">scallop (along the normal): max {} {}, 99th percentile {} {}, mean {} {}; above H on {} "
      "{}&#178;</text>\n",
      px(kMargin), lengthLabel(r.maxScallop), units, lengthLabel(r.scallopP99), units, lengthLabel(r.meanScallop), units,
      lengthLabel(r.uncutArea), units);
  out += fmt::format(
      "<text x=\"{}\" y=\"78\">beyond the ball's reach (left out of the scallop figures): {} {}&#178;, up to {} {} left</text>\n",
      px(kMargin), lengthLabel(r.unreachableArea), units, lengthLabel(r.maxUnreachableScallop), units);

  // One path per colour, in block units (a transform scales them to the page): each run of
  // blocks of one colour in a row is "M a b h n v 1 h -n z", some 15 bytes.
  std::array<std::string, 17> runs;
  for (std::size_t b = 0; b < by; ++b) {
    const std::size_t top = by - 1 - b;  // y up
    std::size_t a = 0;
    while (a < bx) {
      const int index = colour[b * bx + a];
      std::size_t end = a + 1;
      while (end < bx && colour[b * bx + end] == index) ++end;
      runs[static_cast<std::size_t>(index)] += fmt::format("M{} {}h{}v1h-{}z", a, top, end - a, end - a);
      a = end;
    }
  }
  out += fmt::format("<g transform=\"translate({},{}) scale({})\" shape-rendering=\"crispEdges\">\n",
                     px(pageX(design.x0 - 0.5 * design.spacing)), px(pageY(design.y0 - 0.5 * design.spacing) -
                                                                          static_cast<double>(by) * cell),
                     fmt::format("{:.6f}", cell));
  for (std::size_t index = 0; index < runs.size(); ++index) {
    if (runs[index].empty()) continue;
    out += fmt::format("<path fill=\"{}\" d=\"{}\"/>\n", colourOf(static_cast<int>(index)), runs[index]);
  }
  out += "</g>\n";
  out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#222222\"/>\n",
                     px(kMargin), px(kTop), px(mapW), px(mapH));
  // Axes: the extent's corners.
  out += fmt::format("<text x=\"{}\" y=\"{}\">x = {} {}</text>\n", px(kMargin), px(kTop + mapH + 18.0),
                     lengthLabel(design.x0), units);
  out += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"end\">x = {} {}</text>\n", px(kMargin + mapW),
                     px(kTop + mapH + 18.0), lengthLabel(design.x0 + width - design.spacing), units);
  out += fmt::format("<text x=\"{}\" y=\"{}\">y = {} {} (bottom) to {} {} (top), seen from above</text>\n",
                     px(kMargin), px(kTop + mapH + 36.0), lengthLabel(design.y0), units,
                     lengthLabel(design.y0 + height - design.spacing), units);
  if (r.maxGougeAt && r.maxGouge > r.gougeTolerance) {
    const double gx = pageX(r.maxGougeAt->x), gy = pageY(r.maxGougeAt->y);
    out += fmt::format(
        "<circle cx=\"{}\" cy=\"{}\" r=\"9\" fill=\"none\" stroke=\"#000000\" stroke-width=\"2\"/>\n"
        "<text x=\"{}\" y=\"{}\">deepest gouge</text>\n",
        px(gx), px(gy), px(gx + 12.0), px(gy - 10.0));
  }

  // Colour bars.
  const double barX = kMargin + mapW + 30.0, step = 24.0;
  out += fmt::format("<text x=\"{}\" y=\"{}\">scallop ({})</text>\n", px(barX), px(kTop + 10.0), units);
  for (int i = 0; i < 10; ++i) {
    const double y = kTop + 20.0 + (9 - i) * step;
    out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"20\" height=\"{}\" fill=\"{}\"/>\n", px(barX), px(y), px(step),
                       kScallopColours[static_cast<std::size_t>(i)]);
  }
  for (int i = 0; i <= 10; i += 5) {
    const double y = kTop + 20.0 + (10 - i) * step;
    const std::string label = i == 0 ? "0" : i == 5 ? fmt::format("{} (H)", lengthLabel(h))
                                                    : fmt::format("{} (2H) or more", lengthLabel(2.0 * h));
    out += fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", px(barX + 26.0), px(y + 4.0), label);
  }
  const double gougeTop = kTop + 20.0 + 10 * step + 40.0;
  out += fmt::format("<text x=\"{}\" y=\"{}\">gouge ({}, vertical)</text>\n", px(barX), px(gougeTop - 10.0), units);
  for (int i = 0; i < 5; ++i) {
    const double y = gougeTop + (4 - i) * step;
    out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"20\" height=\"{}\" fill=\"{}\"/>\n", px(barX), px(y), px(step),
                       kGougeColours[static_cast<std::size_t>(i)]);
  }
  for (int i = 1; i < 5; ++i) {  // the logarithmic steps' bounds
    out += fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", px(barX + 26.0), px(gougeTop + (5 - i) * step + 4.0),
                       lengthLabel(floorGouge * std::exp(gougeSpan * i / 5.0)));
  }
  out += fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", px(barX + 26.0), px(gougeTop + 5 * step + 4.0),
                     lengthLabel(r.gougeTolerance));
  out += fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", px(barX + 26.0), px(gougeTop + 4.0),
                     lengthLabel(gougeScaleTop));
  const double noneY = gougeTop + 5 * step + 30.0;
  out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"20\" height=\"{}\" fill=\"{}\"/>\n", px(barX), px(noneY),
                     px(step), kNoSurface);
  out += fmt::format("<text x=\"{}\" y=\"{}\">no surface</text>\n", px(barX + 26.0), px(noneY + 16.0));
  const double reachY = noneY + step + 8.0;
  out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"20\" height=\"{}\" fill=\"{}\"/>\n", px(barX), px(reachY),
                     px(step), kUnreachable);
  out += fmt::format("<text x=\"{}\" y=\"{}\">beyond the ball's reach</text>\n", px(barX + 26.0), px(reachY + 16.0));
  const double gridY = reachY + step;
  out += fmt::format("<text x=\"{}\" y=\"{}\">grid {} x {} points,</text>\n", px(barX), px(gridY + 36.0),
                     design.columns, design.rows);
  out += fmt::format("<text x=\"{}\" y=\"{}\">spacing {} {}</text>\n", px(barX), px(gridY + 54.0),
                     lengthLabel(design.spacing), units);
  if (block > 1)
    out += fmt::format("<text x=\"{}\" y=\"{}\">{} x {} points per square</text>\n", px(barX), px(gridY + 72.0),
                       block, block);
  out += "</svg>\n";
  return out;
}

}  // namespace scallop
