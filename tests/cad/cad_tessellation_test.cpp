// CadPart (cad_tessellation.hpp): the tessellation of STEP and IGES parts whose faces are
// trimmed or rational, the deviation it reports against a dense independent sample, the exact
// heights against closed forms and against scallop's own Bezier design, and `scallop plan` /
// `scallop verify` on such parts, judged by OCCT's exact point-to-solid distance.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <BRep_Tool.hxx>
#include <BRepBndLib.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <Bnd_Box.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepLib.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepTools.hxx>
#include <Geom2d_Circle.hxx>
#include <gp_Ax2.hxx>
#include <gp_Ax2d.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Wire.hxx>

#include <nlohmann/json.hpp>

#include "support/cad_fixtures.hpp"
#include "support/cli_fixture.hpp"
#include "support/message_checks.hpp"
#include "scallop/cad/cad_import.hpp"
#include "scallop/cad/cad_tessellation.hpp"
#include "scallop/geometry/face_trim.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/slicing/mesh_slicing.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/section.hpp"
#include "scallop/io/surface_io.hpp"

namespace {

namespace fs = std::filesystem;
using scallop::CadPart;
using scallop::CellPlace;
using scallop::CadTessellation;
using scallop::HeightGrid;
using scallop::Surface;
using scallop::Vec3;
using scallop::test::CadTempDir;
using scallop::test::writeIges;
using scallop::test::writeStep;

constexpr double kInf = std::numeric_limits<double>::infinity();

// `call` throws scallop::Error naming every one of `parts`.
template <class Call>
void expectErrorMentions(Call call, const std::vector<std::string>& parts) {
  try {
    call();
  } catch (const scallop::Error& error) {
    scallop::test::expectMessageContains(error.what(), parts, "the call");
    return;
  }
  ADD_FAILURE() << "accepted; expected an error naming " << parts.front();
}
const std::string kExamples = SCALLOP_EXAMPLES_DIR;
const std::string kOcctSamples = "/usr/share/opencascade/data";

using scallop::test::exampleFile;

// A 20 x 20 x 10 mm block with a cylindrical pocket of radius 4 around (10, 10) down to z = 6:
// its top face is trimmed by the pocket's rim and the pocket's wall is a cylinder (rational).
TopoDS_Shape pocketBlock() {
  const TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 20.0, 20.0, 10.0).Shape();
  const TopoDS_Shape pocket = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(10, 10, 6), gp_Dir(0, 0, 1)), 4.0, 10.0).Shape();
  BRepAlgoAPI_Cut cut(block, pocket);
  EXPECT_TRUE(cut.IsDone());
  return cut.Shape();
}

// The block's height over (x, y), in closed form; NaN within `band` of an edge seen from above
// (where a vertical line grazes a wall and either answer is right).
double pocketBlockHeight(double x, double y, double band) {
  const double r = std::hypot(x - 10.0, y - 10.0);
  const double inside = std::min({x, 20.0 - x, y, 20.0 - y});
  if (std::abs(r - 4.0) < band || std::abs(inside) < band) return std::nan("");
  if (inside < 0.0) return -kInf;
  return r < 4.0 ? 6.0 : 10.0;
}

// Paper-1's patch (inches, written in mm) trimmed to the disk of radius 0.3 around the middle
// of its parameter square: x = 3 v, y = 3 u on that patch, so the face is the part of the
// surface over the disk of radius 0.9 in around (1.5, 1.5) in.
TopoDS_Shape paperDiskFace(const Surface& paper, const std::vector<double>& knots = {}) {
  const Handle(Geom_BSplineSurface) surface = scallop::test::bsplineOf(paper.patches[0], 25.4);
  for (const double knot : knots) {  // split into more Bezier patches (full multiplicity)
    surface->InsertUKnot(knot, 3, 1e-12);
    surface->InsertVKnot(knot, 3, 1e-12);
  }
  const Handle(Geom2d_Circle) circle = new Geom2d_Circle(gp_Ax2d(gp_Pnt2d(0.5, 0.5), gp_Dir2d(1, 0)), 0.3);
  TopoDS_Edge edge = BRepBuilderAPI_MakeEdge(circle, surface).Edge();
  BRepLib::BuildCurves3d(edge);
  const TopoDS_Wire wire = BRepBuilderAPI_MakeWire(edge).Wire();
  BRepBuilderAPI_MakeFace face(surface, wire, Standard_True);
  EXPECT_TRUE(face.IsDone());
  return face.Face();
}

HeightGrid gridOver(double x0, double y0, double x1, double y1, double spacing) {
  HeightGrid grid;
  grid.x0 = x0;
  grid.y0 = y0;
  grid.spacing = spacing;
  grid.columns = static_cast<std::size_t>(std::floor((x1 - x0) / spacing)) + 1;
  grid.rows = static_cast<std::size_t>(std::floor((y1 - y0) / spacing)) + 1;
  grid.z.assign(grid.columns * grid.rows, -kInf);
  return grid;
}

// The distance from p to triangle abc by brute force over a fine barycentric lattice and the
// edges' closest points: an upper bound of the true distance within (lattice step x size).
// (Not the code under test's closed form.)
double distanceToTriangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  // Project onto the plane; inside the triangle the distance is the plane's.
  const Vec3 n = cross(b - a, c - a);
  const double area2 = dot(n, n);
  const Vec3 q = p - (dot(p - a, n) / area2) * n;
  const double wa = dot(cross(b - q, c - q), n) / area2, wb = dot(cross(c - q, a - q), n) / area2;
  const double wc = 1.0 - wa - wb;
  if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) return norm(p - q);
  double best = kInf;
  const auto segment = [&](Vec3 s, Vec3 e) {
    const Vec3 d = e - s;
    const double t = std::clamp(dot(p - s, d) / dot(d, d), 0.0, 1.0);
    best = std::min(best, norm(p - (s + t * d)));
  };
  segment(a, b);
  segment(b, c);
  segment(c, a);
  return best;
}

// The distance from p to the mesh, over the triangles whose bounding box grown by `reach`
// contains p (every triangle that can be within `reach`); infinity when none.
double distanceToMesh(const scallop::Mesh& mesh, Vec3 p, double reach) {
  double best = kInf;
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    if (p.x < std::min({a.x, b.x, c.x}) - reach || p.x > std::max({a.x, b.x, c.x}) + reach) continue;
    if (p.y < std::min({a.y, b.y, c.y}) - reach || p.y > std::max({a.y, b.y, c.y}) + reach) continue;
    if (p.z < std::min({a.z, b.z, c.z}) - reach || p.z > std::max({a.z, b.z, c.z}) + reach) continue;
    best = std::min(best, distanceToTriangle(p, a, b, c));
  }
  return best;
}

// --- tessellation -----------------------------------------------------------------------------

using CadTessellationTest = CadTempDir;

TEST_F(CadTessellationTest, TheMeshOfATrimmedFreeFormFaceIsWithinItsReportedDeviationOfADenseSample) {
  const Surface paper = exampleFile("paper-1");
  const fs::path path = dir_ / "disk.step";
  writeStep(paperDiskFace(paper), path, "INCH");
  const CadPart part(path.string());
  EXPECT_EQ(part.units(), scallop::Units::inch);
  EXPECT_EQ(part.faces(), 1u);
  const scallop::CadImport exact = part.exactFaces();
  ASSERT_EQ(exact.skipped.size(), 1u);
  EXPECT_EQ(exact.skipped[0].issue, scallop::CadFaceIssue::trimmed);

  for (const double deflection : {0.01, 0.002}) {
    scallop::TessellationOptions options;
    options.deflection = deflection;
    const CadTessellation mesh = part.tessellate(options);
    ASSERT_GT(mesh.mesh.triangles.size(), 10u);
    EXPECT_EQ(mesh.mesh.units, scallop::Units::inch);
    EXPECT_GT(mesh.deviation, 0.0);
    EXPECT_EQ(mesh.deviationSamples, 12 * mesh.mesh.triangles.size());
    // Every vertex lies on the surface and over the disk (x = 3v, y = 3u): inside to STEP's
    // 13 digits, on the boundary to the tolerance of the edge's 3D curve (BRepLib fits it to
    // the circle on the surface; 1.3e-7 in measured).
    for (const Vec3& v : mesh.mesh.vertices) {
      EXPECT_LE(std::hypot(v.x - 1.5, v.y - 1.5), 0.9 + 1e-6);
      EXPECT_NEAR(v.z, scallop::point(paper.patches[0], v.y / 3.0, v.x / 3.0).z, 1e-6);
    }
    // A dense independent sample of the exact face (a polar grid over the disk) lies within
    // the margin plan uses (1.5 x the sampled deviation) of the mesh.
    double worst = 0.0;
    for (int i = 0; i <= 40; ++i) {
      for (int k = 0; k < 96; ++k) {
        const double r = 0.9 * std::sqrt(i / 40.0) * (1.0 - 1e-9), t = 2.0 * M_PI * k / 96.0;
        const double x = 1.5 + r * std::cos(t), y = 1.5 + r * std::sin(t);
        const Vec3 p = scallop::point(paper.patches[0], y / 3.0, x / 3.0);
        worst = std::max(worst, distanceToMesh(mesh.mesh, p, 0.05));
      }
    }
    EXPECT_LE(worst, 1.5 * mesh.deviation) << "deflection " << deflection;
    EXPECT_GT(worst, 0.2 * mesh.deviation) << "deflection " << deflection;  // the report is not inflated either
  }
}

