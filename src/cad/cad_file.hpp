#pragma once
// Reading STEP and IGES files through OpenCASCADE: what the scallop::cad target's importers
// (cad_import.cpp: exact Bezier patches; cad_tessellation.cpp: the tessellated part and its
// exact heights) share. Private to that target: it includes OCCT's headers.

#include <cstddef>
#include <mutex>
#include <string>

#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <XSControl_WorkSession.hxx>

#include "scallop/cad/cad_import.hpp"

namespace scallop::detail {

std::string lowerCase(std::string text);
bool endsWith(const std::string& text, const std::string& tail);

// What OCCT says in an exception, for messages.
std::string occtMessage(const Standard_Failure& failure);

// OCCT's console messages (transfer statistics, parse warnings) would mix with scallop's
// output, JSON on standard output included: its default messenger's printers are taken away
// for the call and given back after.
class QuietMessages {
 public:
  QuietMessages() : messenger_(Message::DefaultMessenger()) {
    if (messenger_.IsNull()) return;
    saved_ = messenger_->Printers();
    messenger_->ChangePrinters().Clear();
  }
  ~QuietMessages() {
    if (!messenger_.IsNull()) messenger_->ChangePrinters() = saved_;
  }
  QuietMessages(const QuietMessages&) = delete;
  QuietMessages& operator=(const QuietMessages&) = delete;

 private:
  Handle(Message_Messenger) messenger_;
  Message_SequenceOfPrinters saved_;
};

// A STEP or IGES file as OCCT transferred it, and what the file says of its units.
struct CadFile {
  TopoDS_Shape shape;
  Units units = Units::millimetre;
  std::string fileUnit;
  Handle(XSControl_WorkSession) session;
  int roots = 0;
};

// The file at `path` read as `format`: the checks of cad_import.hpp's contract (empty, not
// that format, truncated), then OCCT's parse and transfer into the file's units. Errors are
// scallop::Error naming the path. The caller holds cadMutex() and a QuietMessages.
CadFile readCadFile(const std::string& path, CadFormat format);

// "face 3" or "face 3 (#812)": the face's index and, where OCCT's transfer recorded it, its
// entity in the file.
std::string cadFaceName(const CadFile& file, const TopoDS_Face& face, std::size_t index);

// The faces of `file` converted to exact Bezier patches (cad_import.hpp's contract; `path`
// for messages). With requireSome, a file none of whose faces converts is refused (with
// skipUnsupportedFaces); without, the result may have no patch. The caller holds cadMutex().
CadImport convertFaces(const CadFile& file, const std::string& path, const CadImportOptions& options,
                       bool requireSome);

// OCCT's reader parameters and message printers are process-wide: every call into the
// readers holds this.
std::mutex& cadMutex();

}  // namespace scallop::detail
