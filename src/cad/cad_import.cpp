// STEP and IGES faces to Bezier patches through OpenCASCADE (see cad_import.hpp). OCCT's
// headers are confined to the scallop::cad target: the rest of scallop never sees them.

#include "scallop/cad/cad_import.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <ElSLib.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_BSplineSurfaceToBezierSurface.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2dConvert_BSplineCurveToBezierCurve.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_Conic.hxx>
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

#include "cad/cad_file.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/face_trim.hpp"

namespace scallop {
namespace {

// Weights of one Bezier piece within this relative spread are one weight: the piece is
// polynomial (knot insertion into equal weights rounds them by an ulp or two).
constexpr double kEqualWeights = 1e-14;
// The converted B-spline must reproduce the original surface to this fraction of the face's
// size at the sample points: OCCT's exact conversions agree to rounding (~1e-15), its
// approximations (1e-4 and coarser) do not.
constexpr double kConversionTolerance = 1e-9;
constexpr int kConversionSamples = 5;  // per direction

// A face refused: the reason (without file and face) and its kind for the summary.
struct FaceRefused {
  CadFaceIssue issue;
  std::string reason;
};

// A trimmed face that needs more pieces than the budget allows: an error naming the face, or
// with skipUnsupportedFaces a face skipped (the part then goes through its tessellation).
struct TrimBudgetExceeded {
  std::string reason;
};

// --- faces -----------------------------------------------------------------------------------

const char* surfaceKind(const Handle(Geom_Surface)& surface) {
  if (surface->IsKind(STANDARD_TYPE(Geom_Plane))) return "a plane";
  if (surface->IsKind(STANDARD_TYPE(Geom_CylindricalSurface))) return "a cylinder";
  if (surface->IsKind(STANDARD_TYPE(Geom_ConicalSurface))) return "a cone";
  if (surface->IsKind(STANDARD_TYPE(Geom_SphericalSurface))) return "a sphere";
  if (surface->IsKind(STANDARD_TYPE(Geom_ToroidalSurface))) return "a torus";
  if (surface->IsKind(STANDARD_TYPE(Geom_BSplineSurface))) return "a B-spline surface";
  if (surface->IsKind(STANDARD_TYPE(Geom_BezierSurface))) return "a Bezier surface";
  if (surface->IsKind(STANDARD_TYPE(Geom_SurfaceOfLinearExtrusion))) return "an extrusion";
  if (surface->IsKind(STANDARD_TYPE(Geom_SurfaceOfRevolution))) return "a surface of revolution";
  if (surface->IsKind(STANDARD_TYPE(Geom_OffsetSurface))) return "an offset surface";
  return surface->DynamicType()->Name();
}

// A curve OCCT converts to a B-spline exactly (GeomConvert::CurveToBSplineCurve is algebraic
// for these; it approximates offset curves).
bool exactCurve(Handle(Geom_Curve) curve) {
  while (curve->IsKind(STANDARD_TYPE(Geom_TrimmedCurve)))
    curve = Handle(Geom_TrimmedCurve)::DownCast(curve)->BasisCurve();
  return curve->IsKind(STANDARD_TYPE(Geom_Line)) || curve->IsKind(STANDARD_TYPE(Geom_Conic)) ||
         curve->IsKind(STANDARD_TYPE(Geom_BSplineCurve)) || curve->IsKind(STANDARD_TYPE(Geom_BezierCurve));
}

// The surface without rectangular trims (the face's UV rectangle trims it again) and with an
// offset replaced by its exact equivalent; refused when OCCT could only approximate it.
Handle(Geom_Surface) exactBasis(Handle(Geom_Surface) surface) {
  for (;;) {
    if (surface->IsKind(STANDARD_TYPE(Geom_RectangularTrimmedSurface))) {
      surface = Handle(Geom_RectangularTrimmedSurface)::DownCast(surface)->BasisSurface();
    } else if (surface->IsKind(STANDARD_TYPE(Geom_OffsetSurface))) {
      const auto offset = Handle(Geom_OffsetSurface)::DownCast(surface);
      Handle(Geom_Surface) equivalent = offset->Surface();
      if (equivalent.IsNull())
        throw FaceRefused{CadFaceIssue::unsupportedSurface,
                          fmt::format("is an offset ({}) of {}, which has no exact B-spline form: offset "
                                      "surfaces are not supported",
                                      offset->Offset(), surfaceKind(offset->BasisSurface()))};
      surface = equivalent;
    } else {
      break;
    }
  }
  if (surface->IsKind(STANDARD_TYPE(Geom_SurfaceOfLinearExtrusion)) ||
      surface->IsKind(STANDARD_TYPE(Geom_SurfaceOfRevolution))) {
    const auto swept = Handle(Geom_SweptSurface)::DownCast(surface);
    if (!exactCurve(swept->BasisCurve()))
      throw FaceRefused{CadFaceIssue::unsupportedSurface,
                        fmt::format("is {} of a {}, which has no exact B-spline form", surfaceKind(surface),
                                    swept->BasisCurve()->DynamicType()->Name())};
    return surface;
  }
  const bool known = surface->IsKind(STANDARD_TYPE(Geom_Plane)) || surface->IsKind(STANDARD_TYPE(Geom_CylindricalSurface)) ||
                     surface->IsKind(STANDARD_TYPE(Geom_ConicalSurface)) || surface->IsKind(STANDARD_TYPE(Geom_SphericalSurface)) ||
                     surface->IsKind(STANDARD_TYPE(Geom_ToroidalSurface)) || surface->IsKind(STANDARD_TYPE(Geom_BSplineSurface)) ||
                     surface->IsKind(STANDARD_TYPE(Geom_BezierSurface));
  if (!known)
    throw FaceRefused{CadFaceIssue::unsupportedSurface, fmt::format("has an unsupported surface kind, {}", surfaceKind(surface))};
  return surface;
}

// The face's parameter rectangle, when the face is one (see the contract's "trimming").
struct Rectangle {
  double u0, u1, v0, v1;
  double tolU, tolV;  // parametric tolerances (the edges' 3D tolerance mapped to u and v)
};

// The points that decide where a pcurve lies: its poles (a B-spline or Bezier lies in their
// convex hull) or, for a line, its ends; empty for any other curve.
std::vector<gp_Pnt2d> decidingPoints(Handle(Geom2d_Curve) curve, double first, double last) {
  while (curve->IsKind(STANDARD_TYPE(Geom2d_TrimmedCurve)))
    curve = Handle(Geom2d_TrimmedCurve)::DownCast(curve)->BasisCurve();
  std::vector<gp_Pnt2d> points;
  if (curve->IsKind(STANDARD_TYPE(Geom2d_Line))) {
    points = {curve->Value(first), curve->Value(last)};
  } else if (curve->IsKind(STANDARD_TYPE(Geom2d_BSplineCurve))) {
    // The edge may use part of the curve: the poles of that part decide.
    const auto spline = Handle(Geom2d_BSplineCurve)::DownCast(curve->Copy());
    const double lo = std::max(std::min(first, last), spline->FirstParameter());
    const double hi = std::min(std::max(first, last), spline->LastParameter());
    if ((lo > spline->FirstParameter() || hi < spline->LastParameter()) && hi - lo > Precision::PConfusion())
      spline->Segment(lo, hi);
    for (int i = 1; i <= spline->NbPoles(); ++i) points.push_back(spline->Pole(i));
  } else if (curve->IsKind(STANDARD_TYPE(Geom2d_BezierCurve))) {
    const auto bezier = Handle(Geom2d_BezierCurve)::DownCast(curve);
    for (int i = 1; i <= bezier->NbPoles(); ++i) points.push_back(bezier->Pole(i));
  }
  return points;
}

void snapToPeriods(Rectangle& r, const Handle(Geom_Surface)& surface);

// The edges' 3D tolerance as parameter tolerances of the surface (at least OCCT's parametric
// confusion).
void setParametricTolerances(Rectangle& r, const Handle(Geom_Surface)& surface, double tolerance3d) {
  const GeomAdaptor_Surface adaptor(surface);
  r.tolU = std::max(Precision::PConfusion(), adaptor.UResolution(tolerance3d));
  r.tolV = std::max(Precision::PConfusion(), adaptor.VResolution(tolerance3d));
}

Rectangle parameterRectangle(const TopoDS_Face& face, const Handle(Geom_Surface)& surface) {
  int wires = 0;
  for (TopoDS_Iterator it(face); it.More(); it.Next()) wires += it.Value().ShapeType() == TopAbs_WIRE ? 1 : 0;
  if (wires != 1)
    throw FaceRefused{CadFaceIssue::trimmed,
                      wires == 0 ? std::string("is trimmed (no boundary wire): trimmed faces are not supported yet")
                                 : fmt::format("is trimmed ({} wires: holes): trimmed faces are not supported yet", wires)};
  struct EdgeOnSurface {
    gp_Pnt2d first, last;
    std::vector<gp_Pnt2d> deciding;
    double tolerance;
    std::string kind;  // the pcurve's OCCT type, for messages
  };
  std::vector<EdgeOnSurface> edges;
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
    double first = 0.0, last = 0.0;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
    if (pcurve.IsNull())
      throw FaceRefused{CadFaceIssue::trimmed, fmt::format("has an edge ({}) without a curve in its parameter "
                                                           "plane: trimmed faces are not supported yet", edges.size())};
    edges.push_back({pcurve->Value(first), pcurve->Value(last), decidingPoints(pcurve, first, last),
                     BRep_Tool::Tolerance(edge), pcurve->DynamicType()->Name()});
  }
  if (edges.empty())
    throw FaceRefused{CadFaceIssue::trimmed, "is trimmed (a wire without edges): trimmed faces are not supported yet"};
  Rectangle r{edges[0].first.X(), edges[0].first.X(), edges[0].first.Y(), edges[0].first.Y(), 0.0, 0.0};
  double tolerance3d = 0.0;
  for (const EdgeOnSurface& e : edges) {
    for (const gp_Pnt2d& p : {e.first, e.last}) {
      r.u0 = std::min(r.u0, p.X());
      r.u1 = std::max(r.u1, p.X());
      r.v0 = std::min(r.v0, p.Y());
      r.v1 = std::max(r.v1, p.Y());
    }
    tolerance3d = std::max(tolerance3d, e.tolerance);
  }
  setParametricTolerances(r, surface, tolerance3d);
  // Each edge lies on one side; the sides' covered lengths add up (edges of a valid wire do
  // not overlap).
  std::array<double, 4> covered{};  // u = u0, u = u1, v = v0, v = v1
  const std::array<const char*, 4> sideNames{"u = u0", "u = u1", "v = v0", "v = v1"};
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const EdgeOnSurface& e = edges[i];
    const auto all = [&](auto onSide) {
      return !e.deciding.empty() && std::all_of(e.deciding.begin(), e.deciding.end(), onSide);
    };
    int side = -1;
    if (all([&](const gp_Pnt2d& p) { return std::abs(p.X() - r.u0) <= r.tolU; })) side = 0;
    else if (all([&](const gp_Pnt2d& p) { return std::abs(p.X() - r.u1) <= r.tolU; })) side = 1;
    else if (all([&](const gp_Pnt2d& p) { return std::abs(p.Y() - r.v0) <= r.tolV; })) side = 2;
    else if (all([&](const gp_Pnt2d& p) { return std::abs(p.Y() - r.v1) <= r.tolV; })) side = 3;
    if (side < 0)
      throw FaceRefused{CadFaceIssue::trimmed,
                        fmt::format("is trimmed (edge {} of {}, a {} from ({:.6g}, {:.6g}) to ({:.6g}, {:.6g}), is not an "
                                    "iso-line on a side of the rectangle [{:.6g}, {:.6g}] x [{:.6g}, {:.6g}] that the "
                                    "edges' ends span): trimmed faces are not supported yet",
                                    i, edges.size(), e.kind, e.first.X(), e.first.Y(), e.last.X(), e.last.Y(), r.u0,
                                    r.u1, r.v0, r.v1)};
    covered[static_cast<std::size_t>(side)] +=
        side < 2 ? std::abs(e.last.Y() - e.first.Y()) : std::abs(e.last.X() - e.first.X());
  }
  for (std::size_t side = 0; side < 4; ++side) {
    const double length = side < 2 ? r.v1 - r.v0 : r.u1 - r.u0;
    const double tol = side < 2 ? r.tolV : r.tolU;
    if (covered[side] < length - 2.0 * tol * static_cast<double>(edges.size()))
      throw FaceRefused{CadFaceIssue::trimmed,
                        fmt::format("is trimmed (its edges cover {:.6g} of the side {} of length {:.6g} of the parameter "
                                    "rectangle): trimmed faces are not supported yet",
                                    covered[side], sideNames[side], length)};
  }
  snapToPeriods(r, surface);
  return r;
}

