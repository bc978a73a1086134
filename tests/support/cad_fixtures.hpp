#pragma once
// STEP and IGES files written by OpenCASCADE's own writers from faces built with BRepBuilderAPI,
// independently of scallop's importers: the inputs of cad_import_test.cpp and
// cad_tessellation_test.cpp.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRep_Builder.hxx>
#include <Geom_BSplineSurface.hxx>
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
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/surface_io.hpp"

namespace scallop::test {

namespace fs = std::filesystem;

// OCCT's writers print statistics on standard output: not in the test log.
// One of examples/surfaces/ (the paper's surfaces, the teapot), as the tests' originals.
inline Surface exampleFile(const std::string& name) {
  return readSurface(std::string(SCALLOP_EXAMPLES_DIR) + "/surfaces/" + name + ".json");
}

inline void quietOcct() { Message::DefaultMessenger()->ChangePrinters().Clear(); }

inline Handle(Geom_BSplineSurface) bsplineOf(const BezierPatch& patch, double scale = 1.0) {
  TColgp_Array2OfPnt poles(1, patch.degreeU + 1, 1, patch.degreeV + 1);
  for (int j = 0; j <= patch.degreeU; ++j)
    for (int k = 0; k <= patch.degreeV; ++k) {
      const Vec3& p = patch.at(j, k);
      poles(j + 1, k + 1) = gp_Pnt(scale * p.x, scale * p.y, scale * p.z);
    }
  TColStd_Array1OfReal knots(1, 2);
  knots(1) = 0.0;
  knots(2) = 1.0;
  TColStd_Array1OfInteger multsU(1, 2), multsV(1, 2);
  multsU.Init(patch.degreeU + 1);
  multsV.Init(patch.degreeV + 1);
  return new Geom_BSplineSurface(poles, knots, knots, multsU, multsV, patch.degreeU, patch.degreeV);
}

inline TopoDS_Face faceOf(const Handle(Geom_Surface)& surface) {
  BRepBuilderAPI_MakeFace make(surface, Precision::Confusion());
  EXPECT_TRUE(make.IsDone());
  return make.Face();
}

// Every patch of `surface` as a face of its own, in order.
inline TopoDS_Shape facesOf(const Surface& surface, double scale = 1.0) {
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  for (const BezierPatch& patch : surface.patches) builder.Add(compound, faceOf(bsplineOf(patch, scale)));
  return compound;
}

// OCCT's writers take the shape in millimetres (their "cascade unit") and convert to the
// file's `unit`, "MM" or "INCH" (IGES: "MM" or "IN"), with 13 (STEP) or 10 (IGES) significant
// digits: an inch file of coordinates p is written from the shape scaled by 25.4 (facesOf's
// scale).
inline void writeStep(const TopoDS_Shape& shape, const fs::path& path, const char* unit) {
  quietOcct();
  STEPControl_Controller::Init();
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  Interface_Static::SetCVal("write.step.unit", unit);
  STEPControl_Writer writer;
  ASSERT_EQ(writer.Transfer(shape, STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(writer.Write(path.string().c_str()), IFSelect_RetDone);
}

inline void writeIges(const TopoDS_Shape& shape, const fs::path& path, const char* unit) {
  quietOcct();
  IGESControl_Controller::Init();
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  IGESControl_Writer writer(unit, 1);  // 1: B-rep faces (type 510/514), not trimmed surfaces
  ASSERT_TRUE(writer.AddShape(shape));
  writer.ComputeModel();
  ASSERT_TRUE(writer.Write(path.string().c_str()));
}

class CadTempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "scallop-cad-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

}  // namespace scallop::test
