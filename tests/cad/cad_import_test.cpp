// Tests of STEP and IGES input (cad_import.hpp). The files are written here with
// OpenCASCADE's own writers from faces built independently of the importer (Bezier nets as
// B-spline surfaces, quadrics, located and reversed faces), read back by scallop::cad, and
// compared with their sources point by point; the optimal slicing angle must not change.
// Bad files must fail with one message naming the file (and the face), through the library
// and through the CLI, which then writes nothing.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <TopExp_Explorer.hxx>
#include <STEPControl_Reader.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <BRep_Tool.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRep_Builder.hxx>
#include <GC_MakeCircle.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_Plane.hxx>
#include <Geom_SphericalSurface.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Ax3.hxx>
#include <gp_Trsf.hxx>

#include <nlohmann/json.hpp>

#include "support/cad_fixtures.hpp"
#include "support/cli_fixture.hpp"
#include "support/message_checks.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/cad/cad_import.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

namespace fs = std::filesystem;
using scallop::BezierPatch;
using scallop::CadFormat;
using scallop::CadImport;
using scallop::Surface;
using scallop::Vec3;

using scallop::test::facesOf;
using scallop::test::quietOcct;
using scallop::test::faceOf;
using scallop::test::bsplineOf;
using scallop::test::writeIges;
using scallop::test::writeStep;
using CadImportTest = scallop::test::CadTempDir;


using scallop::test::exampleFile;

// The largest distance between the patches at an n x n grid (both in [0, 1]^2), relative to
// the size of `a`.
double patchDistance(const BezierPatch& a, const BezierPatch& b, int n = 25) {
  double worst = 0.0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
      worst = std::max(worst, norm(scallop::point(a, u, v) - scallop::point(b, u, v)));
    }
  return worst;
}

void expectSameSurface(const Surface& imported, const Surface& original, double tolerance, const std::string& what) {
  ASSERT_EQ(imported.patches.size(), original.patches.size()) << what;
  EXPECT_EQ(imported.units, original.units) << what;
  const double scale = scallop::surfaceScale(original);
  for (std::size_t i = 0; i < original.patches.size(); ++i) {
    EXPECT_EQ(imported.patches[i].degreeU, original.patches[i].degreeU) << what << " patch " << i;
    EXPECT_EQ(imported.patches[i].degreeV, original.patches[i].degreeV) << what << " patch " << i;
    EXPECT_LE(patchDistance(imported.patches[i], original.patches[i]), tolerance * scale) << what << " patch " << i;
  }
}

void expectSameSlicing(const Surface& imported, const Surface& original, const std::string& what) {
  const scallop::OptimalSlicing a = scallop::optimalSlicing(imported);
  const scallop::OptimalSlicing b = scallop::optimalSlicing(original);
  EXPECT_EQ(a.method, b.method) << what;
  EXPECT_NEAR(a.alphaRad, b.alphaRad, 1e-9) << what;
  EXPECT_NEAR(std::abs(dot(a.normal, b.normal)), 1.0, 1e-9) << what;
}

TEST_F(CadImportTest, PaperSurfacesThroughStepKeepEveryPointAndTheirOptimalAngle) {
  for (const std::string name : {"paper-1", "paper-2"}) {
    const Surface original = exampleFile(name);
    const fs::path path = dir_ / (name + ".step");
    writeStep(facesOf(original, 25.4), path, "INCH");
    const CadImport imported = scallop::importCad(path.string());
    EXPECT_EQ(imported.format, CadFormat::step);
    EXPECT_EQ(imported.fileUnit, "INCH");
    EXPECT_EQ(imported.faces, 1u);
    EXPECT_TRUE(imported.skipped.empty());
    expectSameSurface(imported.surface, original, 1e-12, name);

    // In millimetres the numbers are written as they are.
    const fs::path mm = dir_ / (name + "-mm.step");
    writeStep(facesOf(original), mm, "MM");
    Surface inMillimetres = original;
    inMillimetres.units = scallop::Units::millimetre;
    expectSameSurface(scallop::importCad(mm.string()).surface, inMillimetres, 1e-15, name + " (mm)");
    expectSameSlicing(imported.surface, original, name);
  }
}

