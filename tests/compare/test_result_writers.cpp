#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/writers/fields_h5.hpp"
#include "msfem/compare/writers/vtu.hpp"

namespace msfem::compare {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class ResultWriters : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device random;
    dir_ = fs::temp_directory_path() / ("msfem_writers_" + std::to_string(random()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;

  std::vector<std::string> files_in_dir() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A unit octahedron scaled to millimetres: a closed surface of 6 vertices and 8 triangles.
Eigen::MatrixX3d octahedron_points() {
  Eigen::MatrixX3d p(6, 3);
  p << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  return p * 1e-3;
}
Eigen::MatrixX3i octahedron_triangles() {
  Eigen::MatrixX3i t(8, 3);
  t << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return t;
}
// Values that do not print exactly in fewer than 17 digits.
Eigen::MatrixX3d awkward_field(Eigen::Index rows, double scale) {
  Eigen::MatrixX3d f(rows, 3);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (int c = 0; c < 3; ++c)
      f(r, c) = scale * std::sin(1.0 + r * 3 + c) / 3.0;
  return f;
}

// ---- a minimal reading of VTK XML, enough to check what a reader would see ----

std::string attribute(const std::string& tag, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const auto start = tag.find(key);
  if (start == std::string::npos) return "";
  const auto begin = start + key.size();
  return tag.substr(begin, tag.find('"', begin) - begin);
}

// The opening tag (from '<' to '>') of the first element called `element`.
std::string first_tag(const std::string& xml, const std::string& element) {
  const auto start = xml.find("<" + element + " ");
  if (start == std::string::npos) return "";
  return xml.substr(start, xml.find('>', start) - start + 1);
}

struct DataArray {
  std::string tag;
  std::vector<double> values;
};

std::map<std::string, DataArray> data_arrays_by_name(const std::string& xml) {
  std::map<std::string, DataArray> arrays;
  for (auto start = xml.find("<DataArray "); start != std::string::npos;
       start = xml.find("<DataArray ", start + 1)) {
    const auto tag_end = xml.find('>', start);
    const auto end = xml.find("</DataArray>", tag_end);
    DataArray a;
    a.tag = xml.substr(start, tag_end - start + 1);
    std::istringstream numbers(xml.substr(tag_end + 1, end - tag_end - 1));
    for (double v; numbers >> v;)
      a.values.push_back(v);
    arrays[attribute(a.tag, "Name")] = a;
  }
  return arrays;
}

// Row-major values of a matrix, the order VTK and HDF5 store them in.
template <typename Matrix>
std::vector<double> row_major(const Matrix& m) {
  std::vector<double> v;
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      v.push_back(static_cast<double>(m(r, c)));
  return v;
}

void expect_close(const std::vector<double>& actual, const std::vector<double>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i)
    EXPECT_LE(std::abs(actual[i] - expected[i]),
              1e-15 * std::max(std::abs(actual[i]), std::abs(expected[i])))
        << "value " << i << ": " << actual[i] << " vs " << expected[i];
}

TEST_F(ResultWriters, SurfaceVtuReadsBackWithEveryDigit) {
  const Eigen::MatrixX3d points = octahedron_points();
  const Eigen::MatrixX3i triangles = octahedron_triangles();
  const Eigen::MatrixX3d displacement = awkward_field(6, 1e-4);
  const Eigen::VectorXd magnitude = displacement.rowwise().norm();
  const fs::path file = dir_ / "surface.vtu";
  write_surface_vtu(file, points, triangles,
                    {{"displacement", displacement}, {"error_magnitude", magnitude}});

  const std::string xml = read_text(file);
  EXPECT_EQ(xml.rfind("<?xml", 0), 0u);
  EXPECT_EQ(attribute(first_tag(xml, "VTKFile"), "type"), "UnstructuredGrid");
  const std::string piece = first_tag(xml, "Piece");
  EXPECT_EQ(attribute(piece, "NumberOfPoints"), "6");
  EXPECT_EQ(attribute(piece, "NumberOfCells"), "8");
  EXPECT_EQ(attribute(first_tag(xml, "PointData"), "Vectors"), "displacement");
  EXPECT_EQ(attribute(first_tag(xml, "PointData"), "Scalars"), "error_magnitude");

  auto arrays = data_arrays_by_name(xml);
  ASSERT_EQ(arrays.size(), 6u);  // two fields, Points, connectivity, offsets, types
  EXPECT_EQ(attribute(arrays["Points"].tag, "NumberOfComponents"), "3");
  expect_close(arrays["Points"].values, row_major(points));
  EXPECT_EQ(attribute(arrays["displacement"].tag, "NumberOfComponents"), "3");
  EXPECT_EQ(attribute(arrays["displacement"].tag, "format"), "ascii");
  expect_close(arrays["displacement"].values, row_major(displacement));
  EXPECT_EQ(attribute(arrays["error_magnitude"].tag, "NumberOfComponents"), "1");
  expect_close(arrays["error_magnitude"].values, row_major(magnitude));
  EXPECT_EQ(arrays["connectivity"].values, row_major(triangles));
  EXPECT_EQ(arrays["offsets"].values, (std::vector<double>{3, 6, 9, 12, 15, 18, 21, 24}));
  EXPECT_EQ(arrays["types"].values, std::vector<double>(8, 5.0));  // VTK_TRIANGLE
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"surface.vtu"});
}

