// The image mesher and the surface repair in a build without them (MSFEM_IMAGING=OFF, as the
// README's first command builds msfem): each refuses, before any work, with the way to build it.
#include <string>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_repair.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases {
namespace {

[[noreturn]] void refuse(const std::string& what) {
  throw InputError(what +
                   " needs the imaging part of msfem, which this build leaves out "
                   "(MSFEM_IMAGING=OFF: the README's first command builds msfem without it); "
                   "build it with the README's second command (bash scripts/test.sh) or "
                   "cmake -B build -DMSFEM_IMAGING=ON && cmake --build build --target msfem");
}

}  // namespace

double default_wrap_alpha(const Surface&) {
  refuse("surface repair (alpha wrap)");
}

Surface repair_surface(const Surface&, const RepairOptions&, RepairReport&) {
  refuse("surface repair");
}

namespace detail {

Surface mesh_mask(const Grid&, const Mask&, const Eigen::Vector3d&) {
  refuse("a surface from an image (CGAL Mesh_3)");
}

}  // namespace detail
}  // namespace msfem::cases