// A closed face of a periodic surface spans one period (its pcurves' ends may overshoot it
// by rounding, and OCCT would wrap the excess into an empty trim); refused when empty.
void snapToPeriods(Rectangle& r, const Handle(Geom_Surface)& surface) {
  // Ends within tolerance of a multiple of the period are that multiple (the seam): OCCT's
  // conversions of quadrics fail on a full turn starting at -2e-13.
  const auto snapToPeriod = [](double& x, double period, double tol) {
    const double k = std::round(x / period) * period;
    if (std::abs(x - k) <= tol) x = k;
  };
  if (surface->IsUPeriodic()) {
    snapToPeriod(r.u0, surface->UPeriod(), r.tolU);
    snapToPeriod(r.u1, surface->UPeriod(), r.tolU);
    if (r.u1 - r.u0 > surface->UPeriod() - r.tolU) r.u1 = r.u0 + surface->UPeriod();
  }
  if (surface->IsVPeriodic()) {
    snapToPeriod(r.v0, surface->VPeriod(), r.tolV);
    snapToPeriod(r.v1, surface->VPeriod(), r.tolV);
    if (r.v1 - r.v0 > surface->VPeriod() - r.tolV) r.v1 = r.v0 + surface->VPeriod();
  }
  if (!(r.u1 - r.u0 > r.tolU) || !(r.v1 - r.v0 > r.tolV))
    throw FaceRefused{CadFaceIssue::trimmed, fmt::format("has an empty parameter rectangle [{:.6g}, {:.6g}] x [{:.6g}, {:.6g}]",
                                                         r.u0, r.u1, r.v0, r.v1)};
}