TEST_F(CadImportTest, PaperSurfacesThroughIgesInInchesAndMillimetres) {
  for (const std::string name : {"paper-1", "paper-2"}) {
    const Surface original = exampleFile(name);
    const fs::path inch = dir_ / (name + ".igs");
    writeIges(facesOf(original, 25.4), inch, "IN");
    const CadImport imported = scallop::importCad(inch.string());
    EXPECT_EQ(imported.format, CadFormat::iges);
    // IGES numbers are written with 10 significant digits after the unit conversion.
    expectSameSurface(imported.surface, original, 1e-9, name + " (in)");
    expectSameSlicing(imported.surface, original, name + " (in)");

    const fs::path mm = dir_ / (name + "-mm.iges");
    writeIges(facesOf(original), mm, "MM");
    Surface inMillimetres = original;
    inMillimetres.units = scallop::Units::millimetre;
    expectSameSurface(scallop::importCad(mm.string()).surface, inMillimetres, 1e-12, name + " (mm)");
  }
}

TEST_F(CadImportTest, TeapotThroughStepAndIgesPatchByPatch) {
  const Surface original = exampleFile("teapot");
  const fs::path step = dir_ / "teapot.stp";
  writeStep(facesOf(original, 25.4), step, "INCH");
  const CadImport imported = scallop::importCad(step.string());
  EXPECT_EQ(imported.faces, 32u);
  expectSameSurface(imported.surface, original, 1e-12, "teapot.stp");
  for (std::size_t i = 0; i < imported.patchFaces.size(); ++i) EXPECT_EQ(imported.patchFaces[i], i);
  expectSameSlicing(imported.surface, original, "teapot.stp");

  const fs::path iges = dir_ / "teapot.iges";
  writeIges(facesOf(original, 25.4), iges, "IN");
  expectSameSurface(scallop::importCad(iges.string()).surface, original, 1e-9, "teapot.iges");
}

// A bicubic-by-quadratic B-spline with interior knots (one of them double, so the surface is
// only C^1 there) and random poles.
Handle(Geom_BSplineSurface) knottySpline() {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> noise(-0.3, 0.3);
  const std::vector<double> uKnots{0.0, 0.3, 0.5, 1.0};
  const std::vector<int> uMults{4, 1, 2, 4};
  const std::vector<double> vKnots{0.0, 0.4, 1.0};
  const std::vector<int> vMults{3, 1, 3};
  const int nu = 4 + 1 + 2 + 4 - 3 - 1, nv = 3 + 1 + 3 - 2 - 1;  // sum(mults) - degree - 1
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  for (int i = 1; i <= nu; ++i)
    for (int j = 1; j <= nv; ++j) poles(i, j) = gp_Pnt(i + noise(rng), 2.0 * j + noise(rng), noise(rng) + 0.1 * i * j);
  TColStd_Array1OfReal uk(1, 4), vk(1, 3);
  TColStd_Array1OfInteger um(1, 4), vm(1, 3);
  for (int i = 0; i < 4; ++i) uk(i + 1) = uKnots[static_cast<std::size_t>(i)], um(i + 1) = uMults[static_cast<std::size_t>(i)];
  for (int i = 0; i < 3; ++i) vk(i + 1) = vKnots[static_cast<std::size_t>(i)], vm(i + 1) = vMults[static_cast<std::size_t>(i)];
  return new Geom_BSplineSurface(poles, uk, vk, um, vm, 3, 2);
}

// The largest distance between a patch on [u0, u1] x [v0, v1] of `spline` and OCCT's own
// evaluation of it there.
double distanceToSpline(const BezierPatch& patch, const Handle(Geom_Surface)& spline, double u0, double u1, double v0,
                        double v1) {
  double worst = 0.0;
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; ++j) {
      const double s = i / 16.0, t = j / 16.0;
      const gp_Pnt q = spline->Value(u0 + s * (u1 - u0), v0 + t * (v1 - v0));
      worst = std::max(worst, norm(scallop::point(patch, s, t) - Vec3{q.X(), q.Y(), q.Z()}));
    }
  return worst;
}

