// NIfTI-1/2 input. niftilib, the format's reference implementation, turns the header into the
// voxel-to-world transform (the qform from its quaternion as the standard says). The bytes are read
// and every header field used is checked here first, because niftilib quietly mends what a broken
// file gets wrong: a zero, negative or NaN voxel size becomes 1, a NaN scale factor or offset 0,
// NaN and infinite voxels 0, a negative vox_offset reads the last bytes of the file. Each of those
// would give a surface or a modulus at the wrong place or scale with nothing said.
#include <nifti2_io.h>
#include <zlib.h>

#include <Eigen/LU>
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "msfem/cases/errors.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases::detail {
namespace {

static_assert(sizeof(nifti_1_header) == 348 && sizeof(nifti_2_header) == 540);

// Bounds far beyond any scan of an organ: past them the header is corrupt, and the arithmetic
// downstream (meshing, squared lengths, CGAL's predicates) would lose the surface.
constexpr std::int64_t max_voxels = std::int64_t{1} << 30;
constexpr double min_voxel_m = 1e-9, max_voxel_m = 1.0, max_offset_m = 1e6;

using NiftiPointer = std::unique_ptr<nifti_image, void (*)(nifti_image*)>;

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

[[noreturn]] void refuse_field(const std::string& name, const std::string& field, double value,
                               const std::string& why) {
  throw InputError(name + ": NIfTI header " + field + " = " + number(value) + " (" + why + ")");
}

// The decompressed bytes of the file (zlib reads plain files as they are), read only as far as
// asked, so that a header claiming gigabytes allocates no more than the file holds.
class FileBytes {
 public:
  explicit FileBytes(const std::string& name) : name_(name), file_(gzopen(name.c_str(), "rb")) {
    if (!file_) throw InputError(name + ": cannot open");
  }
  ~FileBytes() { gzclose(file_); }
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;

  // Reads until `bytes` are held or the file ends; returns how many are held.
  std::uint64_t read_to(std::uint64_t bytes) {
    char buffer[1 << 16];
    while (data_.size() < bytes && !ended_) {
      const auto want =
          static_cast<unsigned>(std::min<std::uint64_t>(bytes - data_.size(), sizeof buffer));
      const int got = gzread(file_, buffer, want);
      if (got < 0) {
        int code = 0;
        std::string why = gzerror(file_, &code);
        if (why.rfind(name_ + ": ", 0) == 0) why.erase(0, name_.size() + 2);
        throw InputError(name_ + ": corrupt gzip data (" + why + ")");
      }
      data_.append(buffer, static_cast<std::size_t>(got));
      ended_ = got == 0;
    }
    return data_.size();
  }
  const char* data() const { return data_.data(); }

 private:
  std::string name_;
  gzFile file_;
  std::string data_;
  bool ended_ = false;
};

template <typename T>
T load(const char* at, bool swap) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, at, sizeof(T));
  if (swap) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

struct Layout {
  int version = 0;  ///< 1 or 2
  bool swapped = false;
  int header_bytes = 0;  ///< 348 or 540; the data starts 4 bytes later at the earliest
};

Layout layout_of(const std::string& name, FileBytes& file) {
  const std::uint64_t held = file.read_to(540);
  if (held < 348) throw InputError(name + ": not a NIfTI-1 or NIfTI-2 image (.nii or .nii.gz)");
  Layout l;
  for (bool swap : {false, true}) {
    const auto size = load<std::int32_t>(file.data(), swap);
    if (size == 348 || size == 540) {
      l.swapped = swap;
      l.header_bytes = size;
      l.version = size == 348 ? 1 : 2;
    }
  }
  const char* magic = file.data() + (l.version == 2 ? 4 : 344);
  if (l.version == 0 || (l.version == 2 && held < 540) ||
      !(magic[0] == 'n' && (magic[1] == '+' || magic[1] == 'i') && magic[2] == '0' + l.version &&
        magic[3] == '\0'))
    throw InputError(name + ": not a NIfTI-1 or NIfTI-2 image (.nii or .nii.gz)");
  if (magic[1] == 'i')
    throw InputError(name + ": a two-file NIfTI header (its data in a separate .img); give a " +
                     "single-file .nii or .nii.gz");
  return l;
}

double metres_per_unit(int xyzt_units) {
  switch (xyzt_units & 0x07) {
    case NIFTI_UNITS_METER:
      return 1.0;
    case NIFTI_UNITS_MICRON:
      return 1e-6;
    default:
      return 1e-3;
  }
}

