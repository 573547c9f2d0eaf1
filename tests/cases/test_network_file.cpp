#include "msfem/cases/network_file.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "msfem/cases/errors.hpp"

namespace msfem::cases {
namespace {

namespace fs = std::filesystem;

/// A grid to encode every way VTK XML allows. Nine cells, lines among a triangle and a tetrahedron,
/// so that each array's slots on the other cell types (-1 in the spring arrays, 0 in bulk_modulus)
/// must be ignored.
struct Array {
  std::string name, type;
  int components = 1;
  std::vector<double> values;
  std::vector<std::string> strings = {};
};

struct Grid {
  Array points{
      "", "Float64", 3, {0, 0, 0, 0.1, 0, 0, 0, 0.2, 0, 0, 0, 0.30000000000000004, 1, 1, 1}};
  Array connectivity{
      "connectivity", "Int64", 1, {0, 1, 1, 2, 0, 1, 2, 2, 0, 0, 3, 0, 1, 2, 3, 1, 3, 2, 3, 3, 4}};
  Array offsets{"offsets", "Int32", 1, {2, 4, 7, 9, 11, 15, 17, 19, 21}};
  Array types{"types", "UInt8", 1, {3, 3, 5, 3, 3, 10, 3, 3, 3}};
  std::vector<Array> cell{
      {"stiffness", "Float32", 1, {100.5, 200.25, -1, 300, 400, -1, 500, 600.75, 7}},
      {"damping", "Float64", 1, {0.1, 0.2, -1, 0, 0.4, -1, 0.5, 0.6, 0.7}},
      {"group", "Int32", 1, {0, 1, -1, 0, 1, -1, 0, 1, 1}},
      {"bulk_modulus", "Float64", 1, {0, 0, 0, 0, 0, 2.5e3, 0, 0, 0}}};
  std::vector<Array> point{{"mass", "Float64", 1, {0.5, 0.25, 0.125, 1.0 / 3, 2}},
                           {"fixed", "UInt8", 1, {1, 0, 0, 0, 1}}};
  std::vector<Array> field{{"group_names", "String", 1, {}, {"tier a", "tier_b"}}};
};

enum class Mode { ascii, binary, appended_raw, appended_base64 };

struct Encoding {
  Mode mode = Mode::ascii;
  bool compressed = false, header64 = false, big_endian = false;
  std::size_t block = 16;  ///< small, so that arrays span several blocks and a last partial one
};

std::string base64(const std::string& bytes) {
  static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t group = 0;
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    for (std::size_t k = 0; k < 3; ++k)
      group = (group << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k)
      out += k <= n ? digits[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

void append_word(std::string& out, std::uint64_t value, std::size_t size, bool big_endian) {
  for (std::size_t k = 0; k < size; ++k)
    out += static_cast<char>((value >> (8 * (big_endian ? size - 1 - k : k))) & 0xffu);
}

std::string bytes_of(const Array& array, bool big_endian) {
  std::string out;
  if (array.type == "String") {
    for (const std::string& s : array.strings)
      out += s + '\0';
    return out;
  }
  for (double v : array.values) {
    const float f = static_cast<float>(v);
    std::uint32_t f_bits;
    std::memcpy(&f_bits, &f, 4);
    std::uint64_t bits = f_bits;
    if (array.type == "Float64") std::memcpy(&bits, &v, 8);
    if (array.type != "Float64" && array.type != "Float32")
      bits = static_cast<std::uint64_t>(static_cast<long long>(v));
    const bool four = array.type == "Int32" || array.type == "Float32";
    append_word(out, bits, array.type == "UInt8" ? 1 : four ? 4 : 8, big_endian);
  }
  return out;
}

/// VTK's binary layout: a size header then the data, or a block header then zlib blocks; VTK
/// base64-encodes a compressed array's header apart from its blocks.
std::string payload(const std::string& data, const Encoding& e, bool as_base64) {
  const std::size_t word = e.header64 ? 8 : 4;
  std::string header, blocks;
  if (!e.compressed) {
    append_word(header, data.size(), word, e.big_endian);
    return as_base64 ? base64(header + data) : header + data;
  }
  const std::size_t count = (data.size() + e.block - 1) / e.block;
  append_word(header, count, word, e.big_endian);
  append_word(header, e.block, word, e.big_endian);
  append_word(header, data.size() % e.block, word, e.big_endian);
  for (std::size_t b = 0; b < count; ++b) {
    const std::string piece = data.substr(b * e.block, e.block);
    std::string packed(compressBound(piece.size()), '\0');
    uLongf size = packed.size();
    EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(packed.data()), &size,
                        reinterpret_cast<const Bytef*>(piece.data()), piece.size(), 9),
              Z_OK);
    blocks += packed.substr(0, size);
    append_word(header, size, word, e.big_endian);
  }
  return as_base64 ? base64(header) + base64(blocks) : header + blocks;
}

std::string encode(const Grid& grid, const Encoding& e) {
  std::string appended;
  const auto array_xml = [&](const Array& a) {
    std::string xml = "<DataArray type=\"" + a.type + "\"";
    if (!a.name.empty()) xml += " Name=\"" + a.name + "\"";
    if (a.components != 1) xml += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
    if (a.type == "String") xml += " NumberOfTuples=\"" + std::to_string(a.strings.size()) + "\"";
    const std::string data = bytes_of(a, e.big_endian);
    if (e.mode == Mode::ascii) {
      xml += " format=\"ascii\">";
      char number[32];
      for (std::size_t i = 0; i < (a.type == "String" ? data.size() : a.values.size()); ++i) {
        const double v = a.type == "String" ? static_cast<unsigned char>(data[i]) : a.values[i];
        xml += std::string(number, std::snprintf(number, sizeof number, "%.17g ", v));
      }
      return xml + "</DataArray>\n";
    }
    if (e.mode == Mode::binary)
      return xml + " format=\"binary\">\n  " + payload(data, e, true) + "\n</DataArray>\n";
    xml += " format=\"appended\" offset=\"" + std::to_string(appended.size()) + "\"/>\n";
    appended += payload(data, e, e.mode == Mode::appended_base64);
    return xml;
  };
  const auto group = [&](const char* tag, const std::vector<Array>& arrays) {
    std::string xml = std::string("<") + tag + ">\n";
    for (const Array& a : arrays)
      xml += array_xml(a);
    return xml + "</" + tag + ">\n";
  };
  std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\"";
  xml += e.big_endian ? " byte_order=\"BigEndian\"" : " byte_order=\"LittleEndian\"";
  xml += e.header64 ? " header_type=\"UInt64\"" : " header_type=\"UInt32\"";
  if (e.compressed) xml += " compressor=\"vtkZLibDataCompressor\"";
  // One statement each: the appended data follows the file's order of arrays.
  xml += ">\n<UnstructuredGrid>\n" + group("FieldData", grid.field);
  xml += "<Piece NumberOfPoints=\"5\" NumberOfCells=\"9\">\n" + group("PointData", grid.point);
  xml += group("CellData", grid.cell);
  xml += group("Points", {grid.points});
  xml += group("Cells", {grid.connectivity, grid.offsets, grid.types});
  xml += "</Piece>\n</UnstructuredGrid>\n";
  if (e.mode == Mode::appended_raw || e.mode == Mode::appended_base64)
    xml += std::string("<AppendedData encoding=\"") +
           (e.mode == Mode::appended_raw ? "raw" : "base64") + "\">\n   _" + appended +
           "\n</AppendedData>\n";
  return xml + "</VTKFile>\n";
}

// ---- checks ----

/// Equal sizes and equal coefficients (Eigen's == alone does not check sizes in a release build).
template <typename A, typename B>
::testing::AssertionResult same(const A& a, const B& b) {
  if (a.rows() == b.rows() && a.cols() == b.cols() && (a.rows() == 0 || a.cols() == 0 || a == b))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\n" << a << "\nis not\n" << b;
}

template <typename A>
::testing::AssertionResult same(const std::optional<A>& a, const std::optional<A>& b) {
  if (a.has_value() != b.has_value()) return ::testing::AssertionFailure() << "one is unset";
  return a ? same(*a, *b) : ::testing::AssertionSuccess();
}

void expect_same(const NetworkFile& a, const NetworkFile& b) {
  EXPECT_TRUE(same(a.points, b.points));
  EXPECT_TRUE(same(a.springs, b.springs));
  EXPECT_TRUE(same(a.stiffness, b.stiffness));
  EXPECT_TRUE(same(a.damping, b.damping));
  EXPECT_TRUE(same(a.rest_length, b.rest_length));
  EXPECT_TRUE(same(a.spring_group, b.spring_group));
  EXPECT_EQ(a.group_names, b.group_names);
  EXPECT_TRUE(same(a.triangles, b.triangles));
  EXPECT_TRUE(same(a.tetrahedra, b.tetrahedra));
  EXPECT_TRUE(same(a.bulk_modulus, b.bulk_modulus));
  EXPECT_TRUE(same(a.mass, b.mass));
  EXPECT_EQ(a.fixed, b.fixed);
  EXPECT_TRUE(same(a.gravity, b.gravity));
  EXPECT_EQ(a.viscosity, b.viscosity);
}

/// The message `action` throws as an InputError: one line, holding each of `parts`.
void expect_error(const std::function<void()>& action, const std::vector<std::string>& parts) {
  try {
    action();
    ADD_FAILURE() << "no InputError; expected one containing '" << parts.front() << "'";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& part : parts)
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

void expect_read_error(const std::string& name, const std::string& bytes,
                       std::vector<std::string> parts) {
  parts.insert(parts.begin(), name + ":");
  expect_error([&] { read_network_bytes(name, bytes); }, parts);
}

/// Reads every prefix of `bytes` and, for each byte, a copy with that byte changed: each must read
/// or throw InputError, never crash, hang or throw anything else.
void expect_robust(const std::string& name, const std::string& bytes) {
  std::mt19937 random(7);
  for (std::size_t i = 0; i < 2 * bytes.size(); ++i) {
    std::string variant = i < bytes.size() ? bytes.substr(0, i) : bytes;
    if (i >= bytes.size()) variant[i - bytes.size()] ^= static_cast<char>(1 + random() % 255);
    try {
      read_network_bytes(name, variant);
    } catch (const InputError&) {
    }
  }
}

class NetworkFileTest : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }
  static std::string slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path dir_ =
      fs::temp_directory_path() / ("msfem_network_" + std::to_string(std::random_device()()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
};

// ---- reading ----

TEST(NetworkFile, ReadsHandWrittenAsciiVtu) {
  const std::string vtu = R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="3" NumberOfCells="4">
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0  0.5 0 0  0 0.25 0</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 1 2 2 0 0 1 2</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">2 4 6 9</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">3 3 3 5</DataArray>
      </Cells>
      <CellData>
        <DataArray type="Float64" Name="stiffness" format="ascii">10 20 30 -5</DataArray>
        <DataArray type="String" Name="group" format="ascii">101 100 103 101 0 115 107 105 110 0
          101 100 103 101 0 0</DataArray>
      </CellData>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
)";
  const NetworkFile net = read_network_bytes("hand.vtu", vtu);
  EXPECT_EQ(net.format, NetworkFile::Format::vtu);
  EXPECT_TRUE(same(net.points, Eigen::Matrix3d{{0, 0, 0}, {0.5, 0, 0}, {0, 0.25, 0}}));
  EXPECT_TRUE(same(net.springs, Eigen::Matrix<int, 3, 2>{{0, 1}, {1, 2}, {2, 0}}));
  EXPECT_TRUE(same(net.stiffness, Eigen::Vector3d(10, 20, 30)));
  EXPECT_EQ(net.group_names, (std::vector<std::string>{"edge", "skin"}));
  EXPECT_TRUE(same(net.spring_group, Eigen::Vector3i(0, 1, 0)));
  ASSERT_EQ(net.triangles.rows(), 1);
  EXPECT_FALSE(net.damping || net.rest_length || net.mass || net.fixed);
}

TEST(NetworkFile, ReadsEveryXmlEncodingAlike) {
  const Grid grid;
  const NetworkFile ascii = read_network_bytes("grid.vtu", encode(grid, {}));
  ASSERT_EQ(ascii.springs.rows(), 7);
  EXPECT_EQ(ascii.stiffness(2), 300);  // cell 3: the triangle's slot is skipped
  EXPECT_TRUE(same(ascii.bulk_modulus, Eigen::VectorXd::Constant(1, 2.5e3)));
  EXPECT_EQ(ascii.group_names, (std::vector<std::string>{"tier a", "tier_b"}));
  EXPECT_EQ(ascii.spring_group(6), 1);
  EXPECT_EQ(ascii.fixed, (std::vector<bool>{true, false, false, false, true}));
  EXPECT_EQ(ascii.points(3, 2), 0.30000000000000004);
  for (Mode mode : {Mode::binary, Mode::appended_raw, Mode::appended_base64})
    for (bool compressed : {false, true})
      for (bool header64 : {false, true}) {
        SCOPED_TRACE(::testing::Message() << int(mode) << compressed << header64);
        // BigEndian once: the raw appended arrays and their headers byte-swapped.
        const bool big = header64 && compressed && mode == Mode::appended_raw;
        expect_same(read_network_bytes("grid.vtu", encode(grid, {mode, compressed, header64, big})),
                    ascii);
      }
}

TEST(NetworkFile, ReadsLegacyAsciiBothCellLayouts) {
  const std::string head =
      "# vtk DataFile Version 3.0\nchain\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 3 double\n0 0 0 1 0 0 1 1 0\n";
  const std::string data =
      "CELL_TYPES 3\n3 3 5\nCELL_DATA 3\nSCALARS stiffness double 1\nLOOKUP_TABLE default\n"
      "5 6 0\nFIELD FieldData 2\ndamping 1 3 float\n0.5 0.25 0\ngroup 1 3 string\nouter\n"
      "in%20ner\nouter\nPOINT_DATA 3\nSCALARS mass double\nLOOKUP_TABLE default\n1 2 3\n";
  const NetworkFile classic =
      read_network_bytes("c.vtk", head + "CELLS 3 10\n2 0 1\n2 1 2\n3 0 1 2\n" + data);
  EXPECT_EQ(classic.format, NetworkFile::Format::vtk);
  EXPECT_TRUE(same(classic.stiffness, Eigen::Vector2d(5, 6)));
  EXPECT_TRUE(same(*classic.damping, Eigen::Vector2d(0.5, 0.25)));
  EXPECT_EQ(classic.group_names, (std::vector<std::string>{"outer", "in ner"}));
  EXPECT_EQ(classic.triangles.rows(), 1);
  EXPECT_EQ((*classic.mass)(2), 3);
  const NetworkFile v51 = read_network_bytes(
      "n.vtk", head +
                   "CELLS 4 7\nOFFSETS vtktypeint64\n0 2 4 7\nCONNECTIVITY vtktypeint64\n"
                   "0 1 1 2 0 1 2\n" +
                   data);
  expect_same(v51, classic);
}

TEST(NetworkFile, ReadsLegacyBinaryBigEndian) {
  std::string vtk = "# vtk DataFile Version 3.0\nbinary\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  const auto words = [&](const char* line, const char* type, const std::vector<double>& values) {
    vtk += line + bytes_of({"", type, 1, values}, true) + "\n";
  };
  words("POINTS 3 float\n", "Float32", {0, 0, 0, 1, 0, 0, 0, 2, 0});
  words("CELLS 2 6\n", "Int32", {2, 0, 1, 2, 1, 2});
  words("CELL_TYPES 2\n", "Int32", {3, 3});
  words("CELL_DATA 2\nSCALARS stiffness double 1\nLOOKUP_TABLE default\n", "Float64", {1.5, 2.5});
  const NetworkFile net = read_network_bytes("b.vtk", vtk);
  EXPECT_TRUE(same(net.stiffness, Eigen::Vector2d(1.5, 2.5)));
  EXPECT_EQ(net.points(2, 1), 2);
  expect_robust("b.vtk", vtk);
}

const char* const xs3 =
    "Xsp 3.0\n# a chain\nnumm 3\nnums 2\ngrav 0 -9.81 0\nvisc 0.5\n"
    "mass 1 s 0 0 0 0 0 0 -0.1 0\nmass 2 i 2 0 0 0 0 0 0.2 0\nmass 3 s 2 1 0 1 0 0 0.3 0\n"
    "lspg 1 1 2 100 1 -1\nlspg 2 2 3 50 0.5 0.75\n";

TEST(NetworkFile, ReadsXspAsSofaDoes) {
  const NetworkFile net = read_network_bytes("chain.xs3", xs3);
  EXPECT_EQ(net.format, NetworkFile::Format::xsp);
  EXPECT_TRUE(same(net.springs, Eigen::Matrix2i{{0, 1}, {1, 2}}));  // the file counts from 1
  EXPECT_TRUE(same(net.stiffness, Eigen::Vector2d(50, 50)));  // l0 = -1: 100 per unit of length 2
  EXPECT_TRUE(same(*net.damping, Eigen::Vector2d(0.5, 0.5)));
  EXPECT_TRUE(same(*net.rest_length, Eigen::Vector2d(2, 0.75)));
  EXPECT_TRUE(same(*net.mass, Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_EQ(net.fixed, (std::vector<bool>{true, false, false}));
  EXPECT_TRUE(same(net.gravity, Eigen::Vector3d(0, -9.81, 0)));
  EXPECT_EQ(net.viscosity, 0.5);
  const NetworkFile v4 =
      read_network_bytes("chain.xs4",
                         "Xsp 4.0\nmass 1 s 0 0 0 0 0 0 0.1 0\nmass 2 s 1 0 0 0 0 0 0.1 0\n"
                         "lspg 1 1 2 100 1 1 1.1 1.2 1.3\n");
  EXPECT_EQ(v4.stiffness(0), 100);
  expect_read_error("s.xs3", "Xsp 3.0\nstep 0.01\n", {":2:", "'step'", "time step"});
  expect_read_error("f.xs3", "Xsp 3.0\nfrce 1 0 0 1\n", {":2:", "'frce'"});
  expect_read_error("u.xs3", "Xsp 3.0\nspng 1\n", {":2:", "unknown Xsp keyword 'spng'"});
  expect_read_error("v.xs3", "Xsp 5.0\n", {"version 5"});
  expect_read_error("i.xs3", "Xsp 3.0\nmass 1 s 0 0 0 0 0 0 1 0\nlspg 1 1 2 1 0 1\n",
                    {":3:", "spring 1", "mass 2 out of range 1..1"});
  expect_read_error("t.xs3", std::string(xs3).substr(0, 111), {"numm announces 3 masses"});
  expect_robust("chain.xs3", xs3);
}

// ---- writing ----

NetworkFile awkward_network() {
  const Grid grid;
  NetworkFile net = read_network_bytes("grid.vtu", encode(grid, {}));
  net.points(1, 0) = 0.1 + 0.2;
  net.stiffness(0) = 1.0 / 3.0;
  net.rest_length = Eigen::VectorXd::LinSpaced(7, 0.1, 0.7);
  net.bulk_modulus(0) = 1e300 / 7;
  return net;
}

TEST_F(NetworkFileTest, VtuRoundTripIsExact) {
  const NetworkFile net = awkward_network();
  write_network(dir_ / "out.vtu", net);
  expect_same(read_network(dir_ / "out.vtu"), net);
  NetworkFile bare = net;
  bare.damping.reset();
  bare.rest_length.reset();
  bare.mass.reset();
  bare.fixed.reset();
  write_network(dir_ / "bare.vtu", bare);
  expect_same(read_network(dir_ / "bare.vtu"), bare);
}

TEST_F(NetworkFileTest, XspRoundTripIsExact) {
  NetworkFile net = awkward_network();
  expect_error([&] { write_network(dir_ / "out.xs3", net); }, {"out.xs3", "tetrahedra"});
  net.tetrahedra.resize(0, 4);
  net.bulk_modulus.resize(0);
  net.triangles.resize(0, 3);
  net.spring_group.setZero();
  net.group_names = {"springs"};
  net.gravity << 0, 0, -9.81;
  net.viscosity = 0.01;
  write_network(dir_ / "out.xs3", net);
  expect_same(read_network(dir_ / "out.xs3"), net);
}

TEST_F(NetworkFileTest, CoefficientsVtuKeepOtherArraysAndOrder) {
  const Grid grid;
  for (Mode mode : {Mode::ascii, Mode::appended_raw, Mode::binary}) {
    const std::string original = encode(grid, {mode, mode != Mode::ascii, true});
    const fs::path in = write("in.vtu", original), out = dir_ / "out.vtu";
    const NetworkFile before = read_network(in);
    const Eigen::VectorXd k = Eigen::VectorXd::LinSpaced(7, 1.5, 7.5);
    const Eigen::VectorXd c = Eigen::VectorXd::Constant(7, 0.125);
    write_network_with_coefficients(in, out, k, c);
    NetworkFile after = read_network(out);
    EXPECT_TRUE(same(after.stiffness, k));  // Float32 holds these exactly
    EXPECT_TRUE(same(*after.damping, c));
    after.stiffness = before.stiffness;
    after.damping = before.damping;
    expect_same(after, before);
    // Everything outside the two arrays is byte for byte the original, appended data included.
    const std::string text = slurp(out);
    const std::size_t head = original.find("<DataArray type=\"Float32\" Name=\"stiffness\"");
    EXPECT_EQ(text.substr(0, head), original.substr(0, head));
    const std::size_t tail = original.find("Name=\"group\"");
    EXPECT_EQ(text.substr(text.find("Name=\"group\"")), original.substr(tail));
  }
  // A file without damping gets a damping array beside stiffness.
  Grid undamped;
  undamped.cell.erase(undamped.cell.begin() + 1);
  const fs::path in = write("undamped.vtu", encode(undamped, {Mode::appended_base64, true}));
  write_network_with_coefficients(in, dir_ / "damped.vtu", Eigen::VectorXd::Constant(7, 2),
                                  Eigen::VectorXd::Constant(7, 0.5));
  EXPECT_TRUE(same(*read_network(dir_ / "damped.vtu").damping, Eigen::VectorXd::Constant(7, 0.5)));
}

TEST_F(NetworkFileTest, CoefficientsLegacyAndXspInPlace) {
  const fs::path vtk =
      write("in.vtk",
            "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n"
            "0 0 0 1 0 0 1 1 0\nCELLS 2 6\n2 0 1\n2 1 2\nCELL_TYPES 2\n3 3\nCELL_DATA 2\n"
            "SCALARS stiffness float 1\nLOOKUP_TABLE default\n5 6\nSCALARS group int 1\n"
            "LOOKUP_TABLE default\n4 9\n");
  write_network_with_coefficients(vtk, dir_ / "out.vtk", Eigen::Vector2d(0.5, 8), std::nullopt);
  const std::string text = slurp(dir_ / "out.vtk");
  EXPECT_NE(text.find("LOOKUP_TABLE default\n0.5 8\nSCALARS group"), std::string::npos) << text;
  write_network_with_coefficients(vtk, dir_ / "damped.vtk", Eigen::Vector2d(1, 2),
                                  Eigen::Vector2d(0.25, 0));
  const NetworkFile damped = read_network(dir_ / "damped.vtk");
  EXPECT_TRUE(same(*damped.damping, Eigen::Vector2d(0.25, 0)));
  EXPECT_EQ(damped.group_names, (std::vector<std::string>{"group_4", "group_9"}));

  const fs::path xsp = write("in.xs3", xs3);
  write_network_with_coefficients(xsp, dir_ / "out.xs3", Eigen::Vector2d(30, 40),
                                  Eigen::Vector2d(3, 4));
  const std::string rewritten = slurp(dir_ / "out.xs3");
  EXPECT_NE(rewritten.find("lspg 1 1 2 60 6 -1\nlspg 2 2 3 40 4 0.75"), std::string::npos)
      << rewritten;
  EXPECT_EQ(rewritten.substr(0, rewritten.find("lspg")),
            std::string(xs3).substr(0, rewritten.find("lspg")));
  const auto negative = [&] {
    write_network_with_coefficients(xsp, dir_ / "bad.xs3", Eigen::Vector2d(30, -1), std::nullopt);
  };
  expect_error(negative, {"in.xs3", "line 11 (spring 2)", "new stiffness -1"});
}

// ---- one test per bad-input class: the message names the file and the element ----

std::string ascii_grid(const std::function<void(Grid&)>& change) {
  Grid grid;
  change(grid);
  return encode(grid, {});
}

Array& cell_array(Grid& g, const std::string& name) {
  return *std::find_if(g.cell.begin(), g.cell.end(),
                       [&](const Array& a) { return a.name == name; });
}

TEST(NetworkFile, RefusesPointIdOutOfRange) {
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { g.connectivity.values[3] = 5; }),
                    {"cell 1 (spring 1)", "point id 5 out of range"});
}

TEST(NetworkFile, RefusesZeroLengthSprings) {
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { g.connectivity.values[1] = 0; }),
                    {"cell 0 (spring 0)", "zero-length spring", "point 0"});
  expect_read_error("net.vtu", ascii_grid([](Grid& g) {
                      for (int k = 0; k < 3; ++k)
                        g.points.values[3 + k] = g.points.values[6 + k];
                    }),
                    {"cell 1 (spring 1)", "zero-length", "point 1 and point 2 are both at"});
}

