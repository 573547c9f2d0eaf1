#include "msfem/cases/surface_io.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/x3d.hpp"

namespace msfem::cases {
namespace {

namespace fs = std::filesystem;

/// A closed cube with 12 outward (counter-clockwise from outside) triangles and coordinates that
/// are not short decimals, so that text round trips exercise full precision.
Surface cube() {
  Surface s;
  s.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    s.vertices.row(i) << 0.0123456789012345 * (i & 1) + 1.0 / 3.0,
        0.0234567890123456 * ((i >> 1) & 1) - 0.1 / 7.0, 0.0345678901234567 * ((i >> 2) & 1) + 1e-5;
  // Vertex id = x + 2y + 4z; each face a quad, fanned into two triangles.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  s.triangles.resize(12, 3);
  for (int q = 0; q < 6; ++q) {
    s.triangles.row(2 * q) << quads[q][0], quads[q][1], quads[q][2];
    s.triangles.row(2 * q + 1) << quads[q][0], quads[q][2], quads[q][3];
  }
  return s;
}

/// Signed volume by the divergence theorem, to check orientation without the library's helper.
double volume(const Surface& s) {
  double six_v = 0;
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0));
    const Eigen::Vector3d b = s.vertices.row(s.triangles(t, 1));
    const Eigen::Vector3d c = s.vertices.row(s.triangles(t, 2));
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6;
}

/// Each triangle's corner positions in order (3 rows per triangle): compares surfaces whose vertex
/// numbering differs, as STL's welded one does.
Eigen::MatrixXd corner_positions(const Surface& s) {
  Eigen::MatrixXd corners(3 * s.num_triangles(), 3);
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k)
      corners.row(3 * t + k) = s.vertices.row(s.triangles(t, k));
  return corners;
}

class SurfaceIo : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    std::random_device random;
    dir_ = fs::temp_directory_path() /
           ("msfem_surface_io_" + std::to_string(random()) + "_" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path file(const std::string& name) const { return dir_ / name; }

  fs::path write_file(const std::string& name, const std::string& bytes) const {
    const fs::path path = file(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_))
      names.push_back(entry.path().filename().string());
    return names;
  }

  fs::path dir_;
};

