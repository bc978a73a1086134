// STL input (mesh.hpp): binary and ASCII files written here by an independent writer (random
// meshes, fixed seeds) read back exactly, vertices merged, and every malformed file refused
// with a message that names the file and what is wrong.

#include "scallop/geometry/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "scallop/error.hpp"

namespace {

using scallop::Mesh;
using scallop::StlFormat;
using scallop::Units;
using scallop::Vec3;

struct Tri {
  std::array<std::array<float, 3>, 3> v;
};

void putU32(std::string& out, std::uint32_t x) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((x >> (8 * i)) & 0xff));
}
void putF32(std::string& out, float f) {
  std::uint32_t x = 0;
  std::memcpy(&x, &f, 4);
  putU32(out, x);
}

std::string binaryStl(const std::vector<Tri>& tris, const std::string& header = "written by mesh_test") {
  std::string out = header.substr(0, 80);
  out.resize(80, ' ');
  putU32(out, static_cast<std::uint32_t>(tris.size()));
  for (const Tri& t : tris) {
    for (int k = 0; k < 3; ++k) putF32(out, 0.0f);  // a normal nobody should trust
    for (const auto& p : t.v)
      for (float c : p) putF32(out, c);
    out += std::string(2, '\0');
  }
  return out;
}

std::string asciiStl(const std::vector<Tri>& tris, bool shouting = false) {
  const auto kw = [&](std::string s) {
    if (shouting)
      for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
  };
  std::string out = kw("solid") + " part\n";
  for (const Tri& t : tris) {
    out += "  " + kw("facet normal") + " 0 0 1\n    " + kw("outer loop") + "\n";
    for (const auto& p : t.v) {
      char line[160];
      std::snprintf(line, sizeof line, "      %s %.9g\t%.9g  %.9g\r\n", kw("vertex").c_str(), p[0], p[1], p[2]);
      out += line;
    }
    out += "    " + kw("endloop") + "\n  " + kw("endfacet") + "\n";
  }
  out += kw("endsolid") + " part\n";
  return out;
}

// A random closed-ish mesh: a grid of quads over a random height field, two triangles each,
// so that most vertices are shared by six triangles.
std::vector<Tri> gridMesh(std::mt19937& rng, int n) {
  std::uniform_real_distribution<float> height(-1.0f, 1.0f);
  std::vector<std::vector<float>> z(n + 1, std::vector<float>(n + 1));
  for (auto& row : z)
    for (float& h : row) h = height(rng);
  std::vector<Tri> out;
  const auto p = [&](int i, int j) {
    return std::array<float, 3>{0.5f * static_cast<float>(i), 0.25f * static_cast<float>(j),
                                z[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]};
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      out.push_back({{p(i, j), p(i + 1, j), p(i + 1, j + 1)}});
      out.push_back({{p(i, j), p(i + 1, j + 1), p(i, j + 1)}});
    }
  return out;
}

// A coordinate as the file holds it: the float itself (binary), or the decimal the ASCII
// writer printed, read back by strtod (ASCII STL is decimal: no float rounding on reading).
double asWritten(float value, bool ascii) {
  if (!ascii) return double(value);
  char text[64];
  std::snprintf(text, sizeof text, "%.9g", double(value));
  return std::strtod(text, nullptr);
}

// The read mesh holds the written triangles, in order, each corner exactly.
void expectSame(const std::vector<Tri>& tris, const Mesh& mesh, bool ascii) {
  ASSERT_EQ(mesh.triangles.size(), tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3 got = mesh.vertices.at(mesh.triangles[t][k]);
      EXPECT_EQ(got.x, asWritten(tris[t].v[k][0], ascii)) << t;
      EXPECT_EQ(got.y, asWritten(tris[t].v[k][1], ascii)) << t;
      EXPECT_EQ(got.z, asWritten(tris[t].v[k][2], ascii)) << t;
    }
}

// Independently: the distinct corners, by value.
std::size_t distinctCorners(const std::vector<Tri>& tris) {
  std::map<std::array<float, 3>, int> seen;
  for (const Tri& t : tris)
    for (const auto& p : t.v) seen[{p[0] + 0.0f, p[1] + 0.0f, p[2] + 0.0f}] = 1;
  return seen.size();
}