TEST_F(CadImportTest, BSplineSplitsAtItsKnotsIntoPatchesThatReproduceIt) {
  const Handle(Geom_BSplineSurface) spline = knottySpline();
  const fs::path path = dir_ / "knots.step";
  writeStep(faceOf(spline), path, "MM");
  const CadImport imported = scallop::importCad(path.string());
  EXPECT_EQ(imported.surface.units, scallop::Units::millimetre);
  // Knot intervals: u [0, .3, .5, 1] -> 3, v [0, .4, 1] -> 2; u-interval major.
  ASSERT_EQ(imported.surface.patches.size(), 6u);
  const std::vector<double> us{0.0, 0.3, 0.5, 1.0}, vs{0.0, 0.4, 1.0};
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 2; ++j) {
      const BezierPatch& patch = imported.surface.patches[2 * i + j];
      EXPECT_EQ(patch.degreeU, 3);
      EXPECT_EQ(patch.degreeV, 2);
      EXPECT_LE(distanceToSpline(patch, spline, us[i], us[i + 1], vs[j], vs[j + 1]), 1e-12) << i << " " << j;
    }
}

TEST_F(CadImportTest, AFaceOnASubRectangleIsTheSurfaceRestrictedExactly) {
  const Handle(Geom_BSplineSurface) spline = knottySpline();
  // [0.2, 0.9] x [0.1, 0.4]: u crosses the knots 0.3 and 0.5, v ends at the knot 0.4.
  BRepBuilderAPI_MakeFace make(spline, 0.2, 0.9, 0.1, 0.4, Precision::Confusion());
  ASSERT_TRUE(make.IsDone());
  const fs::path path = dir_ / "sub.step";
  writeStep(make.Face(), path, "MM");
  const CadImport imported = scallop::importCad(path.string());
  ASSERT_EQ(imported.surface.patches.size(), 3u);
  const std::vector<double> us{0.2, 0.3, 0.5, 0.9};
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_LE(distanceToSpline(imported.surface.patches[i], spline, us[i], us[i + 1], 0.1, 0.4), 1e-12) << i;
}

TEST_F(CadImportTest, AFaceAcrossThePeriodicSeamOfABSplineIsCutOutOfTheRing) {
  // A periodic bicubic ring in u (period [0, 1), knots at quarters) by a cubic Bezier in v.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> noise(-0.1, 0.1);
  TColgp_Array2OfPnt poles(1, 4, 1, 4);
  for (int i = 1; i <= 4; ++i)
    for (int j = 1; j <= 4; ++j) {
      const double angle = 2.0 * M_PI * (i - 1) / 4.0;
      poles(i, j) = gp_Pnt((3.0 + noise(rng)) * std::cos(angle), (3.0 + noise(rng)) * std::sin(angle), j + noise(rng));
    }
  TColStd_Array1OfReal uKnots(1, 5), vKnots(1, 2);
  TColStd_Array1OfInteger uMults(1, 5), vMults(1, 2);
  for (int i = 1; i <= 5; ++i) uKnots(i) = (i - 1) / 4.0, uMults(i) = 1;
  vKnots(1) = 0.0, vKnots(2) = 1.0, vMults(1) = 4, vMults(2) = 4;
  const Handle(Geom_BSplineSurface) ring =
      new Geom_BSplineSurface(poles, uKnots, vKnots, uMults, vMults, 3, 3, true, false);
  ASSERT_TRUE(ring->IsUPeriodic());
  // u in [-0.25, 0.25]: across the seam at 0, two knot intervals.
  BRepBuilderAPI_MakeFace make(ring, -0.25, 0.25, 0.0, 1.0, Precision::Confusion());
  ASSERT_TRUE(make.IsDone());
  const fs::path path = dir_ / "seam.step";
  writeStep(make.Face(), path, "MM");
  const CadImport imported = scallop::importCad(path.string());
  ASSERT_EQ(imported.surface.patches.size(), 2u);
  EXPECT_LE(distanceToSpline(imported.surface.patches[0], ring, -0.25, 0.0, 0.0, 1.0), 1e-12);
  EXPECT_LE(distanceToSpline(imported.surface.patches[1], ring, 0.0, 0.25, 0.0, 1.0), 1e-12);
  // The whole ring: four patches, one per knot interval.
  const fs::path whole = dir_ / "ring.step";
  writeStep(faceOf(ring), whole, "MM");
  const CadImport all = scallop::importCad(whole.string());
  ASSERT_EQ(all.surface.patches.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_LE(distanceToSpline(all.surface.patches[i], ring, static_cast<double>(i) / 4.0, static_cast<double>(i + 1) / 4.0, 0.0, 1.0), 1e-12) << i;
}

TEST_F(CadImportTest, TheFaceLocationIsApplied) {
  const Surface original = exampleFile("paper-1");
  gp_Trsf rotation, translation;
  rotation.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 2, 3)), 0.7);
  translation.SetTranslation(gp_Vec(10.0, -4.0, 2.5));
  const gp_Trsf placement = translation * rotation;
  const TopoDS_Shape placed = faceOf(bsplineOf(original.patches[0])).Moved(TopLoc_Location(placement));
  const fs::path path = dir_ / "placed.step";
  writeStep(placed, path, "MM");
  const CadImport imported = scallop::importCad(path.string());
  ASSERT_EQ(imported.surface.patches.size(), 1u);
  double worst = 0.0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double u = i / 20.0, v = j / 20.0;
      const Vec3 p = scallop::point(original.patches[0], u, v);
      gp_Pnt q(p.x, p.y, p.z);
      q.Transform(placement);
      worst = std::max(worst, norm(scallop::point(imported.surface.patches[0], u, v) - Vec3{q.X(), q.Y(), q.Z()}));
    }
  EXPECT_LE(worst, 1e-12);
}

