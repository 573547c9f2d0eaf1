#pragma once
// What a run compares with the FEM: msfem's own variants (mass spring/variants), each made by its
// builder, then a user's networks (mass spring/networks), each read from its file. Every stage of
// a run (statics, loads, timing, sharing under mpirun, reports) takes the one list.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"

namespace msfem::compare {

struct VariantSpec {
  std::string name;                       ///< the variant's name in every table and file
  std::optional<cases::Variant> builtin;  ///< msfem's builder; none for a user's network
  std::filesystem::path network;          ///< the network's file (a user's network only)
};

/// The case's variants in report order: the built-in ones as mass spring/variants lists them, then
/// the networks as mass spring/networks lists them.
std::vector<VariantSpec> variant_specs(const cases::CaseParameters& parameters);

/// The built-in variant `kind` as a spec.
VariantSpec builtin_spec(cases::Variant kind);

}  // namespace msfem::compare