// The surface on the rectangle as a non-periodic B-spline, exactly (see the contract).
Handle(Geom_BSplineSurface) bsplineOn(const Handle(Geom_Surface)& basis, const Rectangle& r) {
  Handle(Geom_BSplineSurface) spline;
  if (basis->IsKind(STANDARD_TYPE(Geom_BSplineSurface))) {
    spline = Handle(Geom_BSplineSurface)::DownCast(basis->Copy());
  } else if (basis->IsKind(STANDARD_TYPE(Geom_BezierSurface))) {
    spline = GeomConvert::SurfaceToBSplineSurface(basis);
  } else {
    // Unbounded or periodic kinds: trimmed to the face first, so the conversion is bounded.
    spline = GeomConvert::SurfaceToBSplineSurface(new Geom_RectangularTrimmedSurface(basis, r.u0, r.u1, r.v0, r.v1));
  }
  const bool converted =
      !basis->IsKind(STANDARD_TYPE(Geom_BSplineSurface)) && !basis->IsKind(STANDARD_TYPE(Geom_BezierSurface));
  if (converted) {
    if (spline->IsUPeriodic()) spline->SetUNotPeriodic();
    if (spline->IsVPeriodic()) spline->SetVNotPeriodic();
    return spline;  // converted on the rectangle already
  }
  // A periodic direction: a face around the whole period is the whole closed surface (wherever
  // its seam), one period's copy; a face on part of it may cross the seam, so it is cut out of
  // the periodic surface itself (Segment works across the seam).
  double u0 = r.u0, u1 = r.u1, v0 = r.v0, v1 = r.v1;
  const bool fullU = spline->IsUPeriodic() && u1 - u0 >= spline->UPeriod() - r.tolU;
  const bool fullV = spline->IsVPeriodic() && v1 - v0 >= spline->VPeriod() - r.tolV;
  if (fullU) spline->SetUNotPeriodic();
  if (fullV) spline->SetVNotPeriodic();
  double bu0 = 0.0, bu1 = 0.0, bv0 = 0.0, bv1 = 0.0;
  spline->Bounds(bu0, bu1, bv0, bv1);
  // Ends within tolerance of (or, by a pcurve's rounding, beyond) the surface's are the
  // surface's: no sliver patch. Ends inside are snapped to knots by Segment's tolerances.
  const auto snap = [](double& lo, double& hi, double first, double last, double tol, bool periodic) {
    if (periodic) {
      if (std::abs(lo - first) <= tol) lo = first;
      if (std::abs(hi - last) <= tol) hi = last;
      return;
    }
    if (lo - first <= tol) lo = first;
    if (last - hi <= tol) hi = last;
  };
  snap(u0, u1, bu0, bu1, r.tolU, spline->IsUPeriodic());
  snap(v0, v1, bv0, bv1, r.tolV, spline->IsVPeriodic());
  if (fullU) u0 = bu0, u1 = bu1;
  if (fullV) v0 = bv0, v1 = bv1;
  if (spline->IsUPeriodic() || spline->IsVPeriodic() || u0 != bu0 || u1 != bu1 || v0 != bv0 || v1 != bv1)
    spline->Segment(u0, u1, v0, v1, r.tolU, r.tolV);
  if (spline->IsUPeriodic()) spline->SetUNotPeriodic();
  if (spline->IsVPeriodic()) spline->SetVNotPeriodic();
  return spline;
}

struct Weights {
  double min = 1.0, max = 1.0;
  bool polynomial() const { return max - min <= kEqualWeights * max; }
};

Weights weightsOf(const Handle(Geom_BezierSurface)& piece) {
  Weights w;
  if (!piece->IsURational() && !piece->IsVRational()) return w;
  TColStd_Array2OfReal weights(1, piece->NbUPoles(), 1, piece->NbVPoles());
  piece->Weights(weights);
  w.min = w.max = weights(1, 1);
  for (int i = 1; i <= piece->NbUPoles(); ++i)
    for (int j = 1; j <= piece->NbVPoles(); ++j) {
      w.min = std::min(w.min, weights(i, j));
      w.max = std::max(w.max, weights(i, j));
    }
  return w;
}