TEST(NetworkFile, RefusesBadCoefficients) {
  const auto with = [](const char* name, std::size_t cell, double value) {
    return ascii_grid([=](Grid& g) { cell_array(g, name).values[cell] = value; });
  };
  expect_read_error("net.vtu", with("stiffness", 6, -3),
                    {"cell 6 (spring 4)", "stiffness -3 N/m must be finite and > 0"});
  expect_read_error("net.vtu", with("stiffness", 0, NAN), {"cell 0 (spring 0)", "stiffness nan"});
  expect_read_error("net.vtu", with("damping", 1, -0.5), {"cell 1 (spring 1)", "damping -0.5"});
  expect_read_error("net.vtu", with("bulk_modulus", 5, 0),
                    {"cell 5 (tetrahedron 0)", "bulk_modulus 0 Pa"});
  expect_read_error("net.vtu", ascii_grid([](Grid& g) {
                      g.cell.push_back({"rest_length", "Float64", 1, {1, 1, 1, 0, 1, 1, 1, 1, 1}});
                    }),
                    {"cell 3 (spring 2)", "rest_length 0 m"});
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { g.point[0].values[2] = 0; }),
                    {"point 2", "mass 0 kg must be finite and > 0"});
  expect_read_error("m.xs3",
                    "Xsp 3.0\nmass 1 s 0 0 0 0 0 0 1 0\nmass 2 s 1 0 0 0 0 0 0 0\n"
                    "lspg 1 1 2 1 0 1\n",
                    {"line 3 (mass 2)", "mass 0 kg"});
}

