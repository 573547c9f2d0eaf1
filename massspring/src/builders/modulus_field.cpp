#include "msfem/massspring/modulus_field.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {
namespace {

std::string point_text(const Eigen::Vector3d& x) {
  return "(" + std::to_string(x.x()) + ", " + std::to_string(x.y()) + ", " + std::to_string(x.z()) +
         ") m";
}

// E_0 / E(x): dividing E_0 by E (not E by E_0) keeps a field equal to E_0 an exact 1.
// `what` and `index` name the item in the message (built only when it is thrown).
double inverse_ratio(const ModulusField& field, const Eigen::Vector3d& x, double built_modulus,
                     const char* what, int index, ModulusRange& range) {
  const double e = field(x);
  if (!(e > 0.0) || !std::isfinite(e))
    throw ModelError("Young's modulus field gives " + std::to_string(e) + " Pa at " +
                     point_text(x) + " (" + what + " " + std::to_string(index) +
                     "); it must be finite and > 0");
  range.include(e);
  return built_modulus / e;
}

void check_built_modulus(double built_modulus) {
  if (!(built_modulus > 0.0) || !std::isfinite(built_modulus))
    throw ModelError("built modulus " + std::to_string(built_modulus) +
                     " Pa must be finite and > 0");
}

}  // namespace

void ModulusRange::include(double value) {
  min = std::min(min, value);
  max = std::max(max, value);
}

void ModulusRange::include(const ModulusRange& other) {
  min = std::min(min, other.min);
  max = std::max(max, other.max);
}

ModulusRange apply_modulus_field(SpringNetwork& network, const ModulusField& field,
                                 double built_modulus, int samples) {
  check_built_modulus(built_modulus);
  if (samples < 1) throw ModelError("modulus field: samples must be >= 1");
  ModulusRange range;
  for (int s = 0; s < network.num_springs(); ++s) {
    const Eigen::Vector3d a = network.rest_positions.row(network.springs(s, 0)).transpose();
    const Eigen::Vector3d b = network.rest_positions.row(network.springs(s, 1)).transpose();
    double compliance = 0.0;  // Σ E_0 / E over the pieces
    for (int i = 0; i < samples; ++i)
      compliance += inverse_ratio(field, a + (b - a) * ((i + 0.5) / samples), built_modulus,
                                  "spring", s, range);
    network.stiffness[s] *= double(samples) / compliance;
  }
  for (int n = 0; n < network.num_anchors(); ++n) {
    const Eigen::Vector3d x = network.anchor_point.row(n).transpose();
    network.anchor_stiffness[n] /= inverse_ratio(field, x, built_modulus, "anchor", n, range);
  }
  return range;
}

ModulusRange apply_modulus_field(VolumeElements& elements, const Eigen::MatrixX3d& rest_positions,
                                 const ModulusField& field, double built_modulus) {
  check_built_modulus(built_modulus);
  ModulusRange range;
  for (int e = 0; e < elements.num_elements(); ++e) {
    double weighted = 0.0, weights = 0.0;
    for (int t = elements.tet_start[e]; t < elements.tet_start[e + 1]; ++t) {
      Eigen::Vector3d corners[4];
      for (int c = 0; c < 4; ++c)
        corners[c] = rest_positions.row(elements.tets(t, c)).transpose();
      const double volume = std::abs((corners[1] - corners[0])
                                         .cross(corners[2] - corners[0])
                                         .dot(corners[3] - corners[0])) *
                            elements.tet_weight[t];
      const Eigen::Vector3d centroid = (corners[0] + corners[1] + corners[2] + corners[3]) / 4.0;
      weighted +=
          volume / inverse_ratio(field, centroid, built_modulus, "volume element", e, range);
      weights += volume;
    }
    if (weights > 0.0) elements.modulus[e] *= weighted / weights;
  }
  return range;
}

}  // namespace msfem::massspring