// The largest distance between the spline and the original surface at a grid of the
// rectangle, relative to the size of the spline's control net.
void checkConversion(const Handle(Geom_Surface)& original, const Handle(Geom_BSplineSurface)& spline, const Rectangle& r) {
  double size = 0.0;
  {
    const TColgp_Array2OfPnt& poles = spline->Poles();
    gp_XYZ lo = poles(poles.LowerRow(), poles.LowerCol()).XYZ(), hi = lo;
    for (int i = poles.LowerRow(); i <= poles.UpperRow(); ++i)
      for (int j = poles.LowerCol(); j <= poles.UpperCol(); ++j) {
        const gp_XYZ p = poles(i, j).XYZ();
        lo.SetCoord(std::min(lo.X(), p.X()), std::min(lo.Y(), p.Y()), std::min(lo.Z(), p.Z()));
        hi.SetCoord(std::max(hi.X(), p.X()), std::max(hi.Y(), p.Y()), std::max(hi.Z(), p.Z()));
      }
    size = (hi - lo).Modulus();
  }
  double su0 = 0.0, su1 = 0.0, sv0 = 0.0, sv1 = 0.0;
  spline->Bounds(su0, su1, sv0, sv1);
  const bool keepsParameters =
      original->IsKind(STANDARD_TYPE(Geom_BSplineSurface)) || original->IsKind(STANDARD_TYPE(Geom_BezierSurface));
  double worst = 0.0;
  for (int a = 0; a < kConversionSamples; ++a)
    for (int b = 0; b < kConversionSamples; ++b) {
      const double s = (a + 0.5) / kConversionSamples, t = (b + 0.5) / kConversionSamples;
      // A B-spline or Bezier surface keeps its parameters (Segment may have snapped the ends
      // to knots, so the spline's bounds need not be the rectangle's exactly); the others'
      // conversions map the rectangle onto the spline's bounds.
      const double U = su0 + s * (su1 - su0), V = sv0 + t * (sv1 - sv0);
      const gp_Pnt expected = keepsParameters ? original->Value(U, V)
                                              : original->Value(r.u0 + s * (r.u1 - r.u0), r.v0 + t * (r.v1 - r.v0));
      const gp_Pnt got = spline->Value(U, V);
      worst = std::max(worst, expected.Distance(got));
    }
  if (!(worst <= kConversionTolerance * size) && spline->IsURational() + spline->IsVRational() > 0) {
    // A rational conversion (conics: OCCT's circles are parametrised by tan(theta / 2), not
    // by theta) may reparametrise the surface: the same point set is then the test, each
    // side's samples within the tolerance of the other surface (projected onto it).
    worst = 0.0;
    const auto distanceTo = [](const gp_Pnt& point, const Handle(Geom_Surface)& surface) {
      GeomAPI_ProjectPointOnSurf projection(point, surface);
      return projection.NbPoints() > 0 ? projection.LowerDistance() : std::numeric_limits<double>::infinity();
    };
    for (int a = 0; a < kConversionSamples; ++a)
      for (int b = 0; b < kConversionSamples; ++b) {
        const double s = (a + 0.5) / kConversionSamples, t = (b + 0.5) / kConversionSamples;
        worst = std::max({worst, distanceTo(spline->Value(su0 + s * (su1 - su0), sv0 + t * (sv1 - sv0)), original),
                          distanceTo(original->Value(r.u0 + s * (r.u1 - r.u0), r.v0 + t * (r.v1 - r.v0)), spline)});
      }
  }
  if (!(worst <= kConversionTolerance * size))
    throw FaceRefused{CadFaceIssue::unsupportedSurface,
                      fmt::format("is {}, whose conversion to a B-spline is not exact (off by {:.3g}, {:.3g} of its size): not supported",
                                  surfaceKind(original), worst, size > 0.0 ? worst / size : worst)};
}

// --- trimmed faces (see the contract's "trimmed faces") ------------------------------------

// The face's trimming curves (every edge's pcurve, seam edges in both orientations) as rational
// Bezier arcs, exactly: OCCT's conversion of lines, conics, B-spline and Bezier curves is
// algebraic; any other kind is refused.
FaceTrim trimArcs(const TopoDS_Face& face) {
  FaceTrim trim;
  std::vector<TrimArc>& arcs = trim.arcs;
  std::size_t index = 0;
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next(), ++index) {
    const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
    double first = 0.0, last = 0.0;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
    if (pcurve.IsNull())
      throw FaceRefused{CadFaceIssue::trimmed,
                        fmt::format("has an edge ({}) without a curve in its parameter plane", index)};
    Handle(Geom2d_Curve) basis = pcurve;
    while (basis->IsKind(STANDARD_TYPE(Geom2d_TrimmedCurve)))
      basis = Handle(Geom2d_TrimmedCurve)::DownCast(basis)->BasisCurve();
    const bool exact = basis->IsKind(STANDARD_TYPE(Geom2d_Line)) || basis->IsKind(STANDARD_TYPE(Geom2d_Conic)) ||
                       basis->IsKind(STANDARD_TYPE(Geom2d_BSplineCurve)) ||
                       basis->IsKind(STANDARD_TYPE(Geom2d_BezierCurve));
    if (!exact)
      throw FaceRefused{CadFaceIssue::unsupportedSurface,
                        fmt::format("has a trimming curve (edge {}) that is a {}, which has no exact B-spline form",
                                    index, basis->DynamicType()->Name())};
    if (!(last > first)) continue;  // a point: bounds nothing
    const Handle(Geom2d_BSplineCurve) spline =
        Geom2dConvert::CurveToBSplineCurve(new Geom2d_TrimmedCurve(pcurve, first, last));
    Geom2dConvert_BSplineCurveToBezierCurve splitter(spline);
    for (int a = 1; a <= splitter.NbArcs(); ++a) {
      const Handle(Geom2d_BezierCurve) bezier = splitter.Arc(a);
      if (static_cast<std::size_t>(bezier->NbPoles()) > kMaxTrimPoles)
        throw FaceRefused{CadFaceIssue::unsupportedSurface,
                          fmt::format("has a trimming curve (edge {}) of degree {}, above the {} supported", index,
                                      bezier->Degree(), kMaxTrimPoles - 1)};
      TrimArc arc;
      for (int i = 1; i <= bezier->NbPoles(); ++i) {
        const gp_Pnt2d p = bezier->Pole(i);
        const double w = bezier->Weight(i);
        if (!(w > 0.0) || !std::isfinite(p.X()) || !std::isfinite(p.Y()))
          throw FaceRefused{CadFaceIssue::unsupportedSurface,
                            fmt::format("has a trimming curve (edge {}) with a pole ({}, {}) of weight {}", index,
                                        p.X(), p.Y(), w)};
        arc.push_back({w * p.X(), w * p.Y(), w});
      }
      // The loops close when each edge runs as its wire does: a REVERSED edge's pcurve backwards.
      if (edge.Orientation() == TopAbs_REVERSED) std::reverse(arc.begin(), arc.end());
      arcs.push_back(std::move(arc));
    }
  }
  if (arcs.empty()) throw FaceRefused{CadFaceIssue::trimmed, "is trimmed by no curve"};
  return trim;
}