TEST_F(ResultWriters, VolumeVtuHoldsTetrahedra) {
  Eigen::MatrixX3d points(5, 3);
  points << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
  Eigen::MatrixX4i tets(2, 4);
  tets << 0, 1, 2, 3, 1, 2, 3, 4;
  const Eigen::MatrixX3d displacement = awkward_field(5, 1e-3);
  const fs::path file = dir_ / "fem.vtu";
  write_volume_vtu(file, points, tets, {{"displacement", displacement}});
  const std::string xml = read_text(file);
  EXPECT_EQ(attribute(first_tag(xml, "Piece"), "NumberOfCells"), "2");
  auto arrays = data_arrays_by_name(xml);
  EXPECT_EQ(arrays["connectivity"].values, row_major(tets));
  EXPECT_EQ(arrays["offsets"].values, (std::vector<double>{4, 8}));
  EXPECT_EQ(arrays["types"].values, (std::vector<double>{10, 10}));  // VTK_TETRA
  expect_close(arrays["displacement"].values, row_major(displacement));
}

TEST_F(ResultWriters, VtuRefusesWhatParaViewCouldNotRead) {
  const Eigen::MatrixX3d points = octahedron_points();
  Eigen::MatrixX3i bad_triangles = octahedron_triangles();
  bad_triangles(3, 1) = 6;
  const fs::path file = dir_ / "surface.vtu";
  EXPECT_THROW(write_surface_vtu(file, points, bad_triangles, {}), std::invalid_argument);
  const auto triangles = octahedron_triangles();
  EXPECT_THROW(write_surface_vtu(file, points, triangles, {{"short", Eigen::MatrixXd::Zero(5, 3)}}),
               std::invalid_argument);
  EXPECT_THROW(write_surface_vtu(file, points, triangles, {{"two", Eigen::MatrixXd::Zero(6, 2)}}),
               std::invalid_argument);
  Eigen::MatrixXd with_nan = Eigen::MatrixXd::Zero(6, 1);
  with_nan(2, 0) = std::nan("");
  try {
    write_surface_vtu(file, points, triangles, {{"error", with_nan}});
    ADD_FAILURE() << "a NaN was written";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'error'"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(files_in_dir().empty());
}

TEST_F(ResultWriters, PvdListsTheFilesRelativeToItself) {
  const fs::path file = dir_ / "result.pvd";
  write_pvd(file, {{"surface.vtu", "surface"}, {"fem.vtu", "FEM & tool"}});
  const std::string xml = read_text(file);
  EXPECT_EQ(attribute(first_tag(xml, "VTKFile"), "type"), "Collection");
  std::vector<std::string> datasets;
  for (auto at = xml.find("<DataSet "); at != std::string::npos; at = xml.find("<DataSet ", at + 1))
    datasets.push_back(xml.substr(at, xml.find("/>", at) - at + 2));
  ASSERT_EQ(datasets.size(), 2u);
  EXPECT_EQ(attribute(datasets[0], "file"), "surface.vtu");
  EXPECT_EQ(attribute(datasets[0], "part"), "0");
  EXPECT_EQ(attribute(datasets[0], "timestep"), "0");
  EXPECT_EQ(attribute(datasets[0], "name"), "surface");
  EXPECT_EQ(attribute(datasets[1], "file"), "fem.vtu");
  EXPECT_EQ(attribute(datasets[1], "part"), "1");
  EXPECT_EQ(attribute(datasets[1], "name"), "FEM &amp; tool");  // escaped: still well-formed XML
  EXPECT_THROW(write_pvd(dir_ / "abs.pvd", {{"/tmp/surface.vtu", "s"}}), std::invalid_argument);
}

// ---- fields.h5 ----

struct Fields {
  Eigen::MatrixX3d surface_vertices = octahedron_points();
  Eigen::MatrixX3i surface_triangles = octahedron_triangles();
  FemField fem;
  std::vector<VariantField> variants;
};

// The octahedron filled with 8 tetrahedra around its centre (vertex 6), and two variants.
Fields example_fields() {
  Fields f;
  f.fem.vertices.resize(7, 3);
  f.fem.vertices << f.surface_vertices, Eigen::RowVector3d::Zero();
  f.fem.tetrahedra.resize(8, 4);
  f.fem.tetrahedra << f.surface_triangles, Eigen::VectorXi::Constant(8, 6);
  f.fem.displacement = awkward_field(7, 2e-4);
  const Eigen::MatrixX3d fem_surface = f.fem.displacement.topRows(6);
  for (const char* name : {"single_layer", "three_tier"}) {
    VariantField v;
    v.name = name;
    v.surface_displacement = fem_surface + awkward_field(6, v.name.size() * 1e-6);
    v.error = v.surface_displacement - fem_surface;
    f.variants.push_back(v);
  }
  return f;
}

void write(const fs::path& file, const Fields& f) {
  write_fields_h5(file, f.surface_vertices, f.surface_triangles, f.fem, f.variants);
}

TEST_F(ResultWriters, FieldsH5ReadsBackExactly) {
  const Fields f = example_fields();
  const fs::path file = dir_ / "fields.h5";
  write(file, f);
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"fields.h5"});

  const Eigen::MatrixXd vertices = read_h5_matrix(file, "/surface/vertices");
  ASSERT_EQ(vertices.rows(), 6);
  ASSERT_EQ(vertices.cols(), 3);
  EXPECT_EQ(vertices, Eigen::MatrixXd(f.surface_vertices));
  EXPECT_EQ(read_h5_matrix(file, "/surface/triangles"),
            Eigen::MatrixXd(f.surface_triangles.cast<double>()));
  EXPECT_EQ(read_h5_matrix(file, "/fem/vertices"), Eigen::MatrixXd(f.fem.vertices));
  EXPECT_EQ(read_h5_matrix(file, "/fem/tetrahedra"),
            Eigen::MatrixXd(f.fem.tetrahedra.cast<double>()));
  EXPECT_EQ(read_h5_matrix(file, "/fem/displacement"), Eigen::MatrixXd(f.fem.displacement));
  for (const VariantField& v : f.variants) {
    const std::string group = "/variants/" + v.name;
    EXPECT_EQ(read_h5_matrix(file, group + "/displacement"),
              Eigen::MatrixXd(v.surface_displacement));
    EXPECT_EQ(read_h5_matrix(file, group + "/error"), Eigen::MatrixXd(v.error));
    const Eigen::MatrixXd magnitude = read_h5_matrix(file, group + "/error_magnitude");
    ASSERT_EQ(magnitude.cols(), 1);  // a rank-1 dataset
    EXPECT_EQ(magnitude, Eigen::MatrixXd(v.error.rowwise().norm()));
  }
  for (const char* length : {"/surface/vertices", "/fem/vertices", "/fem/displacement",
                             "/variants/three_tier/displacement", "/variants/three_tier/error",
                             "/variants/three_tier/error_magnitude"})
    EXPECT_EQ(read_h5_string_attribute(file, length, "units"), "m") << length;
}