TEST_F(CadTessellationTest, ThePocketBlockIsClosedOrientedAndWithinItsDeviation) {
  const fs::path path = dir_ / "pocket.step";
  writeStep(pocketBlock(), path, "MM");
  const CadPart part(path.string());
  EXPECT_EQ(part.units(), scallop::Units::millimetre);
  scallop::TessellationOptions options;
  options.deflection = 0.01;
  const CadTessellation mesh = part.tessellate(options);
  // Merged at shared edges: every edge is used by exactly two triangles, once each way, and
  // the normals point out of the block (its signed volume is positive: 20 x 20 x 10 minus
  // the pocket, pi 4^2 4, up to the chords).
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  double volume = 0.0;
  for (const auto& t : mesh.mesh.triangles) {
    for (int e = 0; e < 3; ++e) ++edges[{t[e], t[(e + 1) % 3]}];
    const Vec3 a = mesh.mesh.vertices[t[0]], b = mesh.mesh.vertices[t[1]], c = mesh.mesh.vertices[t[2]];
    volume += dot(a, cross(b, c)) / 6.0;
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u) << "open edge " << edge.first << "-" << edge.second;
  }
  // Planes are exact; the cylinder's chords sag by at most the deflection asked, r (1 - cos),
  // inward, so the pocket's polygon is smaller than its circle by at most deviation x its
  // perimeter per unit of depth.
  EXPECT_GT(mesh.deviation, 0.0);
  EXPECT_LE(mesh.deviation, 0.01 * 1.0001);
  const double solid = 4000.0 - M_PI * 16.0 * 4.0;
  EXPECT_GT(volume, solid);
  EXPECT_LE(volume, solid + mesh.deviation * 2.0 * M_PI * 4.0 * 4.0);
}

TEST_F(CadTessellationTest, BadOptionsAreRefusedByName) {
  const fs::path path = dir_ / "pocket.step";
  writeStep(pocketBlock(), path, "MM");
  const CadPart part(path.string());
  scallop::TessellationOptions options;
  for (const double deflection : {0.0, -1.0, std::nan(""), kInf, 1e-9}) {
    options.deflection = deflection;
    expectErrorMentions([&] { (void)part.tessellate(options); }, {"deflection"});
  }
  options.deflection = 0.1;
  options.angularDeflection = 0.0;
  expectErrorMentions([&] { (void)part.tessellate(options); }, {"angular deflection"});
  options.angularDeflection = 0.35;
  options.maxTriangles = 10;
  expectErrorMentions([&] { (void)part.tessellate(options); }, {"pocket.step", "budget"});
}

// --- sampled exact normals and the orientation over them --------------------------------------

TEST_F(CadTessellationTest, ThePocketBlocksSampledNormalsGiveItsClosedFormOrientation) {
  // Its normals: +-z (top, floor, bottom), +-x and +-y (sides) and every horizontal direction
  // (the pocket's wall). The farthest direction from all of them stands 45 deg above the
  // horizon: alpha* = 45 deg exactly. Sampled, the wall's directions have gaps, through which
  // the samples' optimum may rise a little above it (an upper bound, as documented).
  const fs::path path = dir_ / "pocket.step";
  writeStep(pocketBlock(), path, "MM");
  const CadPart part(path.string());
  scallop::TessellationOptions options;
  options.deflection = 0.01;
  options.angularDeflection = 0.1;
  const CadTessellation mesh = part.tessellate(options);
  for (const Vec3& n : mesh.sampledNormals) ASSERT_NEAR(norm(n), 1.0, 1e-12);
  const scallop::MeshSlicing slicing = scallop::optimalNormalSlicing(mesh.sampledNormals);
  const double alphaDeg = slicing.alphaRad * 180.0 / M_PI;
  EXPECT_GE(alphaDeg, 45.0 - 1e-9);
  EXPECT_LE(alphaDeg, 45.05);
  EXPECT_NEAR(slicing.normal.z, std::sqrt(0.5), 1e-3);
  EXPECT_EQ(slicing.normalsGiven, mesh.sampledNormals.size());
  expectErrorMentions([] { (void)scallop::optimalNormalSlicing({}); }, {"empty"});
  expectErrorMentions([] { (void)scallop::optimalNormalSlicing({Vec3{1.0, 1.0, 0.0}}); }, {"not a unit vector"});
}

// The same on a trimmed free-form face (paper-1's patch over a disk), against a brute force
// written here: alpha(N) = the least angle between N and the +-normals of a dense polar sample
// of the Bezier surface over the disk (scallop's derivatives, not OCCT's), maximised over a
// fine grid of directions N around the samples' optimum and polished by coordinate search.
TEST_F(CadTessellationTest, TheTrimmedFaceOrientationAgreesWithABruteForceOverItsNormals) {
  const Surface paper = exampleFile("paper-1");
  const fs::path path = dir_ / "disk.step";
  writeStep(paperDiskFace(paper), path, "INCH");
  const CadPart part(path.string());
  scallop::TessellationOptions options;
  options.deflection = 0.002;
  options.angularDeflection = 0.1;
  const scallop::MeshSlicing slicing = scallop::optimalNormalSlicing(part.tessellate(options).sampledNormals);
  std::vector<Vec3> normals;
  for (int i = 0; i <= 60; ++i)
    for (int k = 0; k < 120; ++k) {
      const double r = 0.9 * std::sqrt(i / 60.0) * (1.0 - 1e-9), t = 2.0 * M_PI * k / 120.0;
      const double x = 1.5 + r * std::cos(t), y = 1.5 + r * std::sin(t);
      normals.push_back(scallop::unitNormal(paper.patches[0], y / 3.0, x / 3.0));
    }
  const auto alphaOf = [&](Vec3 n) {
    n = n / norm(n);
    double least = M_PI / 2.0;
    for (const Vec3& m : normals) least = std::min(least, std::atan2(norm(cross(n, m)), std::abs(dot(n, m))));
    return least;
  };
  // Start from the samples' N* and climb on a shrinking grid: the brute force's own optimum.
  Vec3 best = slicing.normal;
  double bestAlpha = alphaOf(best);
  for (double step = 0.05; step > 1e-5; step *= 0.5) {
    bool moved = true;
    while (moved) {
      moved = false;
      for (const Vec3 d : {Vec3{step, 0, 0}, Vec3{-step, 0, 0}, Vec3{0, step, 0}, Vec3{0, -step, 0}, Vec3{0, 0, step},
                           Vec3{0, 0, -step}}) {
        const double a = alphaOf(best + d);
        if (a > bestAlpha) {
          bestAlpha = a;
          best = (best + d) / norm(best + d);
          moved = true;
        }
      }
    }
  }
  const double sampledDeg = slicing.alphaRad * 180.0 / M_PI, bruteDeg = bestAlpha * 180.0 / M_PI;
  std::printf("[          ] trimmed disk: alpha* over OCCT-sampled normals %.4f deg, brute force %.4f deg\n",
              sampledDeg, bruteDeg);
  EXPECT_NEAR(sampledDeg, bruteDeg, 0.25);
  // The disk's normals are a subset of the whole patch's: its alpha* is at least the patch's
  // certified one (78.0376 deg is the certificate's bound; 78.048 deg the optimum).
  EXPECT_GE(sampledDeg, 78.03);
}