// The rectangle of a trimmed face: its pcurves' bounds (BRepTools::UVBounds), within the
// surface's bounds in a non-periodic direction, one period at most in a periodic one.
Rectangle boundsRectangle(const TopoDS_Face& face, const Handle(Geom_Surface)& surface) {
  Rectangle r{};
  BRepTools::UVBounds(face, r.u0, r.u1, r.v0, r.v1);
  double tolerance3d = 0.0;
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next())
    tolerance3d = std::max(tolerance3d, BRep_Tool::Tolerance(TopoDS::Edge(it.Current())));
  setParametricTolerances(r, surface, tolerance3d);
  double su0 = 0.0, su1 = 0.0, sv0 = 0.0, sv1 = 0.0;
  surface->Bounds(su0, su1, sv0, sv1);
  if (!surface->IsUPeriodic()) r.u0 = std::max(r.u0, su0), r.u1 = std::min(r.u1, su1);
  if (!surface->IsVPeriodic()) r.v0 = std::max(r.v0, sv0), r.v1 = std::min(r.v1, sv1);
  snapToPeriods(r, surface);
  return r;
}

// The map from one Bezier piece's (s, t) in [0, 1]^2 (after the face's u reversal) to the
// face's (u, v) (see the contract's "trimmed faces").
class PieceParameters {
 public:
  PieceParameters(const Handle(Geom_Surface)& basis, const Handle(Geom_BSplineSurface)& spline, bool converted,
                  const Rectangle& rectangle, double knotU0, double knotU1, double knotV0, double knotV1,
                  bool reversed)
      : basis_(basis), spline_(spline), converted_(converted), rectangle_(rectangle), knotU0_(knotU0),
        knotU1_(knotU1), knotV0_(knotV0), knotV1_(knotV1), reversed_(reversed) {
    periodU_ = basis->IsUPeriodic() ? basis->UPeriod() : 0.0;
    periodV_ = basis->IsVPeriodic() ? basis->VPeriod() : 0.0;
    const double uc = 0.5 * (knotU0 + knotU1), vc = 0.5 * (knotV0 + knotV1);
    const gp_Pnt2d centre = rawParameters(uc, vc);
    // The centre's representative nearest the rectangle's middle (a point of the rectangle is
    // within half a period of it); every other value is taken nearest the centre's.
    centreU_ = nearest(centre.X(), 0.5 * (rectangle.u0 + rectangle.u1), periodU_);
    centreV_ = nearest(centre.Y(), 0.5 * (rectangle.v0 + rectangle.v1), periodV_);
    marginU_ = 1e-8 * (rectangle.u1 - rectangle.u0);
    marginV_ = 1e-8 * (rectangle.v1 - rectangle.v0);
    if (converted_) {
      // u = phi(U) and v = psi(V) alone: checked at the quarter points.
      for (const double f : {0.25, 0.75}) {
        const double driftU =
            std::abs(nearest(rawParameters(uc, knotV0 + f * (knotV1 - knotV0)).X(), centreU_, periodU_) - centreU_);
        const double driftV =
            std::abs(nearest(rawParameters(knotU0 + f * (knotU1 - knotU0), vc).Y(), centreV_, periodV_) - centreV_);
        if (!(driftU <= 100.0 * marginU_) || !(driftV <= 100.0 * marginV_))
          throw FaceRefused{CadFaceIssue::unsupportedSurface,
                            fmt::format("is {} whose B-spline form mixes its parameters (u moves by {:.3g}, v by "
                                        "{:.3g} along the other): its trimming curves cannot be followed",
                                        surfaceKind(basis), driftU, driftV)};
      }
    }
  }

  // The patch's trim (face_trim.hpp's PatchTrim) when each of its parameters maps onto the
  // face's affinely (B-spline and Bezier faces: the identity up to the period; planes; the
  // heights of cylinders and cones) or, on a converted face, by half-angles (the angles of
  // OCCT's rational quadratic circles): fitted through the ends and the middle, and checked
  // at the seven inner eighths against OCCT's parameters of the patch's points (kAxisMapFit of the
  // span); nullopt when neither fits.
  std::optional<PatchTrim> patchTrim(std::shared_ptr<const FaceTrim> face) {
    const auto atS = [&](double s) { return faceU(knotU0_ + (reversed_ ? 1.0 - s : s) * (knotU1_ - knotU0_)); };
    const auto atT = [&](double t) { return faceV(knotV0_ + t * (knotV1_ - knotV0_)); };
    std::optional<AxisMap> u = axisMap(atS), v = axisMap(atT);
    if (!u || !v) return std::nullopt;
    PatchTrim trim;
    trim.u = *u, trim.v = *v;
    trim.face = std::move(face);
    trim.margin = std::max(marginU_, marginV_);
    return trim;
  }