TEST_F(CadImportTest, AReversedFaceHasItsNormalFlipped) {
  const Surface original = exampleFile("paper-2");
  const fs::path path = dir_ / "reversed.step";
  writeStep(faceOf(bsplineOf(original.patches[0])).Reversed(), path, "MM");
  const CadImport imported = scallop::importCad(path.string());
  ASSERT_EQ(imported.surface.patches.size(), 1u);
  const BezierPatch& patch = imported.surface.patches[0];
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double u = i / 10.0, v = j / 10.0;
      // u reversed: the same point at (1 - u, v), the normal opposite.
      EXPECT_LE(norm(scallop::point(patch, u, v) - scallop::point(original.patches[0], 1.0 - u, v)), 1e-14);
      EXPECT_NEAR(dot(scallop::unitNormal(patch, u, v), scallop::unitNormal(original.patches[0], 1.0 - u, v)), -1.0, 1e-12);
    }
}

TEST_F(CadImportTest, APlanarRectangleIsOneBilinearPatch) {
  const Handle(Geom_Plane) plane = new Geom_Plane(gp_Ax3(gp_Pnt(1, 2, 3), gp_Dir(0, 0, 1), gp_Dir(1, 0, 0)));
  BRepBuilderAPI_MakeFace make(plane, -1.0, 4.0, 0.0, 2.0, Precision::Confusion());
  const fs::path path = dir_ / "plane.step";
  writeStep(make.Face(), path, "MM");
  const CadImport imported = scallop::importCad(path.string());
  ASSERT_EQ(imported.surface.patches.size(), 1u);
  const BezierPatch& patch = imported.surface.patches[0];
  EXPECT_EQ(patch.degreeU, 1);
  EXPECT_EQ(patch.degreeV, 1);
  EXPECT_LE(norm(scallop::point(patch, 0, 0) - Vec3{0, 2, 3}), 1e-14);
  EXPECT_LE(norm(scallop::point(patch, 1, 1) - Vec3{5, 4, 3}), 1e-14);
  EXPECT_NEAR(scallop::unitNormal(patch, 0.5, 0.5).z, 1.0, 1e-15);
}

std::string importError(const fs::path& path, const scallop::CadImportOptions& options = {}) {
  try {
    scallop::importCad(path.string(), options);
  } catch (const scallop::Error& error) {
    return error.what();
  }
  return {};
}

TEST_F(CadImportTest, RationalFacesAreRefusedWithTheirWeights) {
  const Handle(Geom_CylindricalSurface) cylinder = new Geom_CylindricalSurface(gp_Ax3(), 2.0);
  const Handle(Geom_SphericalSurface) sphere = new Geom_SphericalSurface(gp_Ax3(), 3.0);
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  builder.Add(compound, faceOf(bsplineOf(exampleFile("paper-1").patches[0])));
  builder.Add(compound, BRepBuilderAPI_MakeFace(cylinder, 0.0, M_PI / 2, 0.0, 5.0, Precision::Confusion()).Face());
  builder.Add(compound, BRepBuilderAPI_MakeFace(sphere, 0.0, 1.0, -0.5, 0.5, Precision::Confusion()).Face());
  const fs::path path = dir_ / "quadrics.step";
  writeStep(compound, path, "MM");
  scallop::test::expectMessageContains(importError(path), {path.string(), "face 1", "rational", "weights", "a cylinder",
                                                           "not supported yet"}, "cylinder");
  // Skipped on request: the B-spline face stays, the two quadrics are listed.
  scallop::CadImportOptions skip;
  skip.skipUnsupportedFaces = true;
  const CadImport imported = scallop::importCad(path.string(), skip);
  EXPECT_EQ(imported.faces, 3u);
  EXPECT_EQ(imported.surface.patches.size(), 1u);
  ASSERT_EQ(imported.skipped.size(), 2u);
  EXPECT_EQ(imported.skipped[0].face, 1u);
  EXPECT_EQ(imported.skipped[1].face, 2u);
  EXPECT_EQ(imported.skipped[1].issue, scallop::CadFaceIssue::rational);
  EXPECT_NE(imported.skipped[1].reason.find("a sphere"), std::string::npos) << imported.skipped[1].reason;
}