// --- trimmed faces as pieces (cad_import.hpp's acceptTrimmed) ---------------------------------

// The area of a patch by 8 x 8 Gauss-Legendre quadrature of |r_u x r_v|.
double patchArea(const scallop::BezierPatch& patch) {
  static const std::array<double, 8> nodes{-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                           -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                           0.7966664774136267,  0.9602898564975363};
  static const std::array<double, 8> weights{0.1012285362903763, 0.2223810344533745, 0.3137066278833262,
                                             0.3626837833783620, 0.3626837833783620, 0.3137066278833262,
                                             0.2223810344533745, 0.1012285362903763};
  double area = 0.0;
  for (std::size_t i = 0; i < 8; ++i)
    for (std::size_t k = 0; k < 8; ++k)
      area += 0.25 * weights[i] * weights[k] *
              norm(scallop::normalVector(patch, 0.5 * (1.0 + nodes[i]), 0.5 * (1.0 + nodes[k])));
  return area;
}

// The disk-trimmed paper-1 face through the importer: its inside pieces lie over the disk, its
// boundary pieces straddle the circle, the face's area (a polar quadrature written here) lies
// between the inside pieces' and all pieces', and the slicing of the pieces brackets alpha*
// against the normals sampled densely over the disk (scallop's derivatives at points chosen
// here, not OCCT's classification).
// keepTrims: the disk-trimmed face split at 0.4 and 0.6 in u and v (9 Bezier patches; the
// disk of radius 0.3 about (0.5, 0.5) holds the middle one, misses none). The middle patch is
// kept without a trim, and every patch kept without one lies in the disk (its points' (u, v)
// in closed form); the others keep the face's trim and the map to its parameters.
TEST_F(CadTessellationTest, KeptTrimsLeaveOnlyPatchesWhollyInsideTheFaceUntrimmed) {
  const Surface paper = exampleFile("paper-1");
  const fs::path path = dir_ / "split-disk.step";
  writeStep(paperDiskFace(paper, {0.4, 0.6}), path, "INCH");
  scallop::CadImportOptions options;
  options.acceptTrimmed = options.keepTrims = true;
  const scallop::CadImport imported = scallop::importCad(path.string(), options);
  ASSERT_EQ(imported.surface.patches.size(), 9u);
  ASSERT_TRUE(imported.surface.trimmed());
  std::size_t untrimmed = 0;
  for (std::size_t i = 0; i < 9; ++i) {
    const scallop::BezierPatch& patch = imported.surface.patches[i];
    if (imported.surface.trims[i].trimmed()) continue;
    ++untrimmed;
    for (int a = 0; a <= 4; ++a)
      for (int b = 0; b <= 4; ++b) {
        // x = 3 v, y = 3 u on paper-1's patch: the face's (u, v) from the point.
        const Vec3 q = scallop::point(patch, a / 4.0, b / 4.0);
        EXPECT_LE(std::hypot(q.y / 3.0 - 0.5, q.x / 3.0 - 0.5), 0.3 + 1e-9) << "patch " << i;
      }
  }
  EXPECT_EQ(untrimmed, 1u);
}

TEST_F(CadTessellationTest, ATrimmedFaceBecomesPiecesThatFollowItsTrimmingCurve) {
  const Surface paper = exampleFile("paper-1");
  const fs::path path = dir_ / "disk.step";
  writeStep(paperDiskFace(paper), path, "INCH");
  scallop::CadImportOptions options;
  options.acceptTrimmed = true;
  const scallop::CadImport imported = scallop::importCad(path.string(), options);
  EXPECT_EQ(imported.trimmedFaces, 1u);
  ASSERT_EQ(imported.patchRoles.size(), imported.surface.patches.size());
  EXPECT_LE(imported.largestSpreadRad, options.trimSplit.normalSpreadRad);
  double insideArea = 0.0, allArea = 0.0;
  std::size_t boundary = 0;
  for (std::size_t p = 0; p < imported.surface.patches.size(); ++p) {
    const scallop::BezierPatch& piece = imported.surface.patches[p];
    double nearest = kInf, farthest = 0.0, low = kInf, high = -kInf;
    for (int i = 0; i <= 8; ++i)
      for (int k = 0; k <= 8; ++k) {
        const Vec3 q = scallop::point(piece, i / 8.0, k / 8.0);
        const double r = std::hypot(q.x - 1.5, q.y - 1.5);
        nearest = std::min(nearest, r);
        farthest = std::max(farthest, r);
        low = std::min(low, r), high = std::max(high, r);
        // Every piece is the paper's surface (x = 3 v, y = 3 u).
        ASSERT_NEAR(q.z, scallop::point(paper.patches[0], q.y / 3.0, q.x / 3.0).z, 1e-9);
      }
    const double area = patchArea(piece);
    allArea += area;
    if (imported.patchRoles[p] == scallop::PieceRole::inside) {
      insideArea += area;
      EXPECT_LE(farthest, 0.9 + 1e-9) << "inside piece " << p;
    } else {
      ++boundary;
      const double slack = 0.25 * (high - low);
      EXPECT_LE(nearest, 0.9 + slack) << "boundary piece " << p;
      EXPECT_GE(farthest, 0.9 - slack) << "boundary piece " << p;
    }
  }
  EXPECT_GT(boundary, 10u);
  // The face's area: r in [0, 0.3] of the parameter disk around (0.5, 0.5), 24 Gauss points
  // radially (by 3 panels of 8) and 128 angles (periodic: the trapezoid rule is spectral).
  double faceArea = 0.0;
  static const std::array<double, 8> x{-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                       -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                       0.7966664774136267,  0.9602898564975363};
  static const std::array<double, 8> w{0.1012285362903763, 0.2223810344533745, 0.3137066278833262,
                                       0.3626837833783620, 0.3626837833783620, 0.3137066278833262,
                                       0.2223810344533745, 0.1012285362903763};
  for (int panel = 0; panel < 3; ++panel)
    for (std::size_t i = 0; i < 8; ++i) {
      const double r = 0.1 * (panel + 0.5 * (1.0 + x[i]));
      for (int k = 0; k < 128; ++k) {
        const double t = 2.0 * M_PI * k / 128.0;
        faceArea += 0.05 * w[i] * (2.0 * M_PI / 128.0) * r *
                    norm(scallop::normalVector(paper.patches[0], 0.5 + r * std::sin(t), 0.5 + r * std::cos(t)));
      }
    }
  std::printf("[          ] disk face: area %.6f in^2, inside pieces %.6f, all pieces %.6f (%zu pieces, %zu on the "
              "circle)\n",
              faceArea, insideArea, allArea, imported.surface.patches.size(), boundary);
  EXPECT_LE(insideArea, faceArea * (1.0 + 1e-9));
  EXPECT_GE(allArea, faceArea * (1.0 - 1e-9));
  EXPECT_GT(insideArea, 0.8 * faceArea);

  Surface inside{imported.surface.units, {}};
  for (std::size_t p = 0; p < imported.surface.patches.size(); ++p)
    if (imported.patchRoles[p] == scallop::PieceRole::inside) inside.patches.push_back(imported.surface.patches[p]);
  const scallop::OptimalSlicing lower = scallop::optimalSlicing(imported.surface);
  scallop::OptimalSlicingOptions upperOptions;
  upperOptions.certify = false;
  const scallop::OptimalSlicing upper = scallop::optimalSlicing(inside, upperOptions);
  ASSERT_TRUE(lower.certified);
  std::vector<Vec3> normals;
  for (int i = 0; i <= 60; ++i)
    for (int k = 0; k < 120; ++k) {
      const double r = 0.9 * std::sqrt(i / 60.0) * (1.0 - 1e-9), t = 2.0 * M_PI * k / 120.0;
      const double px = 1.5 + r * std::cos(t), py = 1.5 + r * std::sin(t);
      normals.push_back(scallop::unitNormal(paper.patches[0], py / 3.0, px / 3.0));
    }
  double clearance = M_PI / 2.0;
  for (const Vec3& n : normals)
    clearance = std::min(clearance, std::atan2(norm(cross(lower.normal, n)), std::abs(dot(lower.normal, n))));
  const double sampledCap = scallop::optimalNormalSlicing(normals).alphaRad;
  std::printf("[          ] disk face: alpha* in [%.4f, %.4f] deg; N*'s clearance from the samples %.4f deg, their "
              "cap %.4f deg\n",
              lower.certifiedAlphaRad * 180.0 / M_PI, upper.alphaRad * 180.0 / M_PI, clearance * 180.0 / M_PI,
              sampledCap * 180.0 / M_PI);
  EXPECT_GE(clearance, lower.certifiedAlphaRad - 1e-12);
  EXPECT_LE(lower.certifiedAlphaRad, sampledCap);
  EXPECT_LE(lower.certifiedAlphaRad, upper.alphaRad);
  EXPECT_LE(sampledCap - lower.certifiedAlphaRad, 2.0 * options.trimSplit.normalSpreadRad);
}