  // The face-parameter box that the patch cell maps onto, widened by the margins.
  ParameterBox box(const ParameterCell& cell) {
    const double sA = reversed_ ? 1.0 - cell.u1 : cell.u0, sB = reversed_ ? 1.0 - cell.u0 : cell.u1;
    const double ua = faceU(knotU0_ + sA * (knotU1_ - knotU0_)), ub = faceU(knotU0_ + sB * (knotU1_ - knotU0_));
    const double va = faceV(knotV0_ + cell.v0 * (knotV1_ - knotV0_)), vb = faceV(knotV0_ + cell.v1 * (knotV1_ - knotV0_));
    return {std::min(ua, ub) - marginU_, std::max(ua, ub) + marginU_, std::min(va, vb) - marginV_,
            std::max(va, vb) + marginV_};
  }

 private:
  // How closely a fitted map must follow OCCT's parameters, relative to its span: rounding
  // (the angles come from atan2 of points converted through the B-spline's poles).
  static constexpr double kAxisMapFit = 1e-11;

  template <typename At>
  std::optional<AxisMap> axisMap(At at) const {
    const double from = at(0.0), middle = at(0.5), to = at(1.0);
    const auto fits = [&](const AxisMap& map) {
      for (const double x : {0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875})
        if (!(std::abs(map.at(x) - at(x)) <= kAxisMapFit * std::abs(to - from))) return false;
      return true;
    };
    const AxisMap affine = AxisMap::affine(from, to);
    if (fits(affine)) return affine;
    if (!converted_) return std::nullopt;
    try {
      const AxisMap angles = AxisMap::halfAngle(from, middle, to);
      if (fits(angles)) return angles;
    } catch (const Error&) {  // not a monotone arc
    }
    return std::nullopt;
  }

  static double nearest(double x, double reference, double period) {
    return period > 0.0 ? x - period * std::round((x - reference) / period) : x;
  }

  // The basis surface's parameters of the B-spline's point (U, V).
  gp_Pnt2d rawParameters(double U, double V) const {
    if (!converted_) return {U, V};
    const gp_Pnt p = spline_->Value(U, V);
    double u = 0.0, v = 0.0;
    if (const auto plane = Handle(Geom_Plane)::DownCast(basis_); !plane.IsNull()) {
      ElSLib::Parameters(plane->Pln(), p, u, v);
    } else if (const auto cylinder = Handle(Geom_CylindricalSurface)::DownCast(basis_); !cylinder.IsNull()) {
      ElSLib::Parameters(cylinder->Cylinder(), p, u, v);
    } else if (const auto cone = Handle(Geom_ConicalSurface)::DownCast(basis_); !cone.IsNull()) {
      ElSLib::Parameters(cone->Cone(), p, u, v);
    } else if (const auto sphere = Handle(Geom_SphericalSurface)::DownCast(basis_); !sphere.IsNull()) {
      ElSLib::Parameters(sphere->Sphere(), p, u, v);
    } else if (const auto torus = Handle(Geom_ToroidalSurface)::DownCast(basis_); !torus.IsNull()) {
      ElSLib::Parameters(torus->Torus(), p, u, v);
    } else {
      const Rectangle& r = rectangle_;
      const double padU = 0.1 * (r.u1 - r.u0), padV = 0.1 * (r.v1 - r.v0);
      GeomAPI_ProjectPointOnSurf projection(p, basis_, r.u0 - padU, r.u1 + padU, r.v0 - padV, r.v1 + padV);
      if (projection.NbPoints() == 0 || !(projection.LowerDistance() <= kConversionTolerance * (1.0 + p.XYZ().Modulus())))
        throw FaceRefused{CadFaceIssue::unsupportedSurface,
                          fmt::format("is {} whose point ({:.6g}, {:.6g}, {:.6g}) has no parameters on it: its trimming "
                                      "curves cannot be followed",
                                      surfaceKind(basis_), p.X(), p.Y(), p.Z())};
      projection.LowerDistanceParameters(u, v);
    }
    return {u, v};
  }

  double faceU(double U) {
    const auto found = cacheU_.find(U);
    if (found != cacheU_.end()) return found->second;
    const double u = nearest(rawParameters(U, 0.5 * (knotV0_ + knotV1_)).X(), centreU_, periodU_);
    cacheU_.emplace(U, u);
    return u;
  }
  double faceV(double V) {
    const auto found = cacheV_.find(V);
    if (found != cacheV_.end()) return found->second;
    const double v = nearest(rawParameters(0.5 * (knotU0_ + knotU1_), V).Y(), centreV_, periodV_);
    cacheV_.emplace(V, v);
    return v;
  }

  Handle(Geom_Surface) basis_;
  Handle(Geom_BSplineSurface) spline_;
  bool converted_;
  Rectangle rectangle_;
  double knotU0_, knotU1_, knotV0_, knotV1_;
  bool reversed_;
  double periodU_ = 0.0, periodV_ = 0.0, centreU_ = 0.0, centreV_ = 0.0, marginU_ = 0.0, marginV_ = 0.0;
  std::map<double, double> cacheU_, cacheV_;
};

// What facePatches is doing, for the message when OCCT throws.
struct Stage {
  const char* what = "reading the face";
  std::optional<Rectangle> rectangle;  // once known
};

// A face's patches; a trimmed face's (acceptTrimmed) as pieces with their roles.
struct FacePatches {
  std::vector<BezierPatch> patches;
  std::vector<PieceRole> roles;
  bool trimmed = false;
  double largestSpreadRad = 0.0;
  FaceTrim trim;  // a trimmed face's arcs
  std::vector<PatchTrim> trims;  // keepTrims: per patch
};

