// The checks that span keys: a value each key's own pattern accepts, but which the rest of the case
// makes meaningless (a time step no clock resolves, a stiffness table without an image) or leaves
// unused. A setting msfem would ignore is refused, never dropped in silence.
#include "case_consistency.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/modulus_image.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/units.hpp"

namespace msfem::cases {
namespace {

// A step the steppers take as a haptic loop does is 1e-3 s; below 1e-7 s the timing reports the
// time to simulate one frame in hours and a run takes minutes to say so.
constexpr double smallest_time_step_s = 1e-7;
// Soft tissue is 0.1-100 kPa and bone 10-20 GPa: a HU table outside [1e-3 Pa, 1e12 Pa], or whose
// stiffest point is more than 1e9 times its softest, gives a stiffness matrix no solver can
// factor (the FEM failed in PETSc with NaN, after its solve).
constexpr double least_modulus_pa = 1e-3, greatest_modulus_pa = 1e12, greatest_contrast = 1e9;

std::string g(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

void check_time_step(const TimingParameters& timing) {
  if (timing.dt_s > 0 && timing.dt_s < smallest_time_step_s)
    throw InputError("timing/dt = " + g(timing.dt_s) + " s is below " + g(smallest_time_step_s) +
                     " s (a haptic loop steps at 1e-3 s; 0 takes half each variant's stable step)");
}

void check_hu_table(const MaterialParameters& m) {
  const HuToYoungs table = parse_hu_to_youngs(m.hu_to_youngs, "material/hu to youngs");
  if (m.youngs_modulus_image.empty() &&
      table.describe() != parse_hu_to_youngs(default_hu_to_youngs, "default").describe())
    throw InputError(
        "material/hu to youngs is set but material/youngs modulus image is empty: the table maps "
        "an image's Hounsfield units and would be ignored (set the image, or remove the table)");
  double least = table.points.front()[1], greatest = least;
  for (const auto& point : table.points) {
    least = std::min(least, point[1]);
    greatest = std::max(greatest, point[1]);
    if (point[1] < least_modulus_pa || point[1] > greatest_modulus_pa)
      throw InputError("material/hu to youngs: " + g(point[0]) + ":" + g(point[1]) +
                       " gives E outside [" + g(least_modulus_pa) + ", " + g(greatest_modulus_pa) +
                       "] Pa");
  }
  if (greatest > greatest_contrast * least)
    throw InputError("material/hu to youngs: E spans " + g(least) + " to " + g(greatest) +
                     " Pa, a contrast above " + g(greatest_contrast) +
                     " that no solver resolves in one stiffness matrix");
}

void check_geometry_unit(const GeometryParameters& geometry) {
  if (geometry.unit == LengthUnit::metre) return;
  const bool image = is_image_source(geometry.source);
  const bool network = is_network_source(geometry.source);
  if (image || network || is_surface_generator(geometry.source))
    throw InputError("geometry/unit = " + to_string(geometry.unit) + " has no effect on " +
                     (image     ? "an image source (its header gives the voxel size in world units)"
                      : network ? "a network's surface (network files are in metres)"
                                : "a generated surface (its sizes are in metres)") +
                     ": remove it");
}

void check_mass_spring(const MassSpringParameters& ms) {
  if (ms.variants.empty() && ms.networks.empty() && ms.results.empty())
    throw InputError(
        "mass spring/variants is empty and mass spring/networks and results name none: "
        "nothing to compare with the FEM");
  const auto& refinement = ms.contact_refinement;
  if (!refinement.enabled && (refinement.radius_m > 0 || refinement.edge_m > 0))
    throw InputError(
        "mass spring/contact refinement: radius or edge length is set but enabled = false: "
        "nothing is refined (set enabled = true, or remove them)");
  const bool has_volume_elements =
      std::any_of(ms.variants.begin(), ms.variants.end(),
                  [](Variant v) { return v == Variant::three_tier || v == Variant::tet_edges; });
  if (ms.volume_preservation && !has_volume_elements)
    throw InputError(
        "mass spring/volume preservation = true, but none of mass spring/variants has volume "
        "elements (three_tier's shell prisms, tet_edges' tetrahedra): it would change nothing");
}

}  // namespace

void check_consistency(const CaseParameters& c) {
  check_time_step(c.timing);
  check_hu_table(c.material);
  check_geometry_unit(c.geometry);
  check_mass_spring(c.mass_spring);
}

}  // namespace msfem::cases
