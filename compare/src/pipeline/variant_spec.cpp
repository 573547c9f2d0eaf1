#include "msfem/compare/pipeline/variant_spec.hpp"

#include "msfem/cases/setting_names.hpp"

namespace msfem::compare {

VariantSpec builtin_spec(cases::Variant kind) {
  return {cases::name_of(kind), kind, {}};
}

std::vector<VariantSpec> variant_specs(const cases::CaseParameters& parameters) {
  std::vector<VariantSpec> specs;
  for (const cases::Variant kind : parameters.mass_spring.variants)
    specs.push_back(builtin_spec(kind));
  for (const auto& network : parameters.mass_spring.networks)
    specs.push_back({network.name, std::nullopt, network.file});
  return specs;
}

}  // namespace msfem::compare
