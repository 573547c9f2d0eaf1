#pragma once
// Which SIMD kernel a fast stepper runs: both fast steppers choose their lanes alike.

#include <memory>

#include "kernels/gather_kernels.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/spring_force_field.hpp"

namespace msfem::massspring::detail {

/// Kernel<Real, preferred_lanes<Real>(...)>: double 8 lanes (AVX-512) or 4, float 16 (AVX-512,
/// while this network fits the cache) or 8.
template <template <class, int> class Kernel, class Base, class Options>
std::unique_ptr<Base> kernel_for_lanes(const MechanicalSystem& system, const Options& options,
                                       bool allow_avx512) {
  const long springs = spring_field(system, "the fast stepper").network().num_springs();
  if (!options.single_precision) {
    if (preferred_lanes<double>(allow_avx512, springs, system.num_nodes()) == 8)
      return std::make_unique<Kernel<double, 8>>(system, options);
    return std::make_unique<Kernel<double, 4>>(system, options);
  }
  if (preferred_lanes<float>(allow_avx512, springs, system.num_nodes()) == 16)
    return std::make_unique<Kernel<float, 16>>(system, options);
  return std::make_unique<Kernel<float, 8>>(system, options);
}

}  // namespace msfem::massspring::detail