bool supported(int datatype) {
  for (int t : {NIFTI_TYPE_UINT8, NIFTI_TYPE_INT8, NIFTI_TYPE_INT16, NIFTI_TYPE_UINT16,
                NIFTI_TYPE_INT32, NIFTI_TYPE_UINT32, NIFTI_TYPE_INT64, NIFTI_TYPE_UINT64,
                NIFTI_TYPE_FLOAT32, NIFTI_TYPE_FLOAT64})
    if (datatype == t) return true;
  return false;
}

void check_finite(const std::string& name, const std::string& field,
                  std::initializer_list<double> values, const std::string& why) {
  int index = 0;
  for (double v : values) {
    if (!std::isfinite(v))
      refuse_field(name, values.size() > 1 ? field + "[" + std::to_string(index) + "]" : field, v,
                   why);
    ++index;
  }
}

// The voxel count; dimensions past the third must be 1 (one volume).
template <typename Header>
Grid check_dims(const std::string& name, const Header& h) {
  const std::int64_t rank = h.dim[0];
  if (rank < 1 || rank > 7) refuse_field(name, "dim[0]", double(rank), "must be 1 to 7");
  for (int d = 1; d <= rank; ++d)
    if (h.dim[d] < 1 || h.dim[d] > max_voxels)
      refuse_field(name, "dim[" + std::to_string(d) + "]", double(h.dim[d]),
                   "must be 1 to " + std::to_string(max_voxels));
  const auto size = [&](int d) { return d <= rank ? std::int64_t{h.dim[d]} : std::int64_t{1}; };
  if (size(1) < 2 || size(2) < 2 || size(3) < 2)
    throw InputError(name + ": a " + std::to_string(rank) +
                     "-D image; a volume needs at least 2 voxels along i, j and k");
  std::int64_t volumes = 1;
  for (int d = 4; d <= rank; ++d)
    volumes = std::min(volumes * size(d), max_voxels);
  if (volumes > 1)
    throw InputError(name + ": holds " + std::to_string(volumes) +
                     " volumes; give a single 3-D volume");
  if (size(1) * size(2) > max_voxels / size(3))
    throw InputError(name + ": NIfTI header dims " + std::to_string(size(1)) + " x " +
                     std::to_string(size(2)) + " x " + std::to_string(size(3)) +
                     " make more than " + std::to_string(max_voxels) + " voxels");
  Grid grid;
  grid.size = {long(size(1)), long(size(2)), long(size(3))};
  return grid;
}

// Every field the reader or niftilib's conversion uses, so that niftilib mends nothing.
template <typename Header>
void check_fields(const std::string& name, const Header& h) {
  if (!supported(h.datatype)) {
    const std::string type = nifti_datatype_is_valid(h.datatype, 0)
                                 ? nifti_datatype_string(h.datatype)
                                 : "not a NIfTI type";
    throw InputError(name + ": NIfTI header datatype = " + std::to_string(h.datatype) + " (" +
                     type + ") is not supported (integer or real scalars only)");
  }
  const int unit = h.xyzt_units & 0x07;
  if (unit > NIFTI_UNITS_MICRON)
    refuse_field(name, "xyzt_units", h.xyzt_units,
                 "spatial unit code " + std::to_string(unit) + " is none of 0-3");
  const double metres = metres_per_unit(h.xyzt_units);
  for (int d = 1; d <= 3; ++d) {
    const std::string field = "pixdim[" + std::to_string(d) + "]";
    if (!std::isfinite(h.pixdim[d]) || !(h.pixdim[d] > 0))
      refuse_field(name, field, h.pixdim[d], "voxel size must be finite and > 0");
    if (!(h.pixdim[d] * metres >= min_voxel_m && h.pixdim[d] * metres <= max_voxel_m))
      refuse_field(name, field, h.pixdim[d], "voxel size must be between 1 nm and 1 m");
  }
  check_finite(name, "scl_slope", {double(h.scl_slope)}, "must be finite");
  check_finite(name, "scl_inter", {double(h.scl_inter)}, "must be finite");
  for (const auto& [field, code] :
       {std::pair{"qform_code", int(h.qform_code)}, std::pair{"sform_code", int(h.sform_code)}})
    if (code < NIFTI_XFORM_UNKNOWN || code > NIFTI_XFORM_TEMPLATE_OTHER)
      refuse_field(name, field, code, "must be 0 to 5");
  if (h.qform_code > 0) {
    check_finite(name, "pixdim[0] (qfac)", {double(h.pixdim[0])}, "must be finite");
    check_finite(name, "quatern_b", {double(h.quatern_b)}, "the qform must be finite");
    check_finite(name, "quatern_c", {double(h.quatern_c)}, "the qform must be finite");
    check_finite(name, "quatern_d", {double(h.quatern_d)}, "the qform must be finite");
    check_finite(name, "qoffset_x", {double(h.qoffset_x)}, "the qform must be finite");
    check_finite(name, "qoffset_y", {double(h.qoffset_y)}, "the qform must be finite");
    check_finite(name, "qoffset_z", {double(h.qoffset_z)}, "the qform must be finite");
  }
  if (h.sform_code > 0) {
    const auto& x = h.srow_x;
    const auto& y = h.srow_y;
    const auto& z = h.srow_z;
    check_finite(name, "srow_x", {double(x[0]), double(x[1]), double(x[2]), double(x[3])},
                 "the sform must be finite");
    check_finite(name, "srow_y", {double(y[0]), double(y[1]), double(y[2]), double(y[3])},
                 "the sform must be finite");
    check_finite(name, "srow_z", {double(z[0]), double(z[1]), double(z[2]), double(z[3])},
                 "the sform must be finite");
  }
}