// Real data: OCCT's screw.step (8 of its 10 faces trimmed, helical B-spline flanks): the
// certified N* keeps its angle from every exact normal OCCT samples on the faces (at the nodes
// and inside the triangles of its tessellation), and that sample's empty cap, an upper bound
// of alpha*, is at least the certified bound.
TEST(CadTrimmedSamples, ScrewStepsCertifiedDirectionClearsEveryNormalOcctSamples) {
  const std::string path = kOcctSamples + "/step/screw.step";
  if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
  const CadPart part(path);
  scallop::CadImportOptions options;
  options.acceptTrimmed = true;
  options.acceptRational = true;
  options.trimSplit.normalSpreadRad = 4.0 * M_PI / 180.0;
  const scallop::CadImport imported = part.exactFaces(options);
  ASSERT_TRUE(imported.skipped.empty());
  EXPECT_EQ(imported.trimmedFaces, 8u);
  const scallop::OptimalSlicing lower = scallop::optimalSlicing(imported.surface);
  ASSERT_TRUE(lower.certified);
  scallop::TessellationOptions tessellation;
  tessellation.deflection = 0.01;
  tessellation.angularDeflection = 0.1;
  const CadTessellation mesh = part.tessellate(tessellation);
  ASSERT_GT(mesh.sampledNormals.size(), 5000u);
  double clearance = M_PI / 2.0;
  for (const Vec3& n : mesh.sampledNormals)
    clearance = std::min(clearance, std::atan2(norm(cross(lower.normal, n)), std::abs(dot(lower.normal, n))));
  const double sampledCap = scallop::optimalNormalSlicing(mesh.sampledNormals).alphaRad;
  std::printf("[          ] screw.step: certified alpha >= %.4f deg; N*'s clearance from %zu OCCT normals %.4f deg, "
              "their cap %.4f deg\n",
              lower.certifiedAlphaRad * 180.0 / M_PI, mesh.sampledNormals.size(), clearance * 180.0 / M_PI,
              sampledCap * 180.0 / M_PI);
  EXPECT_GE(clearance, lower.certifiedAlphaRad - 1e-9);
  EXPECT_LE(lower.certifiedAlphaRad, sampledCap + 1e-9);
  // A spread no budget can follow is an error naming the face (exactFaces, which skips what it
  // cannot take, lists the face as skipped, and the commands take the part through its
  // tessellation).
  options.trimSplit.normalSpreadRad = 1e-9;
  const scallop::CadImport skipping = part.exactFaces(options);
  ASSERT_FALSE(skipping.skipped.empty());
  EXPECT_NE(skipping.skipped[0].reason.find("more than 20000 pieces in all"), std::string::npos)
      << skipping.skipped[0].reason;
  try {
    (void)scallop::importCad(path, options);
    ADD_FAILURE() << "no error past the budget of pieces";
  } catch (const scallop::Error& error) {
    scallop::test::expectMessageContains(error.what(), {"screw.step", "face 3", "more than 20000 pieces in all", "spread"},
                                         "budget");
  }
}

// Real data: every trimmed face of OpenCASCADE's four sample parts (screw.step, linkrods.step,
// bearing.iges, hammer.iges: B-spline faces, planes, cylinders, cones and tori, holes and
// seams). The winding parity of the arcs the importer keeps (face_trim.hpp's classifyPoint)
// against OCCT's own BRepClass_FaceClassifier on a 41 x 41 grid over each face's UV bounds:
// wherever both decide (the winding's "boundary" and OCCT's ON are left out), they agree.
// A sample's faces, read by OCCT alone in the importer's order, IGES B-splines as written.
std::vector<TopoDS_Face> occtFaces(const std::string& path) {
  scallop::test::quietOcct();
  TopoDS_Shape shape;
  if (path.ends_with(".step")) {
    STEPControl_Reader reader;
    if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return {};
    reader.TransferRoots();
    shape = reader.OneShape();
  } else {
    const std::string saved = Interface_Static::CVal("read.iges.bspline.continuity");
    Interface_Static::SetCVal("read.iges.bspline.continuity", "0");
    IGESControl_Reader reader;
    if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return {};
    reader.TransferRoots();
    shape = reader.OneShape();
    Interface_Static::SetCVal("read.iges.bspline.continuity", saved.c_str());
  }
  std::vector<TopoDS_Face> faces;
  for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next()) faces.push_back(TopoDS::Face(it.Current()));
  return faces;
}

TEST(CadTrimmedSamples, TheArcsWindingAgreesWithOcctsClassifierOnEveryTrimmedFace) {
  struct Sample {
    std::string file;
    std::size_t trimmed;  // trimmed faces the importer keeps
  };
  std::size_t compared = 0, undecided = 0;
  for (const Sample& sample : {Sample{"step/screw.step", 8}, Sample{"step/linkrods.step", 20},
                               Sample{"iges/bearing.iges", 55}, Sample{"iges/hammer.iges", 23}}) {
    const std::string path = kOcctSamples + "/" + sample.file;
    if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
    scallop::CadImportOptions options;
    options.acceptTrimmed = true;
    options.acceptRational = true;
    options.skipUnsupportedFaces = true;
    options.trimSplit.normalSpreadRad = 8.0 * M_PI / 180.0;
    options.maxTrimPieces = 1000000;
    const scallop::CadImport imported = scallop::importCad(path, options);
    EXPECT_TRUE(imported.skipped.empty()) << sample.file << ": " << imported.skipped.front().reason;
    EXPECT_EQ(imported.faceTrims.size(), sample.trimmed) << sample.file;
    const std::vector<TopoDS_Face> faces = occtFaces(path);
    ASSERT_EQ(faces.size(), imported.faces) << sample.file;
    for (const auto& [index, trim] : imported.faceTrims) {
      double u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0;
      BRepTools::UVBounds(faces[index], u0, u1, v0, v1);
      int inside = 0;
      for (int a = 0; a <= 40; ++a)
        for (int b = 0; b <= 40; ++b) {
          // Off the grid of the bounds by a little, so that points do not sit on iso-line edges.
          const double u = u0 + (a + 0.37) / 41.3 * (u1 - u0), v = v0 + (b + 0.61) / 41.3 * (v1 - v0);
          const CellPlace place = scallop::classifyPoint(trim, u, v);
          const TopAbs_State state =
              BRepClass_FaceClassifier(faces[index], gp_Pnt2d(u, v), Precision::PConfusion()).State();
          if (place == CellPlace::boundary || state == TopAbs_ON) {
            ++undecided;
            continue;
          }
          EXPECT_EQ(place == CellPlace::inside, state == TopAbs_IN)
              << sample.file << " face " << index << " at (" << u << ", " << v << ")";
          inside += place == CellPlace::inside ? 1 : 0;
          ++compared;
        }
      EXPECT_GT(inside, 0) << sample.file << " face " << index;
    }
  }
  std::printf("[          ] winding against OCCT's classifier: %zu points agree, %zu left out\n", compared, undecided);
  EXPECT_GT(compared, 170000u);
  EXPECT_LT(undecided, compared / 1000);
}