TEST_F(CadImportTest, TrimmedFacesAreRefused) {
  // A triangle on a plane, and a B-spline square with a hole.
  const TopoDS_Wire triangle = BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(4, 0, 0), gp_Pnt(0, 3, 0), true).Wire();
  const fs::path path = dir_ / "triangle.step";
  writeStep(BRepBuilderAPI_MakeFace(triangle).Face(), path, "MM");
  scallop::test::expectMessageContains(importError(path), {path.string(), "face 0", "trimmed", "not supported yet"},
                                       "triangle");

  const Handle(Geom_Plane) plane = new Geom_Plane(gp_Ax3());
  BRepBuilderAPI_MakeFace square(plane, -5.0, 5.0, -5.0, 5.0, Precision::Confusion());
  const TopoDS_Wire hole = BRepBuilderAPI_MakePolygon(gp_Pnt(-1, -1, 0), gp_Pnt(-1, 1, 0), gp_Pnt(1, 1, 0), gp_Pnt(1, -1, 0), true).Wire();
  square.Add(hole);
  const fs::path holed = dir_ / "holed.step";
  writeStep(square.Face(), holed, "MM");
  scallop::test::expectMessageContains(importError(holed), {holed.string(), "face 0", "trimmed", "2 wires"}, "hole");
}

TEST_F(CadImportTest, BadFilesNameTheFile) {
  const Surface paper = exampleFile("paper-1");
  const fs::path good = dir_ / "good.step";
  writeStep(facesOf(paper), good, "MM");
  const std::string text = scallop::test::readFile(good);
  const auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(dir_ / name, std::ios::binary) << content;
    return dir_ / name;
  };
  const struct {
    fs::path path;
    std::vector<std::string> parts;
  } cases[] = {
      {dir_ / "missing.step", {"missing.step", "cannot open"}},
      {write("empty.step", ""), {"empty.step", "empty"}},
      {write("half.step", text.substr(0, text.size() / 2)), {"half.step", "truncated"}},
      {write("garbage.step", "hello, world\n"), {"garbage.step", "not a STEP file"}},
      {write("garbage-body.stp", "ISO-10303-21;\nHEADER;\n#1 = ((((;\nEND-ISO-10303-21;\n"), {"garbage-body.stp"}},
      {write("empty.igs", ""), {"empty.igs", "empty"}},
      {write("garbage.iges", "not an iges file at all\n"), {"garbage.iges", "not an IGES file"}},
  };
  for (const auto& c : cases) scallop::test::expectMessageContains(importError(c.path), c.parts, c.path.string());

  // A STEP file with a vertex and no face.
  const fs::path vertex = dir_ / "vertex.step";
  writeStep(BRepBuilderAPI_MakeVertex(gp_Pnt(1, 2, 3)).Vertex(), vertex, "MM");
  scallop::test::expectMessageContains(importError(vertex), {"vertex.step", "no faces"}, "vertex");

  // An IGES file missing its last lines.
  const fs::path iges = dir_ / "good.igs";
  writeIges(facesOf(paper), iges, "MM");
  const std::string igesText = scallop::test::readFile(iges);
  const fs::path cut = write("cut.igs", igesText.substr(0, igesText.size() - 3 * 81));
  scallop::test::expectMessageContains(importError(cut), {"cut.igs", "truncated"}, "cut IGES");
}