// Where the voxels start; refused unless they start after the header and end within the file.
template <typename Header>
std::uint64_t check_data_extent(const std::string& name, const Header& h, const Layout& l,
                                const Grid& grid, FileBytes& file) {
  const double offset = double(h.vox_offset);
  const int first = l.header_bytes + 4;
  if (!std::isfinite(offset) || offset != std::floor(offset))
    refuse_field(name, "vox_offset", offset, "must be a whole number of bytes");
  if (offset < first)
    refuse_field(name, "vox_offset", offset,
                 "the data must start after the " + std::to_string(first) + "-byte header");
  if (offset > double(std::int64_t{1} << 40))
    refuse_field(name, "vox_offset", offset, "beyond any file this reader takes");
  int bytes_per_voxel = 0, swap_size = 0;
  nifti_datatype_sizes(h.datatype, &bytes_per_voxel, &swap_size);
  const auto start = static_cast<std::uint64_t>(offset);
  const std::uint64_t end = start + std::uint64_t(grid.count()) * bytes_per_voxel;
  const std::uint64_t held = file.read_to(end);
  if (held < end)
    throw InputError(name + ": truncated: NIfTI header vox_offset = " + std::to_string(start) +
                     " and dims " + std::to_string(grid.size[0]) + " x " +
                     std::to_string(grid.size[1]) + " x " + std::to_string(grid.size[2]) + " of " +
                     nifti_datatype_string(h.datatype) + " need " + std::to_string(end) +
                     " bytes; the file holds " + std::to_string(held));
  return start;
}

std::string voxel_name(const Grid& g, long v) {
  return "voxel (" + std::to_string(v % g.size[0]) + "," +
         std::to_string(v / g.size[0] % g.size[1]) + "," +
         std::to_string(v / (g.size[0] * g.size[1])) + ")";
}

// Stored values are scaled when scl_slope is set (CT in Hounsfield units is often stored so). Every
// voxel must come out finite and within single precision, the type they are kept in.
template <typename T>
void convert(const char* data, bool swap, double slope, double inter, const std::string& name,
             VoxelVolume& volume) {
  const long n = volume.grid.count();
  volume.values.resize(static_cast<std::size_t>(n));
  const bool scaled = slope != 0.0 && !(slope == 1.0 && inter == 0.0);
  for (long v = 0; v < n; ++v) {
    const double stored = static_cast<double>(load<T>(data + v * sizeof(T), swap));
    if (std::isnan(stored)) throw InputError(name + ": " + voxel_name(volume.grid, v) + " is NaN");
    if (std::isinf(stored))
      throw InputError(name + ": " + voxel_name(volume.grid, v) + " is " +
                       (stored > 0 ? "+inf" : "-inf"));
    const double value = scaled ? slope * stored + inter : stored;
    if (!(std::abs(value) <= FLT_MAX))
      throw InputError(name + ": " + voxel_name(volume.grid, v) + " = " + number(stored) +
                       (scaled ? " scaled by scl_slope = " + number(slope) +
                                     ", scl_inter = " + number(inter) + " is " + number(value)
                               : std::string()) +
                       ", beyond single precision");
    volume.values[static_cast<std::size_t>(v)] = static_cast<float>(value);
  }
}