TEST(NetworkFile, RefusesTetrahedraWithoutBulkModulus) {
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { g.cell.pop_back(); }),
                    {"tetrahedra need cell data bulk_modulus", "cell 5"});
}

TEST(NetworkFile, RefusesTriangleVertexInNoSpring) {
  // Point 4 is only on spring 6 (cell 8): retarget the triangle onto it, drop that spring.
  expect_read_error("net.vtu", ascii_grid([](Grid& g) {
                      g.connectivity.values[6] = 4;
                      g.connectivity.values[20] = 2;
                    }),
                    {"cell 2 (triangle 0)", "vertex point 4 is in no spring"});
}

TEST(NetworkFile, RefusesNonFiniteCoordinate) {
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { g.points.values[13] = INFINITY; }),
                    {"point 4", "not finite"});
}

TEST(NetworkFile, RefusesOtherCellTypesAndArraysByName) {
  expect_read_error("net.vtu", ascii_grid([](Grid& g) {
                      g.types.values[2] = 9;
                      g.connectivity.values.insert(g.connectivity.values.begin() + 7, 3);
                      for (std::size_t c = 2; c < 9; ++c)
                        ++g.offsets.values[c];
                    }),
                    {"cell 2", "type 9 (VTK_QUAD)"});
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { cell_array(g, "group").name = "foo"; }),
                    {"array 'foo' is not one msfem reads", "stiffness, damping, rest_length"});
  expect_read_error("net.vtk",
                    "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 "
                    "float\n0 0 0 1 0 0\nCELLS 1 3\n2 0 1\nCELL_TYPES 1\n3\nPOINT_DATA 2\n"
                    "VECTORS velocity float\n0 0 0 0 0 0\n",
                    {":12:", "VECTORS array 'velocity' is not one msfem reads"});
}