TEST_F(CadImportTest, TheFormatComesFromTheNameOrTheFirstLine) {
  const fs::path step = dir_ / "part.STEP";
  writeStep(facesOf(exampleFile("paper-1")), step, "MM");
  EXPECT_EQ(scallop::cadFormatOf(step.string()), CadFormat::step);
  EXPECT_EQ(scallop::cadFormatOf((dir_ / "x.Igs").string()), CadFormat::iges);
  EXPECT_EQ(scallop::cadFormatOf((dir_ / "x.json").string()), std::nullopt);
  EXPECT_EQ(scallop::cadFormatOf("-"), std::nullopt);
  const fs::path renamed = dir_ / "part.dat";
  fs::copy_file(step, renamed);
  EXPECT_EQ(scallop::cadFormatOf(renamed.string()), CadFormat::step);
  const fs::path iges = dir_ / "part.igs", renamedIges = dir_ / "part.txt";
  writeIges(facesOf(exampleFile("paper-1")), iges, "MM");
  fs::copy_file(iges, renamedIges);
  EXPECT_EQ(scallop::cadFormatOf(renamedIges.string()), CadFormat::iges);
  EXPECT_EQ(scallop::importCad(renamedIges.string()).surface.patches.size(), 1u);
}

TEST_F(CadImportTest, TheSameFileGivesTheSamePatchesBitForBit) {
  const fs::path path = dir_ / "teapot.step";
  writeStep(facesOf(exampleFile("teapot"), 25.4), path, "INCH");
  const Surface a = scallop::importCad(path.string()).surface;
  const Surface b = scallop::importCad(path.string()).surface;
  EXPECT_EQ(scallop::surfaceToJson(a), scallop::surfaceToJson(b));
}

// OpenCASCADE's sample parts, from Debian's occt-misc (installed with
// libocct-data-exchange-dev): free-form faces not written by scallop. Every face is either
// imported and valid or refused with a reason; the counts are the README's.
TEST(CadImportSamples, OcctSamplePartsImportOrRefuseEveryFace) {
  const std::string root = "/usr/share/opencascade/data/";
  const struct {
    std::string file;
    std::size_t faces, accepted;
  } samples[] = {
      {"step/linkrods.step", 37, 2},
      {"iges/bearing.iges", 213, 158},
  };
  for (const auto& sample : samples) {
    const std::string path = root + sample.file;
    if (!fs::exists(path)) GTEST_SKIP() << path << " missing (Debian package occt-misc)";
    scallop::CadImportOptions skip;
    skip.skipUnsupportedFaces = true;
    const CadImport imported = scallop::importCad(path, skip);
    EXPECT_EQ(imported.faces, sample.faces) << path;
    EXPECT_EQ(imported.faces - imported.skipped.size(), sample.accepted) << path;
    EXPECT_NO_THROW(scallop::validateSurface(imported.surface)) << path;
    for (const scallop::SkippedFace& face : imported.skipped) EXPECT_FALSE(face.reason.empty());
  }
}

// Rational faces of a part nobody here wrote, as rational patches (orient's): OCCT's
// linkrods.step has 15 untrimmed rational faces (tori, cylinders, rational B-splines) beside
// its 2 polynomial ones. Every patch point, by scallop's quotient-rule evaluation, lies on
// its face's own OCCT surface (projected onto it by GeomAPI, an independent evaluation) to
// 1e-9 of the part's size; and the Gauss map of the 17 faces covers the sphere (alpha* = 0,
// certified).
TEST(CadImportSamples, RationalFacesOfLinkrodsAreExactRationalPatches) {
  const std::string path = "/usr/share/opencascade/data/step/linkrods.step";
  if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
  scallop::CadImportOptions options;
  options.skipUnsupportedFaces = true;
  options.acceptRational = true;
  const CadImport imported = scallop::importCad(path, options);
  EXPECT_EQ(imported.faces - imported.skipped.size(), 17u);
  for (const scallop::SkippedFace& face : imported.skipped) EXPECT_EQ(face.issue, scallop::CadFaceIssue::trimmed);
  // The same faces, read by OCCT alone, in the importer's order (TopExp_Explorer).
  quietOcct();
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  std::vector<TopoDS_Face> faces;
  for (TopExp_Explorer it(reader.OneShape(), TopAbs_FACE); it.More(); it.Next()) faces.push_back(TopoDS::Face(it.Current()));
  ASSERT_EQ(faces.size(), imported.faces);
  const double size = 2.0 * scallop::surfaceScale(imported.surface);
  std::size_t rational = 0, samples = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < imported.surface.patches.size(); ++i) {
    const BezierPatch& patch = imported.surface.patches[i];
    rational += patch.rational() ? 1 : 0;
    const Handle(Geom_Surface) surface = BRep_Tool::Surface(faces[imported.patchFaces[i]]);
    for (int a = 0; a <= 4; ++a)
      for (int b = 0; b <= 4; ++b) {
        const Vec3 p = scallop::point(patch, a / 4.0, b / 4.0);
        GeomAPI_ProjectPointOnSurf projection(gp_Pnt(p.x, p.y, p.z), surface);
        ASSERT_GT(projection.NbPoints(), 0);
        worst = std::max(worst, projection.LowerDistance());
        ++samples;
      }
  }
  std::printf("[          ] linkrods: %zu patches (%zu rational), %zu points, farthest %.3g from their faces\n",
              imported.surface.patches.size(), rational, samples, worst);
  EXPECT_GT(rational, 40u);
  EXPECT_LE(worst, 1e-9 * size);
  const scallop::OptimalSlicing slicing = scallop::optimalSlicing(imported.surface);
  EXPECT_TRUE(slicing.certified);
  // alpha* = 0: the normals cover the sphere. alpha is acos of the largest |n . N|, which
  // rounding may leave an ulp or two below 1: acos(1 - 4 eps) = sqrt(8 eps) = 4.2e-8 rad is
  // the resolution of acos there (the polish's contacts gave 1 - eps, 3.0e-8, once they
  // were searched on every patch alike).
  EXPECT_LE(slicing.alphaRad, std::sqrt(8.0 * std::numeric_limits<double>::epsilon()));
  EXPECT_EQ(slicing.certifiedAlphaRad, 0.0);
}