/// The InputError message `action` throws; a test failure if it throws nothing. Every message must
/// be one line and contain each of `parts` (the file name, the line or element, the fault).
void expect_input_error(const std::function<void()>& action,
                        const std::vector<std::string>& parts) {
  try {
    action();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& part : parts)
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

void expect_read_error(const fs::path& path, const std::vector<std::string>& parts) {
  std::vector<std::string> all = parts;
  all.push_back(path.filename().string());
  expect_input_error([&] { read_surface(path); }, all);
}

// ---- round trips in every format ----

struct Format {
  const char* name;
  const char* extension;
  bool binary;
  bool exact;  ///< false for binary STL, which stores float32
};

void PrintTo(const Format& format, std::ostream* out) {
  *out << format.name;
}

class SurfaceRoundTrip : public SurfaceIo, public ::testing::WithParamInterface<Format> {};

TEST_P(SurfaceRoundTrip, ReadsBackWhatWasWritten) {
  const Format format = GetParam();
  const Surface original = cube();
  const fs::path path = file(std::string("cube") + format.extension);
  write_surface(path, original, {LengthUnit::metre, format.binary});
  const Surface read = read_surface(path);
  ASSERT_EQ(read.num_vertices(), 8);
  ASSERT_EQ(read.num_triangles(), 12);
  EXPECT_GT(volume(read), 0);
  const bool stl = std::string(format.extension) == ".stl";
  if (!stl) {
    EXPECT_EQ(read.vertices, original.vertices);
    EXPECT_EQ(read.triangles, original.triangles);
    return;
  }
  // STL welds corners back into vertices numbered by first use: the same triangles, corner by
  // corner, with a one-to-one renumbering of the vertices.
  std::map<int, int> renumbered;
  for (Eigen::Index t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto [it, inserted] =
          renumbered.try_emplace(original.triangles(t, k), read.triangles(t, k));
      EXPECT_EQ(it->second, read.triangles(t, k)) << "triangle " << t;
      const Eigen::RowVector3d expected = original.vertices.row(original.triangles(t, k));
      const Eigen::RowVector3d got = read.vertices.row(read.triangles(t, k));
      if (format.exact)
        EXPECT_EQ(got, expected);
      else
        EXPECT_LE((got - expected).norm(), 1e-6 * expected.norm());
    }
}

INSTANTIATE_TEST_SUITE_P(
    EveryFormat, SurfaceRoundTrip,
    ::testing::Values(Format{"obj", ".obj", false, true}, Format{"stl_ascii", ".stl", false, true},
                      Format{"stl_binary", ".stl", true, false}, Format{"off", ".off", false, true},
                      Format{"ply_ascii", ".ply", false, true},
                      Format{"ply_binary", ".ply", true, true}, Format{"x3d", ".x3d", false, true}),
    [](const ::testing::TestParamInfo<Format>& info) { return info.param.name; });

// ---- units ----

TEST_F(SurfaceIo, ReadsMillimetresAsMetres) {
  const fs::path path = write_file("mm.obj", "v 25.5 -10 1000\nv 0 0 0\nv 1 2 3\nf 1 2 3\n");
  const Surface s = read_surface(path, LengthUnit::millimetre);
  EXPECT_DOUBLE_EQ(s.vertices(0, 0), 0.0255);
  EXPECT_DOUBLE_EQ(s.vertices(0, 1), -0.01);
  EXPECT_DOUBLE_EQ(s.vertices(0, 2), 1.0);
  EXPECT_DOUBLE_EQ(s.vertices(2, 2), 0.003);
}

TEST_F(SurfaceIo, WritesInTheRequestedUnit) {
  const Surface original = cube();
  const Eigen::MatrixXd corners = corner_positions(original);
  for (const char* extension : {".obj", ".stl", ".off", ".ply"}) {
    const fs::path path = file(std::string("cm") + extension);
    write_surface(path, original, {LengthUnit::centimetre, false});
    // Metres -> cm -> metres is exact up to the rounding of one multiplication and one division.
    const Surface as_cm = read_surface(path, LengthUnit::centimetre);
    EXPECT_LE((corner_positions(as_cm) - corners).cwiseAbs().maxCoeff(), 1e-15) << extension;
    // Read as metres, the file's numbers are 100 times the coordinates.
    const Surface as_m = read_surface(path, LengthUnit::metre);
    EXPECT_LE((corner_positions(as_m) - 100.0 * corners).cwiseAbs().maxCoeff(), 1e-13) << extension;
  }
}

// ---- what the readers accept ----

TEST_F(SurfaceIo, ObjWithQuadsSlashesNegativeIndicesAndIgnoredStatements) {
  const fs::path path = write_file("mixed.obj",
                                   "# a comment\r\n"
                                   "mtllib x.mtl\r\no thing\r\ng group\r\ns 1\r\nusemtl skin\r\n"
                                   "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n"
                                   "vn 0 0 1\r\nvt 0.5 0.5\r\n"
                                   "f 1/1/1 2/1/1 3/1/1 4/1/1\r\n"  // quad, v/vt/vn
                                   "v 0.5 0.5 1 1.0\r\n"            // with a w component
                                   "f -5//1 -4//1 -1//1\r\n"        // negative: 1 2 5
                                   "f 2/1 3/1 5/1\r\n"
                                   "\r\n");
  const Surface s = read_surface(path);
  ASSERT_EQ(s.num_vertices(), 5);
  ASSERT_EQ(s.num_triangles(), 4);
  Eigen::MatrixX3i expected(4, 3);
  expected << 0, 1, 2, 0, 2, 3, 0, 1, 4, 1, 2, 4;
  EXPECT_EQ(s.triangles, expected);
  EXPECT_EQ(s.vertices(4, 2), 1.0);
}

TEST_F(SurfaceIo, OffWithCommentsPolygonsAndCountsOnTheHeaderLine) {
  const fs::path path = write_file("poly.off",
                                   "OFF 5 2 0 # counts here\n"
                                   "# vertices\n"
                                   "0 0 0\n1 0 0\n1 1 0 # a comment\n0 1 0\n\n0.5 1.5 0\n"
                                   "5 0 1 2 4 3 255 0 0\n"  // pentagon with a face colour
                                   "3 0 2 3\n");
  const Surface s = read_surface(path);
  ASSERT_EQ(s.num_vertices(), 5);
  Eigen::MatrixX3i expected(4, 3);
  expected << 0, 1, 2, 0, 2, 4, 0, 4, 3, 0, 2, 3;
  EXPECT_EQ(s.triangles, expected);
}

const char* const ply_header_with_extras =
    "element vertex 4\n"
    "property float nx\nproperty double x\nproperty float y\nproperty float z\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    "property list uchar float texcoord\n"
    "element face 2\n"
    "property uchar flags\nproperty list uchar int vertex_indices\nproperty ushort label\n"
    "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
    "end_header\n";

TEST_F(SurfaceIo, AsciiPlySkipsOtherPropertiesListsAndElements) {
  const fs::path path = write_file("extras.ply", std::string("ply\nformat ascii 1.0\ncomment c\n") +
                                                     ply_header_with_extras +
                                                     "0.1 0 0 0 255 128 0 2 0.5 0.5\n"
                                                     "0.2 1 0 0 1 2 3 0\n"
                                                     "0.3 1 1 0 4 5 6 1 7\n"
                                                     "0.4 0 1 0.25 7 8 9 0\n"
                                                     "9 4 0 1 2 3 65535\n"
                                                     "1 3 3 2 1 0\n"
                                                     "0 1\n");
  const Surface s = read_surface(path);
  ASSERT_EQ(s.num_vertices(), 4);
  EXPECT_EQ(s.vertices(3, 2), 0.25);
  EXPECT_EQ(s.vertices(2, 0), 1.0);
  Eigen::MatrixX3i expected(3, 3);
  expected << 0, 1, 2, 0, 2, 3, 3, 2, 1;
  EXPECT_EQ(s.triangles, expected);
}

/// Binary PLY body writer in either byte order.
struct PlyBytes {
  bool big_endian;
  std::string bytes;
  template <class T>
  PlyBytes& put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    const std::uint16_t probe = 1;
    const bool host_little = *reinterpret_cast<const char*>(&probe) == 1;
    if (host_little == big_endian) std::reverse(raw, raw + sizeof(T));
    bytes.append(raw, sizeof(T));
    return *this;
  }
};

