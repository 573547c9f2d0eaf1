#pragma once
// msfem's own spring variants, one row each: everything the pipeline knows of a built-in variant
// is here, so that adding one is adding a row (docs/architecture.md, "A variant").

#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::compare::detail {

struct BuiltinVariant {
  cases::Variant kind;
  /// Its network from the case (E the case's: a CT's field is applied afterwards).
  massspring::SpringNetwork (*network)(const Problem&, const fem_reference::VolumeMesh&,
                                       const massspring::Material&);
  /// Its spring groups under the case's settings, before it is built: the builder's own list.
  std::vector<std::string> (*spring_groups)(const cases::CaseParameters&);
  /// The nodes it will have, before it is built (the cost ranks deal variants by).
  double (*estimated_nodes)(const Problem&, const fem_reference::VolumeMesh&);
  /// How many copies of the surface it holds (a local refinement's added vertices count so often).
  int surface_copies;
  /// Whether its nodes are the FEM mesh's, with its tetrahedra (tet_edges).
  bool on_fem_mesh;
  /// Its volume elements for volume preservation at modulus κ (rest: the network's rest
  /// positions, tetrahedra: the FEM mesh's where on_fem_mesh); null for a variant without any.
  massspring::VolumeElements (*volume_elements)(const Eigen::MatrixX3d& rest, const Problem&,
                                                const Eigen::MatrixX4i& tetrahedra, double modulus);
};

/// The row of `kind`.
const BuiltinVariant& builtin_variant(cases::Variant kind);

}  // namespace msfem::compare::detail