// --- the CLI ---------------------------------------------------------------------------------

class CadCli : public scallop::test::CliFixture {};

TEST_F(CadCli, OrientAndPlanTakeAStepFile) {
  const Surface paper = exampleFile("paper-1");
  writeStep(facesOf(paper, 25.4), workDir_ / "paper-1.step", "INCH");
  const scallop::test::RunResult orient = run("orient paper-1.step");
  ASSERT_EQ(orient.exitCode, 0) << orient.err;
  const auto json = nlohmann::json::parse(orient.out);
  EXPECT_NEAR(json["alpha_deg"].get<double>() * M_PI / 180.0, scallop::optimalSlicing(paper).alphaRad, 1e-9);
  EXPECT_NE(orient.err.find("STEP, 1 faces -> 1 Bezier patches, units in"), std::string::npos) << orient.err;

  const scallop::test::RunResult plan = run("plan paper-1.step --scallop-height 0.01 --out out --quiet");
  ASSERT_EQ(plan.exitCode, 0) << plan.err;
  const auto report = nlohmann::json::parse(scallop::test::readFile(workDir_ / "out" / "report.json"));
  EXPECT_EQ(report["units"], "in");
  EXPECT_LT(report["verification"]["max_gouge"].get<double>(), 1e-4);
  EXPECT_TRUE(fs::exists(workDir_ / "out" / "toolpath.ngc"));
}

