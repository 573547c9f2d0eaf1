// libFuzzer target for one of msfem's input readers, chosen at compile time (MSFEM_FUZZ_OBJ, _STL,
// _OFF, _PLY, _X3D, _CASE, _NIFTI). A reader may refuse an input only with cases::InputError;
// anything else (a crash, a hang, a sanitizer report, another exception, a surface it returns with
// an index out of range or a non-finite coordinate, an image with a non-finite voxel or a transform
// that is not finite and invertible) is a defect the fuzzer reports.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string>
#include <string_view>

#include "msfem/cases/errors.hpp"
#include "surface_io_detail.hpp"
#ifdef MSFEM_FUZZ_NETWORK
#include "msfem/cases/network_file.hpp"
#endif
#ifdef MSFEM_FUZZ_CASE
#include "case_file_text.hpp"
#endif
#ifdef MSFEM_FUZZ_X3D
#include "msfem/cases/x3d.hpp"
#endif
#ifdef MSFEM_FUZZ_NIFTI
#include <unistd.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>

#include "voxel_volume.hpp"
#endif

namespace {

using msfem::cases::Surface;

void check(const Surface& s) {
  if (!s.vertices.allFinite()) std::abort();
  for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (s.triangles(t, k) < 0 || s.triangles(t, k) >= s.vertices.rows()) std::abort();
}

#ifdef MSFEM_FUZZ_NIFTI
void check(const msfem::cases::detail::VoxelVolume& image) {
  for (long size : image.grid.size)
    if (size < 2) std::abort();
  if (image.values.size() != static_cast<std::size_t>(image.grid.count())) std::abort();
  for (float v : image.values)
    if (!std::isfinite(v)) std::abort();
  if (!image.voxel_to_world.allFinite() || image.voxel_to_world.determinant() == 0) std::abort();
}

// The reader takes a path (zlib and niftilib open files): the bytes go to a file of this process's
// own, so that parallel fuzzing jobs do not share one, removed after each read, because rewriting a
// truncated file makes ext4 flush it to disk on close, a hundredfold slowdown.
class Written {
 public:
  explicit Written(std::string_view bytes) {
    std::FILE* out = std::fopen(path.c_str(), "wb");
    if (!out || std::fwrite(bytes.data(), 1, bytes.size(), out) != bytes.size() ||
        std::fclose(out) != 0)
      std::abort();
  }
  ~Written() { std::remove(path.c_str()); }
  Written(const Written&) = delete;
  Written& operator=(const Written&) = delete;

  const std::string path = "/tmp/msfem_fuzz_nifti_" + std::to_string(::getpid()) + ".nii";
};
#endif

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
#if defined(MSFEM_FUZZ_OBJ)
    check(msfem::cases::detail::read_obj("fuzz.obj", bytes));
#elif defined(MSFEM_FUZZ_STL)
    check(msfem::cases::detail::read_stl("fuzz.stl", bytes));
#elif defined(MSFEM_FUZZ_OFF)
    check(msfem::cases::detail::read_off("fuzz.off", bytes));
#elif defined(MSFEM_FUZZ_PLY)
    check(msfem::cases::detail::read_ply("fuzz.ply", bytes));
#elif defined(MSFEM_FUZZ_X3D)
    check(msfem::cases::read_x3d_surface_bytes("fuzz.x3d", std::string(bytes)));
#elif defined(MSFEM_FUZZ_CASE)
    // The language's sections as the case reader passes them; includes resolve under /nonexistent
    // so the fuzzer cannot make the target read the machine's files.
    static const std::set<std::string> sections = {
        "geometry", "material", "support", "loads", "loads/tool", "loads/patch force", "fem"};
    msfem::cases::checked_case_text("/nonexistent/fuzz.prm", std::string(bytes), sections);
#elif defined(MSFEM_FUZZ_NIFTI)
    const Written file(bytes);
    check(msfem::cases::detail::read_nifti(file.path));
#elif defined(MSFEM_FUZZ_NETWORK)
    // A network that is read is valid: every id in range, every coefficient finite.
    const auto n = msfem::cases::read_network_bytes("fuzz." MSFEM_FUZZ_NETWORK, std::string(bytes));
    if (!n.points.allFinite() || !n.stiffness.allFinite()) std::abort();
    for (Eigen::Index s = 0; s < n.springs.rows(); ++s)
      for (int k = 0; k < 2; ++k)
        if (n.springs(s, k) < 0 || n.springs(s, k) >= n.points.rows()) std::abort();
#endif
  } catch (const msfem::cases::InputError&) {
    // a refused input, named: what a reader must do with bad bytes
  }
  return 0;
}