TEST_F(SurfaceIo, BinaryPlyInBothByteOrdersSkipsExtras) {
  for (bool big_endian : {false, true}) {
    PlyBytes body{big_endian, {}};
    const double xs[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.25}};
    for (const auto& x : xs) {
      body.put(0.5f).put(x[0]).put(static_cast<float>(x[1])).put(static_cast<float>(x[2]));
      body.put<std::uint8_t>(255).put<std::uint8_t>(0).put<std::uint8_t>(10);
      body.put<std::uint8_t>(1).put(0.5f);  // one texcoord
    }
    body.put<std::uint8_t>(9).put<std::uint8_t>(4).put(0).put(1).put(2).put(3);
    body.put<std::uint16_t>(65535);
    body.put<std::uint8_t>(1).put<std::uint8_t>(3).put(3).put(2).put(1).put<std::uint16_t>(0);
    body.put(0).put(1);
    const std::string format = big_endian ? "binary_big_endian" : "binary_little_endian";
    const fs::path path =
        write_file("binary_" + format + ".ply",
                   "ply\r\nformat " + format + " 1.0\r\n" + ply_header_with_extras + body.bytes);
    const Surface s = read_surface(path);
    ASSERT_EQ(s.num_vertices(), 4) << format;
    EXPECT_EQ(s.vertices(3, 2), 0.25) << format;
    EXPECT_EQ(s.vertices(1, 0), 1.0) << format;
    Eigen::MatrixX3i expected(3, 3);
    expected << 0, 1, 2, 0, 2, 3, 3, 2, 1;
    EXPECT_EQ(s.triangles, expected) << format;
  }
}