// Every command takes a rational face exactly (bezier.hpp's rational patches): a part of a
// cylinder's side (radius 2, axis z, 1 rad of it, 5 long) has horizontal normals only, on one
// arc of the equator: alpha* = 90 deg at N* = z, certified; plan cuts it in horizontal
// contours on the rational patch itself (no tessellation), judged by its simulated cut and
// by `verify --fail-on-gouge`, and every ball centre stands R from the axis's cylinder.
TEST_F(CadCli, EveryCommandTakesARationalFaceExactly) {
  const Handle(Geom_CylindricalSurface) cylinder = new Geom_CylindricalSurface(gp_Ax3(), 2.0);
  writeStep(BRepBuilderAPI_MakeFace(cylinder, 0.0, 1.0, 0.0, 5.0, Precision::Confusion()).Face(),
            workDir_ / "cylinder.step", "MM");
  const scallop::test::RunResult orient = run("orient cylinder.step");
  ASSERT_EQ(orient.exitCode, 0) << orient.err;
  EXPECT_NE(orient.err.find("STEP, 1 faces -> "), std::string::npos) << orient.err;
  const auto json = nlohmann::json::parse(orient.out);
  EXPECT_NEAR(json["alpha_deg"].get<double>(), 90.0, 1e-9);
  EXPECT_TRUE(json["certified"].get<bool>());
  EXPECT_NEAR(std::abs(json["normal"][2].get<double>()), 1.0, 1e-9);
  // The patches are the cylinder exactly: every point at distance 2 from the axis.
  scallop::CadImportOptions options;
  options.acceptRational = true;
  const CadImport imported = scallop::importCad((workDir_ / "cylinder.step").string(), options);
  ASSERT_FALSE(imported.surface.patches.empty());
  for (const BezierPatch& patch : imported.surface.patches) {
    EXPECT_TRUE(patch.rational());
    for (int i = 0; i <= 10; ++i)
      for (int j = 0; j <= 10; ++j) {
        const Vec3 p = scallop::point(patch, i / 10.0, j / 10.0);
        EXPECT_NEAR(std::hypot(p.x, p.y), 2.0, 1e-12);
        EXPECT_GE(p.z, -1e-12);
        EXPECT_LE(p.z, 5.0 + 1e-12);
      }
  }
  EXPECT_THROW((void)scallop::importCad((workDir_ / "cylinder.step").string()), scallop::Error);  // not by default
  const scallop::test::RunResult plan = run("plan cylinder.step --tool-radius 0.5 --scallop-height 0.05 --out out --quiet");
  ASSERT_EQ(plan.exitCode, 0) << plan.err;
  const auto report = nlohmann::json::parse(scallop::test::readFile(workDir_ / "out" / "report.json"));
  EXPECT_FALSE(report.contains("tessellation"));
  EXPECT_LE(report["verification"]["max_gouge"].get<double>(), report["verification"]["gouge_tolerance"].get<double>());
  const scallop::test::RunResult verify =
      run("verify cylinder.step out/toolpath.ngc --radius 0.5 --scallop-height 0.05 --fail-on-gouge");
  EXPECT_EQ(verify.exitCode, 0) << verify.err;
  // The wall faces +-x, +-y within its 1 rad arc; the cutting moves' ball centres beside it stand
  // 2.5 from the axis (outside) to the G-code's 4 decimals, or above its top.
  const scallop::GcodeProgram program = scallop::readGcodeProgram((workDir_ / "out" / "toolpath.ngc").string());
  std::size_t beside = 0;
  for (const scallop::SweptMove& move : scallop::sweptMoves(program, 0.5)) {
    if (move.rapid) continue;
    const Vec3 c = move.end;
    const double angle = std::atan2(c.y, c.x);
    if (c.z > 5.0 || angle < 0.0 || angle > 1.0) continue;
    EXPECT_NEAR(std::hypot(c.x, c.y), 2.5, 1e-3) << c.x << ", " << c.y << ", " << c.z;
    ++beside;
  }
  EXPECT_GT(beside, 100u);
}

TEST_F(CadCli, BadFilesFailCleanly) {
  write("empty.step", "");
  expectCleanFailure(run("orient empty.step"), {"empty.step", "empty"}, "empty.step");
  fs::remove(workDir_ / "empty.step");
  write("garbage.igs", "garbage\n");
  expectCleanFailure(run("plan garbage.igs --out out"), {"garbage.igs", "not an IGES file"}, "garbage.igs");
  fs::remove(workDir_ / "garbage.igs");

  // A plane with a square hole: plan and paths take such a part through its tessellation;
  // asked for the exact faces alone, none is left, and the message says why.
  BRepBuilderAPI_MakeFace square(new Geom_Plane(gp_Ax3()), -5.0, 5.0, -5.0, 5.0, Precision::Confusion());
  square.Add(BRepBuilderAPI_MakePolygon(gp_Pnt(-1, -1, 0), gp_Pnt(-1, 1, 0), gp_Pnt(1, 1, 0), gp_Pnt(1, -1, 0), true).Wire());
  writeStep(square.Face(), workDir_ / "holed.step", "MM");
  expectCleanFailure(run("paths holed.step --skip-faces --tool-radius 1 --scallop-height 0.01 --json out.json"),
                     {"holed.step", "none of its 1 faces", "face 0", "trimmed"}, "holed.step");
  expectCleanFailure(run("plan holed.step --skip-faces --out out"), {"holed.step", "none of its 1 faces"},
                     "holed.step");
  const std::string text = scallop::test::readFile(workDir_ / "holed.step");
  fs::remove(workDir_ / "holed.step");
  write("cut.step", text.substr(0, text.size() - 40));
  expectCleanFailure(run("paths cut.step --tool-radius 1 --scallop-height 0.01 --json out.json"), {"cut.step", "truncated"},
                     "cut.step");
}

}  // namespace
