// fields.h5: every field of a comparison run in one HDF5 file, for scripts (h5py, MATLAB, h5dump)
// and for `msfem regress`. The HDF5 library is deal.II's OpenMPI build (one HDF5 per process), used
// serially: default property lists, no MPI-IO driver.

// OpenMPI's hdf5.h includes <mpi.h>: compare/CMakeLists.txt puts MPI on the include path.
#include <hdf5.h>

#include <cstdint>
#include <set>
#include <stdexcept>

#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/writers/fields_h5.hpp"

namespace msfem::compare {

namespace fs = std::filesystem;

namespace {

using RowMajorDoubles = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMajorInt32s = Eigen::Matrix<std::int32_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// HDF5 prints its error stack to stderr by default; we report failures as exceptions instead, with
// the innermost message of that stack. The previous handler comes back when the guard goes.
class SilenceHdf5Errors {
 public:
  SilenceHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &previous_function_, &previous_data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~SilenceHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, previous_function_, previous_data_); }
  SilenceHdf5Errors(const SilenceHdf5Errors&) = delete;
  SilenceHdf5Errors& operator=(const SilenceHdf5Errors&) = delete;

 private:
  H5E_auto2_t previous_function_ = nullptr;
  void* previous_data_ = nullptr;
};

// The description of the innermost entry of HDF5's error stack (the root cause), or "".
std::string hdf5_error_message() {
  std::string message;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned, const H5E_error2_t* error, void* data) -> herr_t {
        auto* text = static_cast<std::string*>(data);
        if (text->empty() && error->desc != nullptr) *text = error->desc;
        return 0;
      },
      &message);
  return message;
}

[[noreturn]] void fail(const fs::path& file, const std::string& object, const std::string& what) {
  const std::string cause = hdf5_error_message();
  throw std::runtime_error("HDF5 file '" + file.string() + "', '" + object + "': " + what +
                           (cause.empty() ? "" : " (" + cause + ")"));
}

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now and reports whether it worked: closing a file is when HDF5 flushes it.
  bool close() {
    const herr_t status = id_ >= 0 ? close_(id_) : 0;
    id_ = -1;
    return status >= 0;
  }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Writes into one open file, naming the file and dataset in any error.
class FieldsWriter {
 public:
  FieldsWriter(const fs::path& reported_path, hid_t file) : path_(reported_path), file_(file) {}

  void group(const std::string& name) {
    Handle g(H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!g.valid()) fail(path_, name, "cannot create group");
  }

  void doubles(const std::string& name, const Eigen::MatrixXd& values, bool as_vector,
               const char* units) {
    const RowMajorDoubles row_major = values;  // HDF5 is row-major, Eigen column-major
    const hsize_t dims[2] = {static_cast<hsize_t>(values.rows()),
                             static_cast<hsize_t>(values.cols())};
    write(name, dims, as_vector ? 1 : 2, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, row_major.data());
    if (units != nullptr) string_attribute(name, "units", units);
  }

  void indices(const std::string& name, const Eigen::MatrixXi& values, const char* refers_to) {
    const RowMajorInt32s row_major = values.cast<std::int32_t>();
    const hsize_t dims[2] = {static_cast<hsize_t>(values.rows()),
                             static_cast<hsize_t>(values.cols())};
    write(name, dims, 2, H5T_STD_I32LE, H5T_NATIVE_INT32, row_major.data());
    string_attribute(name, "indexes", refers_to);
  }

