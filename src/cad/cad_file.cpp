// Reading STEP and IGES files through OpenCASCADE (see cad_file.hpp).

#include "cad/cad_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_BSplineSurfaceToBezierSurface.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_BezierCurve.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom2d_Line.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierCurve.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_Conic.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_Line.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_Plane.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TColGeom_Array2OfBezierSurface.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Wire.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

#include "support/input_file.hpp"
#include "scallop/error.hpp"


namespace scallop {
namespace detail {

std::string lowerCase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

bool endsWith(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

// What OCCT says in an exception, for messages.
std::string occtMessage(const Standard_Failure& failure) {
  const char* text = failure.GetMessageString();
  const std::string type = failure.DynamicType()->Name();
  return (text != nullptr && *text != '\0') ? fmt::format("{}: {}", type, text) : type;
}

std::mutex& cadMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace detail

namespace {

using detail::CadFile;
using detail::endsWith;
using detail::lowerCase;

// One of OCCT's process-wide reader parameters, set for the call and restored after, so that
// the result does not depend on what the host program set (and the host's setting survives).
class StaticParameter {
 public:
  StaticParameter(const char* name, const char* value) : name_(name) {
    if (!Interface_Static::IsPresent(name)) return;
    const char* old = Interface_Static::CVal(name);
    if (old != nullptr) saved_ = old;
    present_ = true;
    Interface_Static::SetCVal(name, value);
  }
  ~StaticParameter() {
    if (present_) Interface_Static::SetCVal(name_, saved_.c_str());
  }
  StaticParameter(const StaticParameter&) = delete;
  StaticParameter& operator=(const StaticParameter&) = delete;

 private:
  const char* name_;
  std::string saved_;
  bool present_ = false;
};

// --- the file before OCCT sees it ----------------------------------------------------------

// The text without a UTF-8 byte order mark and leading blanks.
std::string_view content(std::string_view text) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  return text;
}

std::string quoted(std::string_view text) {
  std::string shown(text.substr(0, 24));
  for (char& c : shown)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return fmt::format("'{}{}'", shown, text.size() > 24 ? "..." : "");
}

// An IGES file's lines, without line ends.
std::vector<std::string_view> lines(std::string_view text) {
  std::vector<std::string_view> result;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    result.push_back(line);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  while (!result.empty() && result.back().find_first_not_of(" \t") == std::string_view::npos) result.pop_back();
  return result;
}

// The checks OCCT's parsers do not make (they read what they can of a truncated file and
// transfer it): the header, and the end that only a complete file has.
void checkText(const std::string& text, CadFormat format) {
  if (text.empty()) throw Error("the file is empty");
  const std::string_view body = content(text);
  if (format == CadFormat::step) {
    if (!body.starts_with("ISO-10303-21;"))
      throw Error(fmt::format("not a STEP file: expected 'ISO-10303-21;' at the start, got {}", quoted(body)));
    std::string_view tail = body;
    while (!tail.empty() && std::isspace(static_cast<unsigned char>(tail.back()))) tail.remove_suffix(1);
    if (!tail.ends_with("END-ISO-10303-21;"))
      throw Error(fmt::format("truncated STEP file: it does not end with 'END-ISO-10303-21;' ({} bytes)", text.size()));
    return;
  }
  // IGES: 80-column lines, the section letter in column 73: S(tart), G(lobal), D(irectory),
  // P(arameter), T(erminate). The terminate line counts the lines of the other four.
  const std::vector<std::string_view> all = lines(text);
  if (all.empty() || all.front().size() < 73 || all.front()[72] != 'S')
    throw Error(fmt::format("not an IGES file: expected a start line with 'S' in column 73, got {}",
                            quoted(all.empty() ? std::string_view() : all.front())));
  const std::string_view last = all.back();
  if (last.size() < 73 || last[72] != 'T')
    throw Error(fmt::format("truncated IGES file: its last line ({}) is not the terminate line ('T' in column 73)",
                            all.size()));
  std::array<std::size_t, 4> counted{};
  constexpr std::string_view kSections = "SGDP";
  for (const std::string_view line : all) {
    if (line.size() < 73) continue;
    const std::size_t s = kSections.find(line[72]);
    if (s != std::string_view::npos) ++counted[s];
  }
  for (std::size_t s = 0; s < kSections.size(); ++s) {
    // The terminate line: "S      1G      4D     26P     40", an 8-column field per section.
    const std::size_t at = 8 * s;
    if (last.size() < at + 8 || last[at] != kSections[s])
      throw Error(fmt::format("malformed IGES terminate line {}", quoted(last)));
    std::size_t declared = 0;
    for (const char c : last.substr(at + 1, 7)) {
      if (c == ' ') continue;
      if (c < '0' || c > '9') throw Error(fmt::format("malformed IGES terminate line {}", quoted(last)));
      declared = declared * 10 + static_cast<std::size_t>(c - '0');
    }
    if (declared != counted[s])
      throw Error(fmt::format("truncated or damaged IGES file: the terminate line counts {} '{}' lines, the file has {}",
                              declared, kSections[s], counted[s]));
  }
}
// "#123" (STEP) or "D45" (IGES): the face's entity in the file, where OCCT's transfer
// records it; empty otherwise (shape healing may have replaced the face).
std::string entityLabel(const Handle(XSControl_WorkSession)& session, const TopoDS_Face& face) {
  try {
    const Handle(XSControl_TransferReader) transfer = session->TransferReader();
    if (transfer.IsNull()) return {};
    Handle(Standard_Transient) entity = transfer->EntityFromShapeResult(face, 1);
    if (entity.IsNull()) entity = transfer->EntityFromShapeResult(face, -1);
    if (entity.IsNull() || session->Model().IsNull()) return {};
    const Handle(TCollection_HAsciiString) label = session->Model()->StringLabel(entity);
    return label.IsNull() ? std::string() : std::string(label->ToCString());
  } catch (const Standard_Failure&) {
    return {};
  }
}

CadFile readStep(const std::string& path) {
  STEPControl_Reader reader;
  StaticParameter unit("xstep.cascade.unit", "MM");
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw Error("OpenCASCADE cannot parse it as STEP (damaged or not ISO 10303-21)");
  CadFile result;
  TColStd_SequenceOfAsciiString lengths, angles, solidAngles;
  reader.FileUnits(lengths, angles, solidAngles);
  bool inch = lengths.Length() > 0;
  for (int i = 1; i <= lengths.Length(); ++i) {
    const std::string name = lengths(i).ToCString();
    if (result.fileUnit.find(name) == std::string::npos)
      result.fileUnit += (result.fileUnit.empty() ? "" : ",") + name;
    inch = inch && lowerCase(name) == "inch";
  }
  result.units = inch ? Units::inch : Units::millimetre;
  // The system unit is the length unit of the shapes OCCT builds, in millimetres.
  reader.SetSystemLengthUnit(inch ? 25.4 : 1.0);
  result.roots = reader.NbRootsForTransfer();
  reader.TransferRoots();
  result.shape = reader.OneShape();
  result.session = reader.WS();
  return result;
}

CadFile readIges(const std::string& path) {
  IGESControl_Reader reader;
  StaticParameter unit("xstep.cascade.unit", "MM");
  // OCCT's default (1) raises C0 B-spline surfaces to C1 by removing knots within tolerance:
  // an approximation. 0 keeps them as written.
  StaticParameter continuity("read.iges.bspline.continuity", "0");
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) throw Error("OpenCASCADE cannot parse it as IGES (damaged)");
  CadFile result;
  const auto model = Handle(IGESData_IGESModel)::DownCast(reader.Model());
  if (model.IsNull()) throw Error("OpenCASCADE cannot parse it as IGES (no model)");
  IGESData_GlobalSection global = model->GlobalSection();
  const Handle(TCollection_HAsciiString) unitName = global.UnitName();
  result.fileUnit = unitName.IsNull() ? fmt::format("flag {}", global.UnitFlag()) : std::string(unitName->ToCString());
  // Unit flag 1 is the inch (IGES 5.3, global parameter 14); flag 3 names the unit in
  // parameter 15. OCCT scales the file's lengths to the "cascade unit" (millimetres per unit)
  // recorded in the model at parse time.
  const std::string named = unitName.IsNull() ? std::string() : lowerCase(unitName->ToCString());
  const bool inch = global.UnitFlag() == 1 || (global.UnitFlag() == 3 && (named == "in" || named == "inch"));
  result.units = inch ? Units::inch : Units::millimetre;
  global.SetCascadeUnit(inch ? 25.4 : 1.0);
  model->SetGlobalSection(global);
  result.roots = reader.NbRootsForTransfer();
  reader.TransferRoots();
  result.shape = reader.OneShape();
  result.session = reader.WS();
  return result;
}

}  // namespace

namespace detail {

CadFile readCadFile(const std::string& path, CadFormat format) {
  std::string text;
  try {
    text = detail::readInputFile(path);
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", path, error.what()));
  }
  try {
    checkText(text, format);
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", path, error.what()));
  }
  text.clear();
  text.shrink_to_fit();
  try {
    return format == CadFormat::step ? readStep(path) : readIges(path);
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", path, error.what()));
  } catch (const Standard_Failure& failure) {
    throw Error(fmt::format("{}: OpenCASCADE failed to read it as {} ({})", path, cadFormatName(format), occtMessage(failure)));
  }
}

std::string cadFaceName(const CadFile& file, const TopoDS_Face& face, std::size_t index) {
  const std::string label = entityLabel(file.session, face);
  return label.empty() ? fmt::format("face {}", index) : fmt::format("face {} ({})", index, label);
}

}  // namespace detail

std::string_view cadFormatName(CadFormat format) { return format == CadFormat::step ? "STEP" : "IGES"; }

std::optional<CadFormat> cadFormatOf(const std::string& path) {
  if (path == "-") return std::nullopt;
  const std::string lower = lowerCase(path);
  if (endsWith(lower, ".step") || endsWith(lower, ".stp")) return CadFormat::step;
  if (endsWith(lower, ".iges") || endsWith(lower, ".igs")) return CadFormat::iges;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return std::nullopt;
  char buffer[256];
  const std::size_t count = std::fread(buffer, 1, sizeof buffer, file);
  std::fclose(file);
  const std::string_view raw(buffer, count);
  if (content(raw).starts_with("ISO-10303-21;")) return CadFormat::step;
  // IGES's start line is blank up to its text: no blanks skipped.
  const std::string_view first = raw.substr(0, raw.find('\n'));
  if (first.size() >= 73 && first[72] == 'S' && (first.size() == 80 || (first.size() == 81 && first.back() == '\r')))
    return CadFormat::iges;
  return std::nullopt;
}

}  // namespace scallop