TEST(Stl, BinaryAndAsciiRoundTripOnRandomMeshes) {
  std::mt19937 rng(20261125);
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<Tri> tris = gridMesh(rng, 1 + trial);
    for (const int form : {0, 1, 2}) {
      const std::string bytes = form == 0 ? binaryStl(tris) : asciiStl(tris, form == 2);
      const scallop::StlMesh read = scallop::parseStl(bytes, "random.stl", {});
      EXPECT_EQ(read.format, form == 0 ? StlFormat::binary : StlFormat::ascii);
      EXPECT_EQ(read.trianglesRead, tris.size());
      EXPECT_EQ(read.mesh.units, Units::millimetre);
      EXPECT_EQ(read.zeroAreaDropped, 0u);
      expectSame(tris, read.mesh, form != 0);
      EXPECT_EQ(read.mesh.vertices.size(), distinctCorners(tris)) << "trial " << trial;
    }
  }
}

TEST(Stl, ABinaryFileWhoseHeaderSaysSolidIsBinary) {
  std::mt19937 rng(7);
  const std::vector<Tri> tris = gridMesh(rng, 3);
  const scallop::StlMesh read = scallop::parseStl(binaryStl(tris, "solid looks like ascii"), "a.stl", {Units::inch, false});
  EXPECT_EQ(read.format, StlFormat::binary);
  expectSame(tris, read.mesh, false);
}