// Independent of our reader: HDF5 stores a small contiguous dataset as its raw bytes, so the
// row-major little-endian doubles must appear in the file as they are.
TEST_F(ResultWriters, FieldsH5StoresRowsContiguously) {
  const Fields f = example_fields();
  const fs::path file = dir_ / "fields.h5";
  write(file, f);
  const std::string bytes = read_text(file);
  EXPECT_EQ(bytes.substr(0, 8), "\x89HDF\r\n\x1a\n");
  for (const Eigen::MatrixXd& m :
       {Eigen::MatrixXd(f.surface_vertices), Eigen::MatrixXd(f.fem.displacement),
        Eigen::MatrixXd(f.variants[1].error)}) {
    const std::vector<double> values = row_major(m);
    std::string expected(values.size() * sizeof(double), '\0');
    std::memcpy(expected.data(), values.data(), expected.size());
    EXPECT_NE(bytes.find(expected), std::string::npos);
  }
}

TEST_F(ResultWriters, FieldsH5WithoutVariants) {
  Fields f = example_fields();
  f.variants.clear();
  const fs::path file = dir_ / "fields.h5";
  write(file, f);
  EXPECT_EQ(read_h5_matrix(file, "/fem/displacement"), Eigen::MatrixXd(f.fem.displacement));
  EXPECT_THROW(read_h5_matrix(file, "/variants/three_tier/error"), std::runtime_error);
}