FacePatches facePatches(const TopoDS_Face& face, Units units, Stage& stage, const CadImportOptions& options,
                        std::size_t& trimBudget) {
  const bool acceptRational = options.acceptRational;
  const Handle(Geom_Surface) located = BRep_Tool::Surface(face);  // the face's location applied
  if (located.IsNull()) throw FaceRefused{CadFaceIssue::unsupportedSurface, "has no surface"};
  const Handle(Geom_Surface) basis = exactBasis(located);
  stage.what = "checking its boundary";
  FacePatches result;
  Rectangle rectangle{};
  try {
    rectangle = parameterRectangle(face, basis);
  } catch (const FaceRefused& refused) {
    if (refused.issue != CadFaceIssue::trimmed || !options.acceptTrimmed) throw;
    result.trimmed = true;
    rectangle = boundsRectangle(face, basis);
  }
  stage.what = "converting it to a B-spline";
  stage.rectangle = rectangle;
  const Handle(Geom_BSplineSurface) spline = bsplineOn(basis, rectangle);
  stage.what = "splitting it into Bezier pieces";
  GeomConvert_BSplineSurfaceToBezierSurface splitter(spline);
  TColGeom_Array2OfBezierSurface pieces(1, splitter.NbUPatches(), 1, splitter.NbVPatches());
  splitter.Patches(pieces);

  Weights range;
  range.min = range.max = weightsOf(pieces(1, 1)).min;
  bool polynomial = true;
  for (int i = 1; i <= pieces.UpperRow(); ++i)
    for (int j = 1; j <= pieces.UpperCol(); ++j) {
      const Weights w = weightsOf(pieces(i, j));
      polynomial = polynomial && w.polynomial();
      range.min = std::min(range.min, w.min);
      range.max = std::max(range.max, w.max);
    }
  if (!polynomial && !acceptRational)
    throw FaceRefused{CadFaceIssue::rational,
                      fmt::format("is rational (weights {:.6g} to {:.6g}, {}): rational faces are not supported yet",
                                  range.min, range.max, surfaceKind(basis))};
  stage.what = "checking the conversion";
  checkConversion(basis, spline, rectangle);

  const bool reversed = face.Orientation() == TopAbs_REVERSED;
  std::vector<BezierPatch> patches;
  for (int i = 1; i <= pieces.UpperRow(); ++i)
    for (int j = 1; j <= pieces.UpperCol(); ++j) {
      const Handle(Geom_BezierSurface)& piece = pieces(i, j);
      BezierPatch patch;
      patch.degreeU = piece->UDegree();
      patch.degreeV = piece->VDegree();
      patch.control.reserve(static_cast<std::size_t>((patch.degreeU + 1) * (patch.degreeV + 1)));
      for (int a = 0; a <= patch.degreeU; ++a)
        for (int b = 0; b <= patch.degreeV; ++b) {
          // Reversing u flips r_u and so r_u x r_v: the normal then points out of the material.
          const gp_Pnt& p = piece->Pole(reversed ? patch.degreeU - a + 1 : a + 1, b + 1);
          patch.control.push_back({p.X(), p.Y(), p.Z()});
          if (!polynomial) patch.weights.push_back(piece->Weight(reversed ? patch.degreeU - a + 1 : a + 1, b + 1));
        }
      patches.push_back(std::move(patch));
    }
  // A trimmed face's patches need be regular only where the face is: its pieces are checked
  // after the split (a B-spline may be singular at a corner its trimming curves cut away).
  const auto validate = [&](const std::vector<BezierPatch>& checked, const std::string& what) {
    try {
      validateSurface(Surface{units, checked});
    } catch (const Error& error) {
      std::string message = error.what();
      if (message.starts_with("patches[")) message = what + " " + message.substr(8);  // "patches[i]..." of this face
      throw FaceRefused{CadFaceIssue::invalidPatch, fmt::format("has an invalid Bezier {} ({}, {} {}s)", message,
                                                                surfaceKind(basis), checked.size(), what)};
    }
  };
  if (!result.trimmed) validate(patches, "piece");
  if (!result.trimmed) {
    result.roles.assign(patches.size(), PieceRole::inside);
    result.patches = std::move(patches);
    return result;
  }
  stage.what = "following its trimming curves";
  result.trim = trimArcs(face);
  const FaceTrim& trim = result.trim;
  const auto shared = std::make_shared<const FaceTrim>(trim);
  std::vector<BezierPatch> whole;  // keepTrims: the patches that meet the face, with their trims
  const bool converted =
      !basis->IsKind(STANDARD_TYPE(Geom_BSplineSurface)) && !basis->IsKind(STANDARD_TYPE(Geom_BezierSurface));
  TColStd_Array1OfReal knotsU(1, splitter.NbUPatches() + 1), knotsV(1, splitter.NbVPatches() + 1);
  splitter.UKnots(knotsU);
  splitter.VKnots(knotsV);
  std::size_t index = 0;
  for (int i = 1; i <= pieces.UpperRow(); ++i)
    for (int j = 1; j <= pieces.UpperCol(); ++j, ++index) {
      PieceParameters parameters(basis, spline, converted, rectangle, knotsU(i), knotsU(i + 1), knotsV(j),
                                 knotsV(j + 1), reversed);
      // A rational piece weighs more (see CadImportOptions::maxTrimPieces).
      const std::size_t weight = patches[index].rational() ? kRationalPieceWeight : 1;
      TrimSplitOptions split = options.trimSplit;
      split.maxPieces = std::min(split.maxPieces, trimBudget / weight);
      if (split.maxPieces == 0)
        throw TrimBudgetExceeded{fmt::format("(piece {}): more than {} pieces in all (a rational piece counts {}) "
                                             "follow the part's trimming curves; a larger spread needs fewer",
                                             index, options.maxTrimPieces, kRationalPieceWeight)};
      TrimSplit pieceSplit;
      try {
        pieceSplit = splitTrimmedPatch(
            patches[index], [&](const ParameterCell& cell) { return classifyBox(trim, parameters.box(cell)); },
            split);
      } catch (const Error& error) {
        if (split.maxPieces < options.trimSplit.maxPieces)  // the file's budget ran out, not the patch's
          throw TrimBudgetExceeded{fmt::format("(piece {}): more than {} pieces in all (a rational piece counts {}) "
                                               "follow the part's trimming curves; a larger spread needs fewer",
                                               index, options.maxTrimPieces, kRationalPieceWeight)};
        throw TrimBudgetExceeded{fmt::format("(piece {}): {}; a larger spread needs fewer", index, error.what())};
      }
      trimBudget -= std::min(trimBudget, weight * pieceSplit.pieces.size());
      result.largestSpreadRad = std::max(result.largestSpreadRad, pieceSplit.largestSpreadRad);
      if (options.keepTrims && !pieceSplit.pieces.empty()) {
        std::optional<PatchTrim> patchTrim = parameters.patchTrim(shared);
        if (!patchTrim)
          throw FaceRefused{CadFaceIssue::trimmed,
                            fmt::format("is {} (piece {}), whose patches' parameters are neither an affine nor a "
                                        "half-angle image of the face's: its trim is followed by pieces only (not "
                                        "kept exactly)",
                                        surfaceKind(basis), index)};
        // A patch wholly inside its face needs no trim (its square classified inside: one
        // inside piece alone may be a quarter whose siblings lie outside).
        const bool inside = classifyBox(trim, parameters.box(ParameterCell{})) == CellPlace::inside;
        whole.push_back(patches[index]);
        result.trims.push_back(inside ? PatchTrim{} : *patchTrim);
      }
      for (TrimmedPiece& piece : pieceSplit.pieces) {
        result.patches.push_back(std::move(piece.patch));
        result.roles.push_back(piece.role);
      }
    }
  if (result.patches.empty())
    throw FaceRefused{CadFaceIssue::trimmed, "lies outside its own trimming curves (no piece of it is inside)"};
  validate(result.patches, "trimmed piece");
  if (options.keepTrims) {  // the pieces were for the checks: the patches are kept whole, trimmed
    result.patches = std::move(whole);
    result.roles.assign(result.patches.size(), PieceRole::inside);
  }
  return result;
}

}  // namespace