 private:
  void write(const std::string& name, const hsize_t* dims, int rank, hid_t file_type,
             hid_t memory_type, const void* data) {
    Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
    if (!space.valid()) fail(path_, name, "cannot create dataspace");
    Handle set(H5Dcreate2(file_, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                          H5P_DEFAULT),
               H5Dclose);
    if (!set.valid()) fail(path_, name, "cannot create dataset");
    if (H5Dwrite(set.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
      fail(path_, name, "cannot write dataset");
    if (!set.close()) fail(path_, name, "cannot close dataset");
  }

  // A fixed-length, NUL-terminated ASCII string: what h5dump, h5py and MATLAB all read plainly.
  void string_attribute(const std::string& object, const char* name, const std::string& value) {
    const std::string where = object + "@" + name;
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (!type.valid() || H5Tset_size(type.get(), value.size() + 1) < 0 ||
        H5Tset_strpad(type.get(), H5T_STR_NULLTERM) < 0)
      fail(path_, where, "cannot make string type");
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attribute(H5Acreate_by_name(file_, object.c_str(), name, type.get(), space.get(),
                                       H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose);
    if (!space.valid() || !attribute.valid()) fail(path_, where, "cannot create attribute");
    if (H5Awrite(attribute.get(), type.get(), value.c_str()) < 0)
      fail(path_, where, "cannot write attribute");
  }

  fs::path path_;
  hid_t file_;
};

void require_rows(const std::string& what, Eigen::Index rows, Eigen::Index expected) {
  if (rows != expected)
    throw std::invalid_argument(what + " has " + std::to_string(rows) + " rows, expected " +
                                std::to_string(expected));
}

void require_indices_below(const std::string& what, const Eigen::MatrixXi& cells,
                           Eigen::Index vertex_count) {
  for (Eigen::Index c = 0; c < cells.rows(); ++c)
    for (Eigen::Index k = 0; k < cells.cols(); ++k)
      if (cells(c, k) < 0 || cells(c, k) >= vertex_count)
        throw std::invalid_argument(what + " row " + std::to_string(c) + " refers to vertex " +
                                    std::to_string(cells(c, k)) + " of " +
                                    std::to_string(vertex_count));
}

void check_fields(const Eigen::MatrixX3d& surface_vertices,
                  const Eigen::MatrixX3i& surface_triangles, const FemField& fem,
                  const std::vector<VariantField>& variants) {
  require_indices_below("/surface/triangles", surface_triangles, surface_vertices.rows());
  require_indices_below("/fem/tetrahedra", fem.tetrahedra, fem.vertices.rows());
  require_rows("/fem/displacement", fem.displacement.rows(), fem.vertices.rows());
  std::set<std::string> names;
  for (const VariantField& variant : variants) {
    // The name becomes an HDF5 path component: '/' would nest groups, '.' is the group itself.
    if (variant.name.empty() || variant.name == "." || variant.name.find('/') != std::string::npos)
      throw std::invalid_argument("variant name '" + variant.name +
                                  "' cannot name an HDF5 group (empty, '.' or holds '/')");
    if (!names.insert(variant.name).second)
      throw std::invalid_argument("variant '" + variant.name + "' appears twice");
    const std::string group = "/variants/" + variant.name;
    require_rows(group + "/displacement", variant.surface_displacement.rows(),
                 surface_vertices.rows());
    require_rows(group + "/error", variant.error.rows(), surface_vertices.rows());
  }
}

void write_fields(FieldsWriter& out, const Eigen::MatrixX3d& surface_vertices,
                  const Eigen::MatrixX3i& surface_triangles, const FemField& fem,
                  const std::vector<VariantField>& variants) {
  out.group("/surface");
  out.doubles("/surface/vertices", surface_vertices, false, "m");
  out.indices("/surface/triangles", surface_triangles, "/surface/vertices rows, 0-based");
  out.group("/fem");
  out.doubles("/fem/vertices", fem.vertices, false, "m");
  out.indices("/fem/tetrahedra", fem.tetrahedra, "/fem/vertices rows, 0-based");
  out.doubles("/fem/displacement", fem.displacement, false, "m");
  out.group("/variants");
  for (const VariantField& variant : variants) {
    const std::string group = "/variants/" + variant.name;
    out.group(group);
    out.doubles(group + "/displacement", variant.surface_displacement, false, "m");
    out.doubles(group + "/error", variant.error, false, "m");
    out.doubles(group + "/error_magnitude", variant.error.rowwise().norm(), true, "m");
  }
}

}  // namespace

void write_fields_h5(const fs::path& path, const Eigen::MatrixX3d& surface_vertices,
                     const Eigen::MatrixX3i& surface_triangles, const FemField& fem,
                     const std::vector<VariantField>& variants) {
  check_fields(surface_vertices, surface_triangles, fem, variants);
  write_file_atomically(path, [&](const fs::path& temporary) {
    SilenceHdf5Errors silence;
    Handle file(H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (!file.valid()) fail(path, "/", "cannot create file");
    FieldsWriter out(path, file.get());
    write_fields(out, surface_vertices, surface_triangles, fem, variants);
    if (!file.close()) fail(path, "/", "cannot close (flush) file");
  });
}

namespace {

Handle open_for_reading(const fs::path& path) {
  if (!fs::is_regular_file(path))
    throw std::runtime_error("HDF5 file '" + path.string() + "' does not exist");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) fail(path, "/", "cannot open as HDF5");
  return file;
}

}  // namespace

Eigen::MatrixXd read_h5_matrix(const fs::path& path, const std::string& dataset) {
  SilenceHdf5Errors silence;
  Handle file = open_for_reading(path);
  Handle set(H5Dopen2(file.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) fail(path, dataset, "no such dataset");
  Handle space(H5Dget_space(set.get()), H5Sclose);
  const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
  if (rank < 0 || rank > 2) fail(path, dataset, "not a scalar, vector or matrix");
  hsize_t dims[2] = {1, 1};
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims, nullptr) < 0)
    fail(path, dataset, "cannot read the dimensions");
  RowMajorDoubles values(static_cast<Eigen::Index>(dims[0]),
                         static_cast<Eigen::Index>(rank == 2 ? dims[1] : 1));
  // HDF5 converts integer datasets to double on reading.
  if (H5Dread(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
    fail(path, dataset, "cannot read as double");
  return values;
}

std::string read_h5_string_attribute(const fs::path& path, const std::string& object,
                                     const std::string& attribute) {
  SilenceHdf5Errors silence;
  const std::string where = object + "@" + attribute;
  Handle file = open_for_reading(path);
  Handle handle(
      H5Aopen_by_name(file.get(), object.c_str(), attribute.c_str(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose);
  if (!handle.valid()) fail(path, where, "no such attribute");
  Handle type(H5Aget_type(handle.get()), H5Tclose);
  if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING)
    fail(path, where, "not a string attribute");
  const htri_t variable = H5Tis_variable_str(type.get());
  if (variable < 0) fail(path, where, "cannot read the string type");
  if (variable > 0) {
    char* text = nullptr;
    if (H5Aread(handle.get(), type.get(), &text) < 0) fail(path, where, "cannot read");
    std::string value = text != nullptr ? text : "";
    H5free_memory(text);
    return value;
  }
  const std::size_t size = H5Tget_size(type.get());
  std::string buffer(size, '\0');
  if (H5Aread(handle.get(), type.get(), buffer.data()) < 0) fail(path, where, "cannot read");
  return buffer.substr(0, buffer.find('\0'));  // NUL-terminated or NUL-padded
}

}  // namespace msfem::compare