// Kept trims through each patch's map (face_trim.hpp's AxisMap: affine, or half-angles on the
// converted cylinders, cones, spheres and tori): a point of a trimmed patch (a point of the
// face's untrimmed surface) is kept exactly when it lies on the face, as OCCT's exact distance
// from the point to the face says (BRepExtrema: 0 on the face, the distance to its boundary
// off it), with no parameters at all.
TEST(CadTrimmedSamples, KeptTrimsFollowTheFacesThroughEachPatchsMap) {
  std::size_t compared = 0, undecided = 0, halfAngle = 0, trimmedPatches = 0;
  for (const std::string file : {"step/screw.step", "step/linkrods.step", "iges/bearing.iges", "iges/hammer.iges"}) {
    const std::string path = kOcctSamples + "/" + file;
    if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
    scallop::CadImportOptions options;
    options.acceptTrimmed = options.keepTrims = true;
    options.acceptRational = true;
    options.skipUnsupportedFaces = true;
    options.maxTrimPieces = 1000000;
    options.trimSplit.normalSpreadRad = 8.0 * M_PI / 180.0;  // coarse pieces: only the kept patches matter
    const scallop::CadImport imported = scallop::importCad(path, options);
    // Every trimmed face is kept exactly: none is refused for its map.
    for (const scallop::SkippedFace& skipped : imported.skipped)
      ADD_FAILURE() << file << ": face " << skipped.face << " skipped: " << skipped.reason;
    const std::vector<TopoDS_Face> faces = occtFaces(path);
    ASSERT_EQ(faces.size(), imported.faces) << file;
    const Surface& surface = imported.surface;
    ASSERT_TRUE(surface.trimmed()) << file;
    const double size = scallop::surfaceScale(surface);
    for (std::size_t i = 0; i < surface.patches.size(); ++i) {
      const scallop::PatchTrim& trim = surface.trims[i];
      if (!trim.trimmed()) continue;
      ++trimmedPatches;
      halfAngle += trim.u.kind == scallop::AxisMap::Kind::halfAngle || trim.v.kind == scallop::AxisMap::Kind::halfAngle;
      const TopoDS_Face& face = faces[imported.patchFaces[i]];
      for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) {
          const double s = (a + 0.37) / 6.0, t = (b + 0.61) / 6.0;
          const Vec3 p = scallop::point(surface.patches[i], s, t);
          BRepExtrema_DistShapeShape distance(BRepBuilderAPI_MakeVertex(gp_Pnt(p.x, p.y, p.z)).Vertex(), face);
          ASSERT_TRUE(distance.IsDone()) << file << " patch " << i;
          const CellPlace place = scallop::classifyPoint(*trim.face, trim.u.at(s), trim.v.at(t));
          const bool onFace = distance.Value() <= 1e-9 * size, offFace = distance.Value() > 1e-6 * size;
          if (place == CellPlace::boundary || (!onFace && !offFace)) {
            ++undecided;
            continue;
          }
          EXPECT_EQ(scallop::keepsPoint(trim, s, t), onFace)
              << file << " patch " << i << " (face " << imported.patchFaces[i] << ") at (" << s << ", " << t
              << "): " << distance.Value() << " from the face";
          ++compared;
        }
    }
  }
  std::printf("[          ] kept trims against OCCT's distance to the face: %zu trimmed patches (%zu by half-angles), "
              "%zu points agree, %zu left out\n",
              trimmedPatches, halfAngle, compared, undecided);
  EXPECT_GE(halfAngle, 10u);  // 13: the screw's cones and tori, the linkrods' cylinders
  EXPECT_GT(compared, 7000u);
  EXPECT_LT(undecided, compared / 50);
}

// Seams (section.hpp's seam joins): the screw is a closed solid, so every plane section of
// it is closed loops. Its faces meet only to the model's tolerance (up to 3e-4 mm): each
// patch carries its face's largest tolerance (recomputed here from OCCT's faces), and with it
// every section by 14 planes in each of three directions is closed loops; without it, some
// stop at the seams.
TEST(CadTrimmedSamples, SectionsOfTheClosedScrewAreClosedLoopsAcrossItsSeams) {
  const std::string path = kOcctSamples + "/step/screw.step";
  if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
  scallop::CadImportOptions options;
  options.acceptTrimmed = options.keepTrims = options.acceptRational = true;
  options.trimSplit.normalSpreadRad = 8.0 * M_PI / 180.0;
  scallop::CadImport imported = scallop::importCad(path, options);
  Surface& surface = imported.surface;
  const std::vector<TopoDS_Face> faces = occtFaces(path);
  ASSERT_EQ(faces.size(), imported.faces);
  ASSERT_EQ(surface.seamTolerances.size(), surface.patches.size());
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    const TopoDS_Face& face = faces[imported.patchFaces[i]];
    double tolerance = BRep_Tool::Tolerance(face);
    for (TopExp_Explorer it(face, TopAbs_VERTEX); it.More(); it.Next())
      tolerance = std::max(tolerance, BRep_Tool::Tolerance(TopoDS::Vertex(it.Current())));
    for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next())
      tolerance = std::max(tolerance, BRep_Tool::Tolerance(TopoDS::Edge(it.Current())));
    EXPECT_EQ(surface.seamTolerances[i], tolerance) << "patch " << i;
  }
  const double size = scallop::surfaceScale(surface);
  double low[3], high[3];
  for (int axis = 0; axis < 3; ++axis) low[axis] = std::numeric_limits<double>::infinity(), high[axis] = -low[axis];
  for (const scallop::BezierPatch& patch : surface.patches)
    for (const Vec3& p : patch.control) {
      const double c[3] = {p.x, p.y, p.z};
      for (int axis = 0; axis < 3; ++axis) low[axis] = std::min(low[axis], c[axis]), high[axis] = std::max(high[axis], c[axis]);
    }
  const std::vector<double> tolerances = surface.seamTolerances;
  std::size_t curves = 0, openWithout = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int k = 0; k < 14; ++k) {
      Vec3 normal{0, 0, 0};
      (axis == 0 ? normal.x : axis == 1 ? normal.y : normal.z) = 1.0;
      const double offset = low[axis] + (high[axis] - low[axis]) * (k + 1.123) / 15;
      surface.seamTolerances = tolerances;
      const scallop::PlaneSection section = scallop::planeSection(surface, normal, offset, 1e-4 * size);
      for (const scallop::SectionCurve& curve : section.curves) {
        ++curves;
        EXPECT_TRUE(curve.closed) << "axis " << axis << " offset " << offset << ": a curve of " << curve.points.size()
                                  << " points stops at " << curve.points.back().point.x << ", "
                                  << curve.points.back().point.y << ", " << curve.points.back().point.z;
      }
      surface.seamTolerances.clear();
      for (const scallop::SectionCurve& curve : scallop::planeSection(surface, normal, offset, 1e-4 * size).curves)
        openWithout += !curve.closed;
    }
  std::printf("[          ] screw sections: %zu closed loops across its seams; %zu open curves without the seam joins\n",
              curves, openWithout);
  EXPECT_GT(curves, 30u);
  EXPECT_GT(openWithout, 10u);
}

// --- exact heights ----------------------------------------------------------------------------