std::string_view cadFaceIssueName(CadFaceIssue issue) {
  switch (issue) {
    case CadFaceIssue::rational: return "rational";
    case CadFaceIssue::trimmed: return "trimmed";
    case CadFaceIssue::unsupportedSurface: return "unsupported surface";
    case CadFaceIssue::invalidPatch: return "invalid patch";
  }
  return "unknown";
}

CadImport importCad(const std::string& path, const CadImportOptions& options) {
  const std::optional<CadFormat> format = cadFormatOf(path);
  if (!format) throw Error(fmt::format("{}: not a STEP or IGES file (by its name or its first line)", path));
  return importCad(path, *format, options);
}

CadImport importCad(const std::string& path, CadFormat format, const CadImportOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::lock_guard<std::mutex> lock(detail::cadMutex());
  const detail::QuietMessages quiet;
  const detail::CadFile file = detail::readCadFile(path, format);
  CadImport result = detail::convertFaces(file, path, options, true);
  result.format = format;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

namespace {

// How far a face's edges may stand off its neighbours' (surface.hpp's seamTolerances): the
// largest tolerance of the face, its edges and its vertices (OCCT keeps tolerance(face) <=
// tolerance(edge) <= tolerance(vertex), but files do not always respect it).
double faceSeamTolerance(const TopoDS_Face& face) {
  double tolerance = BRep_Tool::Tolerance(face);
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next())
    tolerance = std::max(tolerance, BRep_Tool::Tolerance(TopoDS::Edge(it.Current())));
  for (TopExp_Explorer it(face, TopAbs_VERTEX); it.More(); it.Next())
    tolerance = std::max(tolerance, BRep_Tool::Tolerance(TopoDS::Vertex(it.Current())));
  return std::isfinite(tolerance) ? tolerance : 0.0;
}

}  // namespace

namespace detail {

CadImport convertFaces(const CadFile& transferred, const std::string& path, const CadImportOptions& options,
                       bool requireSome) {
  CadImport result;
  result.surface.units = transferred.units;
  result.fileUnit = transferred.fileUnit;

  std::size_t trimBudget = options.maxTrimPieces;
  std::size_t index = 0;
  for (TopExp_Explorer it(transferred.shape, TopAbs_FACE); it.More(); it.Next(), ++index) {
    const TopoDS_Face& face = TopoDS::Face(it.Current());
    try {
      FacePatches patches;
      Stage stage;
      try {
        patches = facePatches(face, transferred.units, stage, options, trimBudget);
      } catch (const Standard_Failure& failure) {
        throw FaceRefused{CadFaceIssue::unsupportedSurface,
                          fmt::format("could not be converted: OpenCASCADE failed {}{} ({})", stage.what,
                                      stage.rectangle ? fmt::format(" on [{:.17g}, {:.17g}] x [{:.17g}, {:.17g}]",
                                                                    stage.rectangle->u0, stage.rectangle->u1,
                                                                    stage.rectangle->v0, stage.rectangle->v1)
                                                      : std::string(),
                                      detail::occtMessage(failure))};
      }
      const double seam = faceSeamTolerance(face);
      for (std::size_t p = 0; p < patches.patches.size(); ++p) {
        result.surface.seamTolerances.push_back(seam);
        result.surface.patches.push_back(std::move(patches.patches[p]));
        result.patchFaces.push_back(index);
        result.patchRoles.push_back(patches.roles[p]);
        result.surface.trims.push_back(patches.trims.empty() ? PatchTrim{} : patches.trims[p]);
      }
      if (patches.trimmed) {
        ++result.trimmedFaces;
        result.faceTrims.emplace(index, std::move(patches.trim));
      }
      result.largestSpreadRad = std::max(result.largestSpreadRad, patches.largestSpreadRad);
    } catch (const TrimBudgetExceeded& exceeded) {
      const std::string name = detail::cadFaceName(transferred, face, index);
      if (!options.skipUnsupportedFaces) throw Error(fmt::format("{}: {} {}", path, name, exceeded.reason));
      result.skipped.push_back({index, CadFaceIssue::trimmed, fmt::format("{} {}", name, exceeded.reason)});
    } catch (const FaceRefused& refused) {
      const std::string name = detail::cadFaceName(transferred, face, index);
      if (!options.skipUnsupportedFaces) throw Error(fmt::format("{}: {} {}", path, name, refused.reason));
      result.skipped.push_back({index, refused.issue, fmt::format("{} {}", name, refused.reason)});
    }
  }
  result.faces = index;
  // No patch trimmed: no trims (surface.hpp: empty, or one per patch).
  if (std::none_of(result.surface.trims.begin(), result.surface.trims.end(),
                   [](const PatchTrim& trim) { return trim.trimmed(); }))
    result.surface.trims.clear();
  if (index == 0)
    throw Error(fmt::format("{}: no faces in the file ({} root entities transferred): nothing to machine", path,
                            transferred.roots));
  if (requireSome && result.surface.patches.empty())
    throw Error(fmt::format("{}: none of its {} faces can be imported exactly; the first: {}", path, index,
                            result.skipped.front().reason));
  return result;
}

}  // namespace detail
}  // namespace scallop
