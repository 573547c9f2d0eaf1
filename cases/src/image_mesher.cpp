// The one translation unit that includes CGAL Mesh_3 (slow to compile). Mesh_3 samples the
// boundary of the labelled image with a restricted Delaunay triangulation: its facets are faces of
// a tetrahedralisation, so they cannot intersect, and the manifold criterion refines until every
// edge and vertex of the boundary is 2-manifold. Marching cubes gives neither guarantee.
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_3/initialize_triangulation_from_labeled_image.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/facets_in_complex_3_to_triangle_mesh.h>
#include <CGAL/refine_mesh_3.h>

#include <algorithm>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "cgal_surface_mesh.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases::detail {
namespace {

using Domain = CGAL::Labeled_mesh_domain_3<Kernel>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

CGAL::Image_3 image_of(const Grid& g, const Mask& mask, const Eigen::Vector3d& spacing) {
  _image* image = _createImage(g.size[0], g.size[1], g.size[2], 1, spacing.x(), spacing.y(),
                               spacing.z(), 1, WK_FIXED, SGN_UNSIGNED);
  if (image == nullptr) throw std::runtime_error("cannot allocate the voxel image");
  std::copy(mask.begin(), mask.end(), static_cast<unsigned char*>(image->data));
  return CGAL::Image_3(image);
}

}  // namespace

Surface mesh_mask(const Grid& grid, const Mask& mask, const Eigen::Vector3d& spacing) {
  // The same input gives the same surface: Mesh_3 draws its initial points at random.
  CGAL::get_default_random() = CGAL::Random(0);
  const CGAL::Image_3 image = image_of(grid, mask, spacing);
  namespace p = CGAL::parameters;
  const Domain domain =
      Domain::create_labeled_image_mesh_domain(image, p::relative_error_bound = 1e-6);
  // Facets about a voxel across and within half a voxel of the labelled boundary (CGAL's image
  // examples use one to two voxels): a third of a voxel chased the staircase corners for minutes.
  const double voxel = spacing.minCoeff();
  const Criteria criteria(p::facet_angle = 25.0, p::facet_size = 1.0 * voxel,
                          p::facet_distance = 0.5 * voxel);
  Complex complex;
  {
    // CGAL's image initialisation reports its progress on std::cout, msfem's result channel.
    std::ostringstream progress;
    const auto previous = std::cout.rdbuf(progress.rdbuf());
    try {
      initialize_triangulation_from_labeled_image(complex, domain, image, criteria,
                                                  static_cast<unsigned char>(0));
    } catch (...) {
      std::cout.rdbuf(previous);
      throw;
    }
    std::cout.rdbuf(previous);
  }
  CGAL::refine_mesh_3(complex, domain, criteria, p::manifold(), p::no_perturb(), p::no_exude());
  CgalMesh boundary;
  CGAL::facets_in_complex_3_to_triangle_mesh(complex, boundary);
  Surface s = from_cgal(boundary);
  for (int axis = 0; axis < 3; ++axis)
    s.vertices.col(axis) /= spacing(axis);
  return s;
}

}  // namespace msfem::cases::detail