TEST_F(CadTessellationTest, ExactHeightsOfThePocketBlockAreItsClosedForm) {
  const fs::path path = dir_ / "pocket.iges";
  writeIges(pocketBlock(), path, "MM");
  const CadPart part(path.string());
  HeightGrid grid = gridOver(-1.0, -1.0, 21.0, 21.0, 0.173);
  std::vector<double> normalZ;
  part.designHeights(grid, &normalZ);
  std::size_t compared = 0;
  for (std::size_t j = 0; j < grid.rows; ++j)
    for (std::size_t i = 0; i < grid.columns; ++i) {
      const scallop::Vec2 p = grid.point(i, j);
      const double expected = pocketBlockHeight(p.x, p.y, 1e-6);
      if (std::isnan(expected)) continue;
      ++compared;
      const double z = grid.z[j * grid.columns + i];
      if (expected == -kInf) {
        EXPECT_EQ(z, -kInf) << p.x << ", " << p.y;
      } else {
        EXPECT_NEAR(z, expected, 1e-7) << p.x << ", " << p.y;
        EXPECT_NEAR(normalZ[j * grid.columns + i], 1.0, 1e-12);
      }
    }
  EXPECT_GT(compared, 15000u);

  // The same bits on one thread and on four.
  HeightGrid one = gridOver(-1.0, -1.0, 21.0, 21.0, 0.173), four = one;
  part.designHeights(one, nullptr, {1, 1'000'000});
  part.designHeights(four, nullptr, {4, 1'000'000});
  EXPECT_EQ(one.z, grid.z);
  EXPECT_EQ(four.z, grid.z);
  // The budget of lines.
  HeightGrid fine = gridOver(-1.0, -1.0, 21.0, 21.0, 0.01);
  expectErrorMentions([&] { part.designHeights(fine, nullptr, {0, 100'000}); },
                                     {"pocket.iges", "budget", "100000"});
}

TEST_F(CadTessellationTest, ExactHeightsOfATrimmedFreeFormFaceAreTheBezierSurfacesInsideItsTrim) {
  const Surface paper = exampleFile("paper-1");
  const fs::path path = dir_ / "disk.step";
  writeStep(paperDiskFace(paper), path, "INCH");
  const CadPart part(path.string());
  HeightGrid exact = gridOver(0.0, 0.0, 3.0, 3.0, 0.0213);
  HeightGrid bezier = exact;
  std::vector<double> exactNormalZ, bezierNormalZ;
  part.designHeights(exact, &exactNormalZ);
  scallop::designHeights(paper, bezier, &bezierNormalZ);  // scallop's Newton on the untrimmed patch
  std::size_t inside = 0;
  for (std::size_t j = 0; j < exact.rows; ++j)
    for (std::size_t i = 0; i < exact.columns; ++i) {
      const scallop::Vec2 p = exact.point(i, j);
      const double r = std::hypot(p.x - 1.5, p.y - 1.5);
      const std::size_t at = j * exact.columns + i;
      if (std::abs(r - 0.9) < 1e-6) continue;
      if (r > 0.9) {
        EXPECT_EQ(exact.z[at], -kInf) << p.x << ", " << p.y;
        continue;
      }
      ++inside;
      EXPECT_NEAR(exact.z[at], bezier.z[at], 1e-9) << p.x << ", " << p.y;
      EXPECT_NEAR(exactNormalZ[at], bezierNormalZ[at], 1e-9) << p.x << ", " << p.y;
    }
  EXPECT_GT(inside, 5000u);
}

// --- the CLI ----------------------------------------------------------------------------------

class CadTessellationCli : public scallop::test::CliFixture {
 protected:
  // The least distance from the ball centres of `program` (every move's end and, along each
  // feed line, points every R/4) to the solid of `shape`, by OCCT's exact BRepExtrema (0 for
  // a centre inside the solid), over at most `budget` centres spread evenly.
  static double leastCentreDistance(const TopoDS_Shape& shape, const fs::path& program, double radius,
                                    std::size_t budget) {
    const scallop::GcodeProgram parsed = scallop::readGcodeProgram(program.string());
    const std::vector<scallop::SweptMove> moves = scallop::sweptMoves(parsed, radius);
    std::vector<Vec3> centres;
    for (const scallop::SweptMove& move : moves) {
      if (move.kind != scallop::MoveKind::line) {
        centres.push_back(move.end);
        continue;
      }
      const double length = norm(move.end - move.start);
      const int steps = std::max(1, static_cast<int>(std::ceil(length / (0.25 * radius))));
      for (int s = 1; s <= steps; ++s) centres.push_back(move.start + (static_cast<double>(s) / steps) * (move.end - move.start));
    }
    const std::size_t stride = std::max<std::size_t>(1, centres.size() / budget);
    // The distance to the shape is the least over its faces (each with its edges and
    // vertices): a face whose box is farther than the least found so far cannot lower it, so
    // only the faces whose boxes come nearer are asked, nearest box first (on bearing.iges'
    // 213 faces this asks a few per centre instead of all). Boxes from the faces' geometry
    // (their poles), which enclose them.
    struct FaceBox {
      TopoDS_Shape face;
      Bnd_Box box;
    };
    std::vector<FaceBox> faces;
    for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next()) {
      FaceBox face{it.Current(), {}};
      BRepBndLib::Add(face.face, face.box, false);
      faces.push_back(face);
    }
    // Inside a solid (the block and OCCT's samples may be closed solids): distance 0.
    const bool solid = TopExp_Explorer(shape, TopAbs_SOLID).More();
    std::optional<BRepClass3d_SolidClassifier> classifier;
    if (solid) classifier.emplace(shape);
    const auto boxDistance = [](const Bnd_Box& box, const gp_Pnt& p) {
      double x0, y0, z0, x1, y1, z1;
      box.Get(x0, y0, z0, x1, y1, z1);
      const double dx = std::max({0.0, x0 - p.X(), p.X() - x1});
      const double dy = std::max({0.0, y0 - p.Y(), p.Y() - y1});
      const double dz = std::max({0.0, z0 - p.Z(), p.Z() - z1});
      return std::sqrt(dx * dx + dy * dy + dz * dz);
    };
    double least = kInf;
    std::vector<std::pair<double, std::size_t>> near;
    for (std::size_t c = 0; c < centres.size(); c += stride) {
      const gp_Pnt p(centres[c].x, centres[c].y, centres[c].z);
      if (classifier) {
        classifier->Perform(p, Precision::Confusion());
        if (classifier->State() == TopAbs_IN) least = 0.0;
      }
      near.clear();
      for (std::size_t f = 0; f < faces.size(); ++f) {
        const double d = boxDistance(faces[f].box, p);
        if (d < least) near.emplace_back(d, f);
      }
      std::sort(near.begin(), near.end());
      const TopoDS_Vertex vertex = BRepBuilderAPI_MakeVertex(p).Vertex();
      for (const auto& [boxGap, f] : near) {
        if (boxGap >= least) break;
        BRepExtrema_DistShapeShape distance(vertex, faces[f].face);
        EXPECT_TRUE(distance.IsDone());
        least = std::min(least, distance.Value());
      }
    }
    return least;
  }
};

// A trimmed B-spline face taken exactly (surface.hpp's trims): paper-1's patch trimmed to a
// disk. Both strategies plan it on the face alone: the simulated cut (on the trimmed face)
// finds no gouge and scallops within H, and OCCT's exact distance from the ball centres to
// the face (BRepExtrema, which honours the trim) is never below R: an independent judge. And
// the trim is what the paths followed: some centres come nearer than R to the untrimmed
// patch (where it goes on beyond the disk), which a path over the whole patch never does.
TEST_F(CadTessellationCli, PlanCutsATrimmedBSplineFaceExactlyOnTheFaceAlone) {
  const Surface paper = exampleFile("paper-1");
  const TopoDS_Shape face = paperDiskFace(paper);
  writeStep(face, workDir_ / "disk.step", "INCH");
  // A ball of 1/8 in and H 0.004 in (0.25 and 0.002 took twice the run time: the
  // trimmed face's distance queries per pass end and per checked point dominate).
  const double radius = 0.125, height = 0.004;
  for (const std::string strategy : {"contour", "raster"}) {
    SCOPED_TRACE(strategy);
    const scallop::test::RunResult plan = run("plan disk.step --exact-trims --strategy " + strategy +
                                              " --tool-radius 0.125 --scallop-height 0.004 --out out");
    ASSERT_EQ(plan.exitCode, 0) << plan.err;
    EXPECT_EQ(plan.err.find("cannot be machined exactly"), std::string::npos) << plan.err;
    const auto report = nlohmann::json::parse(scallop::test::readFile(workDir_ / "out" / "report.json"));
    EXPECT_FALSE(report.contains("tessellation"));
    const auto& v = report["verification"];
    std::printf("[          ] trimmed disk face, %s: gouge %.3g, scallop max %.6f (H %.3f)\n", strategy.c_str(),
                v["max_gouge"].get<double>(), v["max_scallop"].get<double>(), height);
    EXPECT_LE(v["max_gouge"].get<double>(), v["gouge_tolerance"].get<double>());
    EXPECT_LE(v["max_scallop"].get<double>(), height);
    // OCCT's distance from the centres (inches in the program, millimetres in OCCT) to the face.
    const scallop::GcodeProgram program = scallop::readGcodeProgram((workDir_ / "out" / "toolpath.ngc").string());
    const std::vector<scallop::SweptMove> moves = scallop::sweptMoves(program, radius);
    const scallop::SurfaceDistance untrimmed(paper);
    double least = kInf;
    std::size_t checked = 0, nearerThanRToTheWholePatch = 0;
    for (std::size_t i = 0; i < moves.size(); i += std::max<std::size_t>(1, moves.size() / 1500)) {
      if (moves[i].rapid) continue;
      if (untrimmed.closest(moves[i].end).distance < radius - 1e-3) ++nearerThanRToTheWholePatch;
      const Vec3 c = 25.4 * moves[i].end;
      BRepExtrema_DistShapeShape distance(BRepBuilderAPI_MakeVertex(gp_Pnt(c.x, c.y, c.z)).Vertex(), face);
      ASSERT_TRUE(distance.IsDone());
      least = std::min(least, distance.Value() / 25.4);
      ++checked;
    }
    EXPECT_GT(checked, 1000u);
    EXPECT_GE(least, radius - 1e-4);  // the gouge tolerance: the G-code's rounding, 1e-4 in
    EXPECT_LE(least, radius + 1e-3);  // and the ball does touch the face
    EXPECT_GT(nearerThanRToTheWholePatch, 0u);
    fs::remove_all(workDir_ / "out");
  }
}

TEST_F(CadTessellationCli, PlanCutsATrimmedRationalPartThroughItsTessellationWithoutGouging) {
  const TopoDS_Shape block = pocketBlock();
  writeStep(block, workDir_ / "pocket.step", "MM");
  const scallop::test::RunResult plan =
      run("plan pocket.step --tool-radius 1.5 --scallop-height 0.05 --out out");
  ASSERT_EQ(plan.exitCode, 0) << plan.err;
  EXPECT_NE(plan.err.find("faces cannot be machined exactly yet"), std::string::npos) << plan.err;
  EXPECT_NE(plan.err.find("simulated on the exact faces"), std::string::npos) << plan.err;
  const auto report = nlohmann::json::parse(scallop::test::readFile(workDir_ / "out" / "report.json"));
  EXPECT_EQ(report["units"], "mm");
  EXPECT_EQ(report["tessellation"]["design"], "exact faces");
  EXPECT_GT(report["tessellation"]["clearance"].get<double>(), report["tessellation"]["deviation"].get<double>());
  EXPECT_LE(report["verification"]["max_gouge"].get<double>(), 0.0025);
  // The ball reaches into the pocket (radius 4 > R): the floor at z = 6 is cut to near H.
  // OCCT's exact distance from the ball centres to the solid: never below R.
  const double least = leastCentreDistance(block, workDir_ / "out" / "toolpath.ngc", 1.5, 4000);
  EXPECT_GE(least, 1.5 - 1e-6);
  EXPECT_LE(least, 1.5 + 0.05);  // and it does touch the part
  // verify judges the program on the exact faces: no gouge.
  const scallop::test::RunResult verify = run(
      "verify pocket.step out/toolpath.ngc --radius 1.5 --scallop-height 0.05 --stock-allowance 0.25 --fail-on-gouge "
      "--json verify.json");
  ASSERT_EQ(verify.exitCode, 0) << verify.err;
  const auto judged = nlohmann::json::parse(scallop::test::readFile(workDir_ / "verify.json"));
  EXPECT_LE(judged["gouge"]["max"].get<double>(), 0.0025);
  // `paths` cuts the part the same way: plan's program without rest passes but for its title
  // line (compared whole: gtest's line diff of two programs is quadratic).
  const scallop::test::RunResult paths =
      run("paths pocket.step --tool-radius 1.5 --scallop-height 0.05 --gcode paths.ngc");
  ASSERT_EQ(paths.exitCode, 0) << paths.err;
  const scallop::test::RunResult plain =
      run("plan pocket.step --tool-radius 1.5 --scallop-height 0.05 --no-rest-finishing --out plain --quiet");
  ASSERT_EQ(plain.exitCode, 0) << plain.err;
  const auto body = [](const std::string& program) { return program.substr(program.find('\n')); };
  EXPECT_TRUE(body(scallop::test::readFile(workDir_ / "paths.ngc")) ==
              body(scallop::test::readFile(workDir_ / "plain" / "toolpath.ngc")));
}

TEST_F(CadTessellationCli, PlanAndVerifyOpenCascadesSampleStepAndIgesParts) {
  // Parts nobody here wrote: OCCT's screw.step (planes, cones, cylinders and tori) and
  // bearing.iges (213 B-spline faces, 55 trimmed).
  struct Sample {
    std::string file;
    std::string radius;
    std::string height;
  };
  for (const Sample& sample : {Sample{"step/screw.step", "3", "0.05"}, Sample{"iges/bearing.iges", "0.004", "0.0016"}}) {
    const std::string path = kOcctSamples + "/" + sample.file;
    if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
    const scallop::test::RunResult plan = run("plan " + path + " --tool-radius " + sample.radius +
                                              " --scallop-height " + sample.height + " --out out --quiet");
    ASSERT_EQ(plan.exitCode, 0) << sample.file << ": " << plan.err;
    const auto report = nlohmann::json::parse(scallop::test::readFile(workDir_ / "out" / "report.json"));
    EXPECT_EQ(report["tessellation"]["design"], "exact faces") << sample.file;
    EXPECT_LE(report["verification"]["max_gouge"].get<double>(), 0.0025) << sample.file;
    if (sample.file == "iges/bearing.iges") {
      // Its model's tolerance makes the clearance exceed H: no rest pass could help, none is made.
      EXPECT_GE(report["tessellation"]["clearance"].get<double>(), 0.0016);
      EXPECT_TRUE(report["rest_finishing"].is_null());
    }
    if (sample.file == "step/screw.step") {
      // Its slot is narrower than the ball: beyond reach, not in the scallop figures, which the
      // passes (aimed at H less the tessellation's clearance and deviation) keep below H.
      EXPECT_GT(report["verification"]["unreachable_area"].get<double>(), 20.0);
      EXPECT_LE(report["verification"]["max_scallop"].get<double>(), 0.05);
    }
    const scallop::test::RunResult verify =
        run("verify " + path + " out/toolpath.ngc --radius " + sample.radius + " --scallop-height " + sample.height +
            " --stock-allowance 0.25 --fail-on-gouge");
    EXPECT_EQ(verify.exitCode, 0) << sample.file << ": " << verify.err;
    fs::remove_all(workDir_ / "out");
  }
}

// bearing.iges with --exact-trims: its 55 trimmed B-spline faces taken exactly, with their
// trims. The scallops stay within H (through its tessellation they reach 8.5 H: the clearance
// its model's tolerance asks exceeds H), and OCCT's distance from the ball centres to the
// part is never below R by more than the G-code's rounding (1e-4 mm, on steep walls);
// `verify` judges the program on the exact faces through OpenCASCADE (without the flag) and
// on the trimmed patches (with it).
TEST_F(CadTessellationCli, ExactTrimsCutOpenCascadesBearingWithinH) {
  const std::string path = kOcctSamples + "/iges/bearing.iges";
  if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
  const scallop::test::RunResult plan =
      run("plan " + path + " --exact-trims --tool-radius 0.004 --scallop-height 0.0008 --out out --quiet");
  ASSERT_EQ(plan.exitCode, 0) << plan.err;
  const auto report = nlohmann::json::parse(scallop::test::readFile(workDir_ / "out" / "report.json"));
  EXPECT_FALSE(report.contains("tessellation"));
  EXPECT_LE(report["verification"]["max_gouge"].get<double>(), 0.0025);
  EXPECT_LE(report["verification"]["max_scallop"].get<double>(), 0.0008);
  scallop::test::quietOcct();
  const std::string saved = Interface_Static::CVal("read.iges.bspline.continuity");
  Interface_Static::SetCVal("read.iges.bspline.continuity", "0");
  IGESControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  Interface_Static::SetCVal("read.iges.bspline.continuity", saved.c_str());
  const double least = leastCentreDistance(reader.OneShape(), workDir_ / "out" / "toolpath.ngc", 0.004, 600);
  std::printf("[          ] bearing.iges --exact-trims: scallop max %.6f mm, least centre distance %.6f mm (R 0.004)\n",
              report["verification"]["max_scallop"].get<double>(), least);
  EXPECT_GE(least, 0.004 - 1e-4);
  for (const std::string flag : {"", " --exact-trims"}) {
    const scallop::test::RunResult verify = run("verify " + path + " out/toolpath.ngc --radius 0.004 --scallop-height "
                                                "0.0008 --stock-allowance 0.25 --fail-on-gouge" + flag);
    EXPECT_EQ(verify.exitCode, 0) << flag << ": " << verify.err;
  }
}

TEST_F(CadTessellationCli, OrientTakesAPartWithTrimmedAndRationalFacesBySampledNormals) {
  writeStep(pocketBlock(), workDir_ / "pocket.step", "MM");
  const scallop::test::RunResult orient = run("orient pocket.step --tessellate --json o.json");
  ASSERT_EQ(orient.exitCode, 0) << orient.err;
  EXPECT_NE(orient.err.find("alpha* <= "), std::string::npos) << orient.err;
  EXPECT_NE(orient.err.find("not certified"), std::string::npos) << orient.err;
  const auto json = nlohmann::json::parse(scallop::test::readFile(workDir_ / "o.json"));
  EXPECT_EQ(json["input"], "tessellation");
  EXPECT_EQ(json["alpha_is"], "upper bound");
  EXPECT_EQ(json["certified"], false);
  EXPECT_GE(json["alpha_deg"].get<double>(), 45.0 - 1e-9);
  EXPECT_LE(json["alpha_deg"].get<double>(), 45.05);
  fs::remove(workDir_ / "o.json");
  expectCleanFailure(run("orient pocket.step --tessellate --svg-dir figs"), {"pocket.step", "--svg-dir", "tessellated"},
                     "pocket.step");
}

// Without --tessellate the pocket block's trimmed faces (the top around the pocket, the pocket's
// floor) are pieces that follow their circles, its cylinder a rational patch: alpha* = 45 deg
// (the planes' normals +-z and the walls' horizontal ones), bracketed by a certified lower bound
// and the inside pieces' optimum.
TEST_F(CadTessellationCli, OrientBracketsATrimmedPartsAlphaBetweenCertifiedBounds) {
  writeStep(pocketBlock(), workDir_ / "pocket.step", "MM");
  const scallop::test::RunResult orient = run("orient pocket.step --json o.json --svg-dir figs");
  ASSERT_EQ(orient.exitCode, 0) << orient.err;
  EXPECT_NE(orient.err.find("2 trimmed faces"), std::string::npos) << orient.err;
  EXPECT_NE(orient.err.find("certified over the faces"), std::string::npos) << orient.err;
  const auto json = nlohmann::json::parse(scallop::test::readFile(workDir_ / "o.json"));
  EXPECT_EQ(json["certified"], true);
  const auto& trimmed = json["trimmed"];
  EXPECT_EQ(trimmed["faces"], 2);
  const double lower = trimmed["alpha_lower_deg"].get<double>(), upper = trimmed["alpha_upper_deg"].get<double>();
  EXPECT_LE(lower, 45.0);
  EXPECT_GE(upper, 45.0);
  EXPECT_GE(lower, 44.99);
  EXPECT_LE(upper, 45.01);
  EXPECT_NEAR(std::abs(json["normal"][2].get<double>()), std::sqrt(0.5), 1e-3);
  EXPECT_TRUE(fs::exists(workDir_ / "figs" / "gauss-map.svg"));
  fs::remove_all(workDir_ / "figs");
  fs::remove(workDir_ / "o.json");
  expectCleanFailure(run("orient pocket.step --trim-spread 0 --json o.json"), {"trim spread", "0"}, "pocket.step");
  expectCleanFailure(run("orient pocket.step --trim-spread 20 --json o.json"), {"trim spread", "20"}, "pocket.step");
  expectCleanFailure(run("orient pocket.step --patches 0-3 --json o.json"), {"pocket.step", "--patches", "trimmed"},
                     "pocket.step");
  expectCleanFailure(run("orient --example paper-1 --trim-spread 1 --json o.json"), {"--trim-spread", "trimmed"},
                     "pocket.step");
  fs::remove(workDir_ / "pocket.step");
}

// Real data whose pieces leave no direction free (OCCT's hammer.iges, 23 of 45 faces trimmed):
// the lower bound is 0 with nothing searched, and the inside pieces, unproven to cover the
// sphere, bound nothing: no number is printed or written as if it were a bound.
TEST_F(CadTessellationCli, ATrimmedPartWhosePiecesLeaveNoDirectionFreeClaimsNoBound) {
  const std::string path = kOcctSamples + "/iges/hammer.iges";
  if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
  const scallop::test::RunResult orient = run("orient " + path + " --json o.json");
  ASSERT_EQ(orient.exitCode, 0) << orient.err;
  EXPECT_NE(orient.err.find("alpha* >= 0 (the pieces"), std::string::npos) << orient.err;
  const auto json = nlohmann::json::parse(scallop::test::readFile(workDir_ / "o.json"));
  EXPECT_EQ(json["method"], "open");
  EXPECT_EQ(json["alpha_deg"].get<double>(), 0.0);
  const auto& trimmed = json["trimmed"];
  EXPECT_EQ(trimmed["faces"], 23);
  if (trimmed["upper_method"] == "covered") {
    EXPECT_EQ(trimmed["alpha_upper_deg"].get<double>(), 0.0);
  } else {
    EXPECT_EQ(trimmed["upper_method"], "open");
    EXPECT_TRUE(trimmed["alpha_upper_deg"].is_null());
    EXPECT_NE(orient.err.find("no upper bound"), std::string::npos) << orient.err;
  }
  fs::remove(workDir_ / "o.json");
}

// An asked spread past the budget of pieces is refused with the face's reason; without it the
// same part (here at the default) is oriented exactly, and an STL mesh refuses the option.
TEST_F(CadTessellationCli, AnAskedTrimSpreadPastTheBudgetIsRefusedWithItsReason) {
  const std::string path = kOcctSamples + "/step/screw.step";
  if (!fs::exists(path)) GTEST_FAIL() << path << " is missing: Debian's occt-misc package installs it";
  expectCleanFailure(run("orient " + path + " --trim-spread 0.1 --json o.json"),
                     {"screw.step", "--trim-spread 0.1", "face", "pieces"}, nullptr);
  writeStep(pocketBlock(), workDir_ / "pocket.step", "MM");
  const scallop::test::RunResult mesh = run("orient pocket.step --tessellate --trim-spread 1 --json o.json");
  EXPECT_EQ(mesh.exitCode, 1) << mesh.err;
  EXPECT_NE(mesh.err.find("--trim-spread"), std::string::npos) << mesh.err;
  EXPECT_FALSE(fs::exists(workDir_ / "o.json"));
  fs::remove(workDir_ / "pocket.step");
}

TEST_F(CadTessellationCli, TessellationOptionsAreRefusedWhereTheyDoNotApply) {
  writeStep(pocketBlock(), workDir_ / "pocket.step", "MM");
  expectCleanFailure(run("plan pocket.step --tessellate --skip-faces --out out"), {"pocket.step", "--skip-faces"},
                     "pocket.step");
  expectCleanFailure(run("plan pocket.step --deflection 0 --out out --quiet"), {"deflection", "0"}, "pocket.step");
  expectCleanFailure(run("plan pocket.step --deflection 1e-9 --out out --quiet"), {"pocket.step", "deflection", "1e-06"},
                     "pocket.step");
  expectCleanFailure(run("plan pocket.step --strategy contour --out out"), {"pocket.step", "contour", "tessellated"},
                     "pocket.step");
  expectCleanFailure(run("plan --example paper-1 --deflection 0.1 --out out"), {"--deflection"}, "pocket.step");
  fs::remove(workDir_ / "pocket.step");
  fs::copy_file(kExamples + "/surfaces/paper-1.json", workDir_ / "paper-1.json");
  expectCleanFailure(run("plan paper-1.json --tessellate --out out"), {"--tessellate", "STEP and IGES"},
                     "paper-1.json");
  // --exact-trims: for STEP and IGES parts, and not with the tessellation or --skip-faces.
  expectCleanFailure(run("plan paper-1.json --exact-trims --out out"), {"paper-1.json", "--exact-trims", "STEP and IGES"},
                     "paper-1.json");
  expectCleanFailure(run("paths --example paper-1 --tool-radius 0.25 --scallop-height 0.002 --exact-trims --json o.json"),
                     {"--exact-trims", "STEP and IGES"}, "paper-1.json");
  fs::remove(workDir_ / "paper-1.json");
  writeStep(pocketBlock(), workDir_ / "pocket.step", "MM");
  expectCleanFailure(run("plan pocket.step --exact-trims --tessellate --out out"), {"pocket.step", "--tessellate"},
                     "pocket.step");
  expectCleanFailure(run("plan pocket.step --exact-trims --skip-faces --out out"), {"pocket.step", "--skip-faces"},
                     "pocket.step");
}

}  // namespace
