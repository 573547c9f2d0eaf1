// msfem export-network CASE.prm OUTDIR: msfem's own models as the network files a simulator loads,
// and that msfem reads back as mass spring/networks (docs/networks.md).
#include <array>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;

// The model's volume elements as the file's cells: a one-tetrahedron element as a tetrahedron, a
// shell prism (nine tetrahedra: its three decompositions) as the wedge a b c / a' b' c'.
void add_volume_elements(const ms::VolumeForceField& volume, cases::NetworkFile& n) {
  const ms::VolumeElements& e = volume.elements();
  std::vector<std::array<int, 4>> tets;
  std::vector<std::array<int, 6>> wedges;
  std::vector<double> tet_modulus, wedge_modulus;
  for (int k = 0; k < e.num_elements(); ++k) {
    const int first = e.tet_start[std::size_t(k)], count = e.tet_start[std::size_t(k) + 1] - first;
    if (count == 1) {
      tets.push_back({{e.tets(first, 0), e.tets(first, 1), e.tets(first, 2), e.tets(first, 3)}});
      tet_modulus.push_back(e.modulus[k]);
    } else if (count == 9) {
      // (a b c a'), (b c a' b'), (c a' b' c'): the first decomposition names all six corners.
      wedges.push_back({{e.tets(first, 0), e.tets(first, 1), e.tets(first, 2), e.tets(first, 3),
                         e.tets(first + 2, 2), e.tets(first + 2, 3)}});
      wedge_modulus.push_back(e.modulus[k]);
    } else {
      throw std::runtime_error("a volume element of " + std::to_string(count) +
                               " tetrahedra has no cell type in a network file");
    }
  }
  n.tetrahedra.resize(Eigen::Index(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c)
      n.tetrahedra(Eigen::Index(t), c) = tets[t][std::size_t(c)];
  n.bulk_modulus = Eigen::Map<Eigen::VectorXd>(tet_modulus.data(), Eigen::Index(tets.size()));
  n.wedges.resize(Eigen::Index(wedges.size()), 6);
  for (std::size_t w = 0; w < wedges.size(); ++w)
    for (int c = 0; c < 6; ++c)
      n.wedges(Eigen::Index(w), c) = wedges[w][std::size_t(c)];
  n.wedge_bulk_modulus =
      Eigen::Map<Eigen::VectorXd>(wedge_modulus.data(), Eigen::Index(wedges.size()));
}

// Everything the model is made of, in its own node and spring order.
cases::NetworkFile network_file_of(const ms::MassSpringModel& model) {
  const ms::SpringNetwork& net = model.network();
  cases::NetworkFile n;
  n.points = net.rest_positions;
  n.springs = net.springs;
  n.stiffness = net.stiffness;
  n.damping = net.damping;
  n.rest_length = net.rest_length;
  n.spring_group = net.spring_group;
  n.group_names = net.spring_group_names;
  n.triangles = net.surface_triangles;
  n.mass = net.masses;
  std::vector<bool> fixed(std::size_t(net.num_nodes()), false);
  for (const int node : model.constrained_nodes())
    fixed[std::size_t(node)] = true;
  n.fixed = fixed;
  if (net.num_anchors() > 0) {
    n.anchor_stiffness = Eigen::VectorXd::Zero(net.num_nodes());
    n.anchor_damping = Eigen::VectorXd::Zero(net.num_nodes());
    for (int a = 0; a < net.num_anchors(); ++a) {
      if ((net.anchor_point.row(a) - net.rest_positions.row(net.anchor_node[a])).norm() > 0)
        throw std::runtime_error(
            "an anchor away from its node's rest position has no network "
            "file form");
      (*n.anchor_stiffness)[net.anchor_node[a]] = net.anchor_stiffness[a];
      (*n.anchor_damping)[net.anchor_node[a]] = net.anchor_damping[a];
    }
  }
  if (const ms::VolumeForceField* volume = model.volume()) add_volume_elements(*volume, n);
  return n;
}

// Xsp holds springs, masses and fixed flags only: what it would drop, or nothing.
std::string xsp_leaves_out(const cases::NetworkFile& n) {
  if (n.anchor_stiffness) return "anchors";
  if (n.tetrahedra.rows() + n.wedges.rows() > 0) return "volume elements";
  return "";
}

}  // namespace

int export_network_command(const Arguments& args) {
  const Options opt(args, {}, {"set"});
  if (opt.positional().size() != 2)
    throw std::invalid_argument("usage: msfem export-network CASE.prm OUTDIR [--set K=V]...");
  const cases::CaseParameters parameters = cases::read_case(opt.positional()[0], opt.values("set"));
  const std::filesystem::path out = opt.positional()[1];
  check_output_folder(out);
  check_group_names(parameters);
  const Problem problem = make_problem(parameters);
  check_variants_fit(problem);
  const std::vector<VariantSpec> specs = variant_specs(parameters);
  fem_reference::VolumeMesh mesh;
  for (const VariantSpec& spec : specs)
    // The mesh msfem run springs, refined at every tool of the case.
    if (spec.builtin == cases::Variant::tet_edges) mesh = mesh_problem(problem, problem.tools);
  std::vector<std::string> written;
  fill_directory_atomically(out, [&](const std::filesystem::path& work) {
    for (const VariantSpec& spec : specs) {
      const BuiltVariant built = build_variant(spec, problem, mesh, std::nullopt);
      const cases::NetworkFile n = network_file_of(*built.model);
      cases::write_network(work / (spec.name + ".vtu"), n);
      written.push_back(spec.name + ".vtu");
      if (const std::string dropped = xsp_leaves_out(n); dropped.empty()) {
        cases::write_network(work / (spec.name + ".xs3"), n);
        written.push_back(spec.name + ".xs3");
      } else {
        std::cerr << "msfem export-network: " << spec.name << ": no .xs3 (Xsp has no " << dropped
                  << ")\n";
      }
    }
  });
  for (const auto& file : written)
    std::cout << (out / file).string() << "\n";
  return 0;
}

}  // namespace msfem::compare
