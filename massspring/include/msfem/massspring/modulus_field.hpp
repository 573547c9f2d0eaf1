#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <limits>

#include "msfem/massspring/spring_network.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {

/// Young's modulus as a function of position (Pa), e.g. a CT's Hounsfield units through a table.
using ModulusField = std::function<double(const Eigen::Vector3d&)>;

/// The smallest and largest E a model's coefficients were taken from.
struct ModulusRange {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void include(double value);
  void include(const ModulusRange& other);
  bool empty() const { return min > max; }
};

/// Gives every spring of a network built for the uniform modulus `built_modulus` the stiffness its
/// analytic rule gives for the field: every rule (analytic_stiffness.hpp) is linear in E, so
/// k_s <- k_s · Ē_s / E_0. A spring through soft and stiff tissue is those pieces in series, so Ē_s
/// is the harmonic mean of E at `samples` points evenly spaced along its rest segment (midpoint
/// rule); a zero-length anchor takes E at its point. Where E is constant and equal to E_0 every
/// stiffness is unchanged, bit for bit. Returns the range of E the samples saw. Throws ModelError
/// for a sample that is not finite and > 0, naming the spring and the point.
ModulusRange apply_modulus_field(SpringNetwork& network, const ModulusField& field,
                                 double built_modulus, int samples = 8);

/// The same for volume elements: κ_e <- κ_e · Ē_e / E_0, Ē_e the volume-weighted mean of E at the
/// centroids of the element's tetrahedra (`rest_positions`, as the elements were built from).
ModulusRange apply_modulus_field(VolumeElements& elements, const Eigen::MatrixX3d& rest_positions,
                                 const ModulusField& field, double built_modulus);

}  // namespace msfem::massspring