TEST(NetworkFile, RefusesTruncatedAndCorruptData) {
  const Grid grid;
  const std::string raw = encode(grid, {Mode::appended_raw, true});
  expect_read_error("net.vtu", raw.substr(0, raw.size() - 40), {"AppendedData has no end tag"});
  expect_read_error("net.vtu", encode(grid, {}).substr(0, 900), {"not well-formed XML"});
  std::string bad64 = encode(grid, {Mode::binary});
  bad64[bad64.find("format=\"binary\">") + 20] = '*';
  expect_read_error("net.vtu", bad64, {"bad base64"});
  // Flip a byte inside the first zlib block of the first appended array (group_names).
  std::string corrupt = raw;
  corrupt[corrupt.find(">\n   _") + 5 + 4 * 4 + 2] ^= 0x55;
  expect_read_error("net.vtu", corrupt, {"field data 'group_names'", "corrupt zlib block 0"});
  expect_read_error("net.vtu", ascii_grid([](Grid& g) { g.points.values.pop_back(); }),
                    {"Points", "14 values, expected 15"});
  std::string huge = encode(grid, {});
  huge.replace(huge.find("NumberOfPoints=\"5\""), 18, "NumberOfPoints=\"999999999999\"");
  expect_read_error("net.vtu", huge,
                    {"NumberOfPoints 999999999999 is more than the file can hold"});
  const std::string legacy = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  expect_read_error("net.vtk", legacy + "POINTS 100000000 double\n",
                    {":5:", "point count 100000000 is more than the file can hold"});
  expect_read_error("net.vtk", legacy + "POINTS 2 double\n" + std::string(10, '\0'),
                    {":5:", "POINTS: the file ends before its 6 values (truncated)"});
}

TEST(NetworkFile, SurvivesEveryTruncationAndCorruption) {
  const Grid grid;
  for (Mode mode : {Mode::ascii, Mode::binary, Mode::appended_raw, Mode::appended_base64})
    expect_robust("net.vtu", encode(grid, {mode, mode != Mode::ascii, mode == Mode::binary}));
}

}  // namespace
}  // namespace msfem::cases