TEST(Stl, ACubeMergesToEightVerticesAndMinusZeroIsZero) {
  std::vector<Tri> tris;
  const float o = 0.0f, l = 1.0f, m = -0.0f;
  // Six faces, two triangles each; some zeros written as -0.
  const std::array<std::array<float, 3>, 8> c = {{{o, o, o}, {l, o, m}, {l, l, o}, {m, l, o},
                                                   {o, o, l}, {l, m, l}, {l, l, l}, {o, l, l}}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  for (const auto& f : faces) {
    tris.push_back({{c[f[0]], c[f[1]], c[f[2]]}});
    tris.push_back({{c[f[0]], c[f[2]], c[f[3]]}});
  }
  for (const std::string& bytes : {binaryStl(tris), asciiStl(tris)}) {
    const Mesh mesh = scallop::parseStl(bytes, "cube.stl", {}).mesh;
    EXPECT_EQ(mesh.vertices.size(), 8u);
    EXPECT_EQ(mesh.triangles.size(), 12u);
    // Outward normals from the vertex order: the bottom face's is -z.
    const Vec3 n = scallop::triangleNormal(mesh, 0);
    EXPECT_EQ(n.z, -1.0);
  }
}

TEST(Stl, SeveralSolidsInOneAsciiFile) {
  std::mt19937 rng(3);
  const std::vector<Tri> a = gridMesh(rng, 2), b = gridMesh(rng, 3);
  std::vector<Tri> both = a;
  both.insert(both.end(), b.begin(), b.end());
  const scallop::StlMesh read = scallop::parseStl(asciiStl(a) + asciiStl(b), "two.stl", {});
  expectSame(both, read.mesh, true);
}

// Every malformed file: an error naming the file and the problem.
TEST(Stl, MalformedFilesAreRefusedNamingTheProblem) {
  std::mt19937 rng(11);
  const std::vector<Tri> tris = gridMesh(rng, 2);
  const std::string binary = binaryStl(tris);
  const std::string ascii = asciiStl(tris);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<Tri> withNan = tris, withInf = tris, repeated = tris, collinear = tris;
  withNan[3].v[1][2] = nan;
  withInf[5].v[0][0] = -inf;
  repeated[2].v[2] = repeated[2].v[0];
  collinear[4].v = {{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}};
  std::string asciiNan = ascii;
  asciiNan.replace(asciiNan.find("vertex") + 7, 1, "nan ");
  std::string badNumber = ascii;
  badNumber.replace(badNumber.find("vertex") + 7, 1, "1.2.3 ");
  std::string noEndloop = ascii;
  noEndloop.erase(noEndloop.find("endloop"), 7);
  const struct {
    const char* what;
    std::string bytes;
    std::vector<std::string> mentions;
  } cases[] = {
      {"empty", "", {"bad.stl", "empty"}},
      {"short", std::string(40, 'x'), {"bad.stl", "40 bytes", "too short"}},
      {"truncated binary", binary.substr(0, binary.size() - 7), {"bad.stl", "truncated", "counts 8 triangles"}},
      {"binary with extra bytes", binary + "xyz", {"bad.stl", "truncated"}},
      {"no triangle (binary)", binaryStl({}), {"bad.stl", "no triangle"}},
      {"no triangle (ascii)", "solid empty\nendsolid empty\n", {"bad.stl", "no triangle"}},
      {"NaN vertex", binaryStl(withNan), {"bad.stl: triangle 3, vertex 2", "not finite"}},
      {"infinite vertex", binaryStl(withInf), {"bad.stl: triangle 5, vertex 1", "not finite"}},
      {"repeated point", binaryStl(repeated), {"bad.stl", "triangle 2", "zero area", "repeat a point"}},
      {"collinear", asciiStl(collinear), {"bad.stl:", "triangle 4 has zero area", "lie on a line"}},
      {"nan in ascii", asciiNan, {"bad.stl:4: triangle 0, vertex 1 (nan", "not finite"}},
      {"bad number", badNumber, {"bad.stl:4", "expected a number", "1.2.3"}},
      {"missing endloop", noEndloop, {"bad.stl:", "expected 'endloop'", "endfacet"}},
      {"cut short", ascii.substr(0, ascii.size() / 2), {"bad.stl:", "expected", "the end of the file"}},
      {"not STL", "<html>hello</html>" + std::string(100, ' '), {"bad.stl", "not ASCII STL"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    try {
      scallop::parseStl(c.bytes, "bad.stl", {});
      ADD_FAILURE() << "accepted";
    } catch (const scallop::Error& e) {
      const std::string message = e.what();
      for (const std::string& m : c.mentions) EXPECT_NE(message.find(m), std::string::npos) << message << " lacks " << m;
    }
  }
}

// With dropZeroArea, triangles of zero area are skipped and counted; the rest read as written.
TEST(Stl, ZeroAreaTrianglesDroppedOnRequest) {
  std::mt19937 rng(13);
  std::vector<Tri> tris = gridMesh(rng, 3);
  std::vector<Tri> kept = tris;
  tris.insert(tris.begin() + 4, Tri{{{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}}});  // on a line
  tris.insert(tris.begin() + 9, Tri{{{{1, 0, 0}, {1, 0, 0}, {0, 1, 0}}}});  // a repeated point
  for (const bool ascii : {false, true}) {
    const std::string bytes = ascii ? asciiStl(tris) : binaryStl(tris);
    EXPECT_THROW(scallop::parseStl(bytes, "z.stl", {}), scallop::Error);
    const scallop::StlMesh read = scallop::parseStl(bytes, "z.stl", {Units::millimetre, true});
    EXPECT_EQ(read.trianglesRead, tris.size());
    EXPECT_EQ(read.zeroAreaDropped, 2u);
    EXPECT_EQ(read.firstZeroArea, 4u);
    expectSame(kept, read.mesh, ascii);
  }
  // Nothing but zero area: refused all the same.
  try {
    scallop::parseStl(binaryStl({Tri{{{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}}}}), "z.stl", {Units::millimetre, true});
    ADD_FAILURE() << "accepted";
  } catch (const scallop::Error& e) {
    EXPECT_NE(std::string(e.what()).find("no triangle of positive area"), std::string::npos) << e.what();
  }
}

// Random bytes: a mesh or a clean error, never a crash or a hang.
TEST(Stl, RandomBytesNeverCrash) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 600);
  std::mt19937 meshes(5);
  const std::string ascii = asciiStl(gridMesh(meshes, 2));
  for (int trial = 0; trial < 3000; ++trial) {
    std::string bytes;
    if (trial % 3 == 0) {
      bytes = ascii;  // a good file, a few bytes flipped
      for (int k = 0; k < 3; ++k) bytes[static_cast<std::size_t>(byte(rng)) % bytes.size()] = static_cast<char>(byte(rng));
    } else {
      bytes.resize(static_cast<std::size_t>(length(rng)));
      for (char& ch : bytes) ch = static_cast<char>(byte(rng));
      if (trial % 3 == 1 && bytes.size() >= 5) bytes.replace(0, 5, "solid");
    }
    try {
      const scallop::StlMesh read = scallop::parseStl(bytes, "fuzz.stl", {});
      for (const Vec3& p : read.mesh.vertices) EXPECT_TRUE(std::isfinite(p.x + p.y + p.z));
    } catch (const scallop::Error& e) {
      EXPECT_NE(std::string(e.what()).find("fuzz.stl"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