TEST_F(ResultWriters, FieldsH5RefusesInconsistentInput) {
  const fs::path file = dir_ / "fields.h5";
  Fields short_error = example_fields();
  short_error.variants[0].error.conservativeResize(5, 3);
  EXPECT_THROW(write(file, short_error), std::invalid_argument);
  Fields bad_tet = example_fields();
  bad_tet.fem.tetrahedra(0, 0) = 7;
  EXPECT_THROW(write(file, bad_tet), std::invalid_argument);
  Fields nested = example_fields();
  nested.variants[0].name = "a/b";
  EXPECT_THROW(write(file, nested), std::invalid_argument);
  Fields twice = example_fields();
  twice.variants[1].name = twice.variants[0].name;
  EXPECT_THROW(write(file, twice), std::invalid_argument);
  EXPECT_TRUE(files_in_dir().empty());
}

TEST_F(ResultWriters, ReadingNamesTheFileAndDataset) {
  const fs::path file = dir_ / "fields.h5";
  write(file, example_fields());
  try {
    read_h5_matrix(file, "/fem/pressure");
    ADD_FAILURE() << "a missing dataset was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/fem/pressure"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_h5_matrix(dir_ / "missing.h5", "/fem/vertices"), std::runtime_error);
  write_text_atomically(dir_ / "not.h5", "plain text");
  EXPECT_THROW(read_h5_matrix(dir_ / "not.h5", "/fem/vertices"), std::runtime_error);
  EXPECT_THROW(read_h5_string_attribute(file, "/surface/triangles", "units"), std::runtime_error);
}

TEST_F(ResultWriters, FieldsH5ReplacesAnEarlierRun) {
  const fs::path file = dir_ / "fields.h5";
  Fields first = example_fields();
  write(file, first);
  Fields second = example_fields();
  second.fem.displacement *= 2;
  write(file, second);
  EXPECT_EQ(read_h5_matrix(file, "/fem/displacement"), Eigen::MatrixXd(second.fem.displacement));
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"fields.h5"});
}

// ---- atomic writing ----

TEST_F(ResultWriters, FailedWriteLeavesNoFile) {
  const fs::path file = dir_ / "summary.json";
  try {
    write_file_atomically(file, [](const fs::path& temporary) {
      std::ofstream(temporary) << "{\"half\": ";
      throw std::runtime_error("disk full");
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("disk full"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(files_in_dir().empty());  // neither the target nor a .tmp
}

TEST_F(ResultWriters, ExistingFileIsReplacedOnlyOnSuccess) {
  const fs::path file = dir_ / "report.md";
  write_text_atomically(file, "old");
  EXPECT_THROW(write_file_atomically(file,
                                     [](const fs::path& temporary) {
                                       std::ofstream(temporary) << "new but broken";
                                       throw std::logic_error("writer bug");
                                     }),
               std::runtime_error);
  EXPECT_EQ(read_text(file), "old");
  EXPECT_THROW(write_file_atomically(file, [](const fs::path&) {}), std::runtime_error);
  EXPECT_EQ(read_text(file), "old");  // a writer that wrote nothing replaces nothing
  write_text_atomically(file, "new");
  EXPECT_EQ(read_text(file), "new");
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"report.md"});
}

TEST_F(ResultWriters, TemporaryIsBesideTheTarget) {
  const fs::path file = dir_ / "plot.png";
  fs::path seen;
  write_file_atomically(file, [&](const fs::path& temporary) {
    seen = temporary;
    std::ofstream(temporary) << "x";
  });
  EXPECT_EQ(seen.parent_path(), dir_);
  EXPECT_EQ(seen.filename().string().rfind("plot.png.tmp.", 0), 0u) << seen;
}

TEST_F(ResultWriters, NonStandardExceptionPassesThroughAndCleansUp) {
  EXPECT_THROW(write_file_atomically(dir_ / "a.txt",
                                     [](const fs::path& temporary) {
                                       std::ofstream(temporary) << "x";
                                       throw 42;
                                     }),
               int);
  EXPECT_TRUE(files_in_dir().empty());
}

TEST_F(ResultWriters, MissingFolderIsAnErrorNamingTheFile) {
  const fs::path file = dir_ / "no" / "such" / "surface.vtu";
  try {
    write_text_atomically(file, "x");
    ADD_FAILURE() << "wrote into a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace msfem::compare