TEST_F(SurfaceIo, PlyAcceptsVertexIndexAndSizedTypeNames) {
  const fs::path path = write_file("vi.ply",
                                   "ply\nformat ascii 1.0\nelement vertex 3\nproperty float32 x\n"
                                   "property float32 y\nproperty float32 z\nelement face 1\n"
                                   "property list uint8 uint32 vertex_index\nend_header\n"
                                   "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(read_surface(path).num_triangles(), 1);
}

TEST_F(SurfaceIo, StlWeldsSharedCornersAndTakesBinaryWithASolidHeader) {
  write_surface(file("cube.stl"), cube(), {LengthUnit::metre, true});
  std::string bytes;
  {
    std::ifstream in(file("cube.stl"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  bytes.replace(0, 11, "solid cube ");  // what some exporters put in a binary header
  const Surface s = read_surface(write_file("solid_binary.stl", bytes));
  EXPECT_EQ(s.num_vertices(), 8);
  EXPECT_EQ(s.num_triangles(), 12);
}

TEST_F(SurfaceIo, ExtensionsAreCaseInsensitive) {
  EXPECT_EQ(surface_format_for("a/B.OBJ"), SurfaceFormat::obj);
  EXPECT_EQ(surface_format_for("x.Stl"), SurfaceFormat::stl);
  EXPECT_EQ(surface_format_for("x.off"), SurfaceFormat::off);
  EXPECT_EQ(surface_format_for("x.PLY"), SurfaceFormat::ply);
}

// ---- bad input: InputError naming the file and the line or element ----

TEST_F(SurfaceIo, UnknownExtensionAndMissingFile) {
  expect_read_error(write_file("points.xyz", "1 2 3\n"),
                    {"unknown surface format '.xyz'", "(expected .obj, .stl, .off, .ply, .x3d)"});
  expect_read_error(file("absent.obj"), {"cannot open", "No such file"});
  expect_read_error(write_file("empty.obj", ""), {"empty file"});
  expect_read_error(write_file("no_faces.obj", "v 0 0 0\n"), {"no triangles"});
}

TEST_F(SurfaceIo, BadObjLines) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expect_read_error(write_file("a.obj", "v 0 0 0\n\nv 1 abc 0\n"), {"a.obj:3:", "'abc'"});
  expect_read_error(write_file("b.obj", "v 0 0 0\nv nan 0 0\n"),
                    {"b.obj:2: non-finite coordinate"});
  expect_read_error(write_file("c.obj", "v 1e999 0 0\n"), {"c.obj:1: non-finite coordinate"});
  expect_read_error(write_file("d.obj", "v 0 0\n"), {"d.obj:1:", "three coordinates"});
  expect_read_error(write_file("e.obj", v + "f 1 2 9\n"), {"e.obj:4:", "9 out of range"});
  expect_read_error(write_file("f.obj", v + "f -1 -2 -4\n"), {"f.obj:4:", "out of range"});
  expect_read_error(write_file("g.obj", v + "f 1 2\n"), {"g.obj:4:", "needs at least 3"});
  expect_read_error(write_file("h.obj", v + "f 0 1 2\n"), {"h.obj:4:", "index 0"});
  expect_read_error(write_file("i.obj", v + "f 1 x 2\n"), {"i.obj:4:", "'x'"});
  expect_read_error(write_file("j.obj", v + "curv 0 1 1 2\n"), {"j.obj:4:", "'curv'"});
}

TEST_F(SurfaceIo, AbsurdScalesAreRefusedForEveryReader) {
  // CGAL's predicates overflow on the first (the alpha wrap died with SIGFPE) and divide by zero on
  // the others; every command reads through here, so none of them gets that far.
  const std::string faces = "f 1 2 3\nf 1 3 2\n";
  expect_read_error(write_file("far.obj", "v 0 0 0\nv 1e200 0 0\nv 0 1 0\n" + faces),
                    {"far.obj: vertex 2 (of 3, in file order) is at (1e+200, 0, 0) m, more than "
                     "1e6 m from the origin"});
  expect_read_error(write_file("point.obj", "v 1 2 3\nv 1 2 3\nv 1 2 3\n" + faces),
                    {"point.obj: the surface spans 0 m (its bounding-box diagonal), less than "
                     "1e-6 m"});
  expect_read_error(write_file("tiny.obj", "v 0 0 0\nv 1e-300 0 0\nv 0 1e-300 0\n" + faces),
                    {"tiny.obj: the surface spans 1.41421e-300 m"});
  // The bound applies in metres, after the unit: 5e8 mm is 5e5 m.
  const fs::path mm = write_file("mm.off", "OFF\n3 1 0\n0 0 0\n5e8 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NO_THROW(read_surface(mm, LengthUnit::millimetre));
  expect_read_error(mm, {"mm.off: vertex 2", "(5e+08, 0, 0) m"});
}

TEST_F(SurfaceIo, BadStl) {
  write_surface(file("cube.stl"), cube(), {LengthUnit::metre, true});
  std::string bytes;
  {
    std::ifstream in(file("cube.stl"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_EQ(bytes.size(), 84u + 50u * 12u);
  expect_read_error(write_file("short.stl", bytes.substr(0, bytes.size() - 10)),
                    {"truncated binary STL: header says 12 triangles (needs 684 bytes) but file "
                     "has 674 bytes"});
  std::string solid = bytes.substr(0, 300);
  solid.replace(0, 6, "solid ");
  expect_read_error(write_file("short_solid.stl", solid), {"truncated binary STL"});
  std::string nan_corner = bytes;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan_corner[84 + 50 * 5 + 12 + 4], &nan, 4);  // triangle 5, first corner, y
  expect_read_error(write_file("nan.stl", nan_corner), {"triangle #5: non-finite coordinate"});
  expect_read_error(write_file("tiny.stl", "abc"), {"not an STL file"});
  expect_read_error(write_file("two.stl",
                               "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                               "vertex 1 0 0\nendloop\nendfacet\nendsolid s\n"),
                    {"two.stl:7:", "facet with 2 vertices"});
  expect_read_error(
      write_file("word.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 zero 0\n"),
      {"word.stl:4:", "'zero'"});
}

TEST_F(SurfaceIo, BadOff) {
  expect_read_error(write_file("a.off", "# nothing\nOFX\n"), {"a.off:2:", "'OFF'"});
  expect_read_error(write_file("b.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
                    {"b.off:6:", "3 out of range"});
  expect_read_error(write_file("c.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"),
                    {"c.off:4:", "2 of 3 vertices"});
  expect_read_error(write_file("d.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n"),
                    {"d.off:4: non-finite coordinate"});
  expect_read_error(write_file("e.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                    {"e.off:6:", "needs at least 3"});
  expect_read_error(write_file("f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
                    {"f.off:6:", "2 of 3 vertex indices"});
}

// An X3D IndexedFaceSet as the layered brain paper's scene has it: commas between points, polygons
// fan-triangulated, the last face without its -1, the Shape chosen by DEF; every fault named.
TEST_F(SurfaceIo, X3dFaceSetsByDefWithPolygonsAndFaults) {
  const std::string square =
      "<X3D version=\"3.3\"><Scene><Shape DEF=\"other\"><IndexedFaceSet coordIndex=\"0 1 2\">"
      "<Coordinate point=\"0 0 0, 1 0 0, 0 1 0\"/></IndexedFaceSet></Shape>"
      "<Transform><Shape DEF=\"quad\"><IndexedFaceSet coordIndex=\"0 1 2 3 -1 0 3 2\">"
      "<Coordinate point=\"0 0 0, 0.1 0 0, 0.1 0.1 0, 0 0.1 0\"/></IndexedFaceSet></Shape>"
      "</Transform></Scene></X3D>";
  const fs::path path = write_file("scene.x3d", square);
  const Surface quad = read_x3d_surface(path, "quad");
  EXPECT_EQ(quad.num_vertices(), 4);
  ASSERT_EQ(quad.num_triangles(), 3);  // the quad's two and the last face's one
  EXPECT_EQ(quad.triangles.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(read_x3d_surface(path).num_vertices(), 3);  // the first face set
  const std::string head = "<X3D><Scene><Shape><IndexedFaceSet coordIndex=\"";
  expect_read_error(write_file("a.x3d", "<X3D><Scene>"), {"a.x3d: not XML"});
  expect_read_error(write_file("b.x3d", "<X3D><Scene/></X3D>"), {"b.x3d: no IndexedFaceSet"});
  expect_read_error(write_file("c.x3d", head + "0 1 3\"><Coordinate point=\"0 0 0 1 0 0 0 1 0\"/>"
                                               "</IndexedFaceSet></Shape></Scene></X3D>"),
                    {"c.x3d: coordIndex face 0: index 3 out of range (3 points)"});
  expect_read_error(write_file("d.x3d", head + "0 1 2\"><Coordinate point=\"0 0 0 1 nan 0 0 1 0\"/>"
                                               "</IndexedFaceSet></Shape></Scene></X3D>"),
                    {"d.x3d: Coordinate point 1:", "not a finite number"});
  expect_read_error(write_file("e.x3d", head + "0 1 -1\"><Coordinate point=\"0 0 0 1 0 0 0 1 0\"/>"
                                               "</IndexedFaceSet></Shape></Scene></X3D>"),
                    {"e.x3d: coordIndex face 0 has 2 corners"});
  EXPECT_THROW(read_x3d_surface(path, "none"), InputError);
}

TEST_F(SurfaceIo, BadPly) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_read_error(write_file("a.ply", header + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
                    {"a.ply:11: non-finite coordinate"});
  expect_read_error(write_file("b.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
                    {"b.ply:13:", "3 out of range"});
  expect_read_error(write_file("c.ply", header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                    {"c.ply:13:", "needs at least 3"});
  expect_read_error(write_file("d.ply", header + "0 0 0\n1 0 0\n"), {"d.ply:", "file ends"});
  expect_read_error(write_file("e.ply",
                               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x"
                               "\nproperty float y\nelement face 0\n"
                               "property list uchar int vertex_indices\nend_header\n0 0\n"),
                    {"e.ply:3:", "'z'"});
  expect_read_error(write_file("f.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                    {"f.ply:2:", "binary_middle_endian"});

  write_surface(file("cube.ply"), cube(), {LengthUnit::metre, true});
  std::string bytes;
  {
    std::ifstream in(file("cube.ply"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  expect_read_error(write_file("g.ply", bytes.substr(0, bytes.size() - 20)),
                    {"face #10:", "truncated"});
  const std::size_t body = bytes.find("end_header\n") + 11;
  std::string nan_vertex = bytes;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&nan_vertex[body + 24 * 6 + 16], &nan, 8);  // vertex 6, z
  expect_read_error(write_file("h.ply", nan_vertex), {"vertex #6: non-finite coordinate"});
}

// ---- writing: all or nothing ----

TEST_F(SurfaceIo, RefusedWritesLeaveNothingBehind) {
  Surface not_finite = cube();
  not_finite.vertices(3, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { write_surface(file("nan.obj"), not_finite); },
                     {"nan.obj", "vertex #3", "non-finite"});
  Surface out_of_range = cube();
  out_of_range.triangles(7, 2) = 8;
  expect_input_error([&] { write_surface(file("range.ply"), out_of_range); },
                     {"range.ply", "triangle #7", "8 out of range"});
  Surface huge = cube();
  huge.vertices(0, 0) = 1e306;  // finite in metres, infinite in millimetres
  expect_input_error(
      [&] {
        write_surface(file("huge.off"), huge, {LengthUnit::millimetre, false});
      },
      {"huge.off", "non-finite"});
  huge.vertices(0, 0) = 1e300;  // finite as double, not as float32
  expect_input_error(
      [&] {
        write_surface(file("huge.stl"), huge, {LengthUnit::metre, true});
      },
      {"huge.stl", "float32"});
  expect_input_error([&] { write_surface(file("empty.obj"), Surface{}); }, {"empty.obj"});
  expect_input_error([&] { write_surface(file("cube.vtk"), cube()); }, {"cube.vtk", "'.vtk'"});
  EXPECT_TRUE(listing().empty());
}

TEST_F(SurfaceIo, FailedWritesNameTheFileAndRemoveTheTemporary) {
  expect_input_error([&] { write_surface(file("missing_dir") / "cube.obj", cube()); },
                     {"missing_dir/cube.obj", "cannot write"});
  fs::create_directory(file("taken.obj"));  // rename onto a directory fails
  expect_input_error([&] { write_surface(file("taken.obj"), cube()); },
                     {"taken.obj", "cannot write"});
  EXPECT_EQ(listing(), std::vector<std::string>{"taken.obj"});
}

TEST_F(SurfaceIo, WriteReplacesAnExistingFile) {
  const fs::path path = write_file("cube.off", "old contents");
  Surface moved = cube();
  moved.vertices.array() += 1.0;
  write_surface(path, moved);
  EXPECT_EQ(read_surface(path).vertices, moved.vertices);
  EXPECT_EQ(listing(), std::vector<std::string>{"cube.off"});
}

}  // namespace
}  // namespace msfem::cases