template <typename Header>
void convert_values(const char* data, bool swap, const Header& h, const std::string& name,
                    VoxelVolume& volume) {
  const double slope = h.scl_slope, inter = h.scl_inter;
  switch (h.datatype) {
    case NIFTI_TYPE_UINT8:
      return convert<std::uint8_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_INT8:
      return convert<std::int8_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_INT16:
      return convert<std::int16_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_UINT16:
      return convert<std::uint16_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_INT32:
      return convert<std::int32_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_UINT32:
      return convert<std::uint32_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_INT64:
      return convert<std::int64_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_UINT64:
      return convert<std::uint64_t>(data, swap, slope, inter, name, volume);
    case NIFTI_TYPE_FLOAT32:
      return convert<float>(data, swap, slope, inter, name, volume);
    default:
      return convert<double>(data, swap, slope, inter, name, volume);
  }
}

// The sform is the scanner's or the registration's full affine; the qform a rigid map times the
// voxel size; with neither code set, niftilib's qform is the voxel size alone (ANALYZE's default).
Eigen::Matrix4d transform_of(const nifti_image& image, const std::string& name,
                             std::vector<std::string>& notes) {
  const nifti_dmat44& m = image.sform_code > 0 ? image.sto_xyz : image.qto_xyz;
  const char* which = image.sform_code > 0 ? "sform" : "qform";
  notes.push_back(image.sform_code > 0   ? "voxel to world: sform"
                  : image.qform_code > 0 ? "voxel to world: qform (no sform)"
                                         : "voxel to world: voxel size only (no sform or qform)");
  if ((image.xyz_units & 0x07) == NIFTI_UNITS_UNKNOWN)
    notes.push_back("the image gives no spatial unit: millimetres assumed, as scanners write");
  Eigen::Matrix4d t;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      t(r, c) = m.m[r][c];
  t.topRows<3>() *= metres_per_unit(image.xyz_units);
  for (int axis = 0; axis < 3; ++axis) {
    const double voxel = t.col(axis).head<3>().stableNorm();
    if (!(voxel >= min_voxel_m && voxel <= max_voxel_m))
      throw InputError(name + ": the voxel-to-world transform (" + which + ") steps " +
                       number(voxel) + " m along " + "ijk"[axis] +
                       " (a voxel must be between 1 nm and 1 m)");
  }
  const double offset = t.col(3).head<3>().stableNorm();
  if (!(offset <= max_offset_m))
    throw InputError(name + ": the voxel-to-world transform (" + which + ") puts voxel (0,0,0) " +
                     number(offset) + " m from the origin (more than 1e6 m)");
  const double det = t.topLeftCorner<3, 3>().determinant();
  const double voxel = t.topLeftCorner<3, 3>().colwise().norm().prod();
  if (!std::isfinite(det) || !(std::abs(det) > 1e-9 * voxel))
    throw InputError(name + ": the voxel-to-world transform (" + which +
                     ") is singular (determinant " + number(det) + ")");
  if (det < 0) notes.push_back("left-handed voxel-to-world transform: triangles reoriented");
  return t;
}

nifti_image* to_image(const nifti_1_header& h) {
  return nifti_convert_n1hdr2nim(h, nullptr);
}
nifti_image* to_image(const nifti_2_header& h) {
  return nifti_convert_n2hdr2nim(h, nullptr);
}

template <typename Header>
VoxelVolume read_as(const std::string& name, FileBytes& file, const Layout& l) {
  Header h;
  std::memcpy(&h, file.data(), sizeof h);
  if (l.swapped) swap_nifti_header(&h, l.version);
  VoxelVolume volume;
  volume.grid = check_dims(name, h);
  check_fields(name, h);
  const std::uint64_t start = check_data_extent(name, h, l, volume.grid, file);
  convert_values(file.data() + start, l.swapped, h, name, volume);
  // In host byte order now, so niftilib swaps nothing; no file name, so it opens nothing.
  NiftiPointer image(to_image(h), nifti_image_free);
  if (!image) throw InputError(name + ": niftilib refuses the NIfTI header");
  volume.voxel_to_world = transform_of(*image, name, volume.notes);
  return volume;
}

}  // namespace

VoxelVolume read_nifti(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(name + ": no such file");
  nifti_set_debug_level(0);
  FileBytes bytes(name);
  const Layout layout = layout_of(name, bytes);
  return layout.version == 1 ? read_as<nifti_1_header>(name, bytes, layout)
                             : read_as<nifti_2_header>(name, bytes, layout);
}

}  // namespace msfem::cases::detail
