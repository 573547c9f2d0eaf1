// A user's network as a variant: read from its file (cases/network_file.hpp) and given what the
// file leaves to the case, so that it is measured exactly as msfem's own variants are.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/cases/surface.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;

// A case surface vertex and a network node are the same point when they are this close, relative
// to the surface's bounding-box diagonal: far below any mesh's edge, far above the round-off of
// coordinates a simulator wrote with 9 or more significant digits.
constexpr double match_tolerance = 1e-7;

std::string point_text(const Eigen::Vector3d& x) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.9g, %.9g, %.9g)", x.x(), x.y(), x.z());
  return text;
}

// The network node at each case surface vertex, by position: the points sorted along x, each
// vertex searched within the tolerance there.
std::vector<int> surface_nodes_of(const cases::NetworkFile& n, const Problem& problem,
                                  const std::string& where) {
  const cases::Surface& s = problem.surface;
  const Eigen::Matrix<double, 2, 3> box = cases::bounding_box(s);
  const double tolerance = match_tolerance * (box.row(1) - box.row(0)).norm();
  std::vector<int> by_x(static_cast<std::size_t>(n.points.rows()));
  std::iota(by_x.begin(), by_x.end(), 0);
  std::sort(by_x.begin(), by_x.end(),
            [&](int a, int b) { return n.points(a, 0) < n.points(b, 0); });
  std::vector<int> nodes(static_cast<std::size_t>(s.num_vertices()), -1);
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v) {
    const Eigen::Vector3d x = s.vertices.row(v).transpose();
    auto it = std::lower_bound(by_x.begin(), by_x.end(), x.x() - tolerance,
                               [&](int node, double value) { return n.points(node, 0) < value; });
    double best = tolerance;
    for (; it != by_x.end() && n.points(*it, 0) <= x.x() + tolerance; ++it) {
      const double d = (n.points.row(*it).transpose() - x).norm();
      if (d <= best) best = d, nodes[std::size_t(v)] = *it;
    }
    if (nodes[std::size_t(v)] < 0) {
      char text[64];
      std::snprintf(text, sizeof text, "%.3g m", tolerance);
      throw cases::InputError(where + ": surface vertex " + std::to_string(v) + " at " +
                              point_text(x) + " has no network node within " + text +
                              " (the network is not of the case's geometry, or not in metres)");
    }
  }
  return nodes;
}

// Masses the file leaves out: the case's density times the organ's volume, shared among the nodes
// as their springs are (half of each spring's rest length to each end), so that a node among short
// springs, in a finer part of the network, carries less.
Eigen::VectorXd lumped_masses(const ms::SpringNetwork& net, const Problem& problem) {
  const double total = problem.parameters.material.density_kg_per_m3 *
                       std::abs(cases::signed_volume(problem.surface));
  Eigen::VectorXd share = Eigen::VectorXd::Zero(net.num_nodes());
  for (int k = 0; k < net.num_springs(); ++k)
    for (int end = 0; end < 2; ++end)
      share[net.springs(k, end)] += 0.5 * net.rest_length[k];
  const double sum = share.sum();
  if (!(sum > 0)) return Eigen::VectorXd::Constant(net.num_nodes(), total / net.num_nodes());
  // A node in no spring (an anchored or fixed point alone) still needs a mass to be stepped.
  const double least = sum / net.num_nodes() * 1e-3;
  for (Eigen::Index i = 0; i < share.size(); ++i)
    share[i] = std::max(share[i], least);
  return share * (total / share.sum());
}

ms::SpringNetwork spring_network(const cases::NetworkFile& n, const Problem& problem,
                                 const std::string& where) {
  ms::SpringNetwork net;
  net.rest_positions = n.points;
  net.springs = n.springs;
  net.stiffness = n.stiffness;
  net.rest_length.resize(n.springs.rows());
  for (Eigen::Index k = 0; k < n.springs.rows(); ++k)
    net.rest_length[k] =
        n.rest_length ? (*n.rest_length)[k]
                      : (n.points.row(n.springs(k, 0)) - n.points.row(n.springs(k, 1))).norm();
  net.damping = n.damping ? *n.damping : Eigen::VectorXd::Zero(n.springs.rows());
  net.spring_group = n.spring_group;
  net.spring_group_names = n.group_names;
  net.node_damping = Eigen::VectorXd::Zero(n.points.rows());
  net.node_group = Eigen::VectorXi::Zero(n.points.rows());
  net.node_group_names = {"nodes"};
  if (n.anchor_stiffness) {
    for (Eigen::Index i = 0; i < n.points.rows(); ++i)
      if ((*n.anchor_stiffness)[i] > 0) {
        const Eigen::Index a = net.anchor_node.size();
        net.anchor_node.conservativeResize(a + 1);
        net.anchor_point.conservativeResize(a + 1, 3);
        net.anchor_stiffness.conservativeResize(a + 1);
        net.anchor_damping.conservativeResize(a + 1);
        net.anchor_node[a] = static_cast<int>(i);
        net.anchor_point.row(a) = n.points.row(i);
        net.anchor_stiffness[a] = (*n.anchor_stiffness)[i];
        net.anchor_damping[a] = n.anchor_damping ? (*n.anchor_damping)[i] : 0.0;
      }
  }
  net.surface_nodes = surface_nodes_of(n, problem, where);
  if (n.triangles.rows() > 0) {
    net.surface_triangles = n.triangles;
    // The file's surface may have more nodes than the case's (tet_edges on the FEM's mesh refined
    // at the tool): they follow the case's vertices, and a bonded tool holds them too.
    std::vector<bool> listed(std::size_t(n.points.rows()), false);
    for (const int node : net.surface_nodes)
      listed[std::size_t(node)] = true;
    std::vector<int> more;
    for (Eigen::Index t = 0; t < n.triangles.rows(); ++t)
      for (int c = 0; c < 3; ++c)
        if (!listed[std::size_t(n.triangles(t, c))]) {
          listed[std::size_t(n.triangles(t, c))] = true;
          more.push_back(n.triangles(t, c));
        }
    std::sort(more.begin(), more.end());
    net.surface_nodes.insert(net.surface_nodes.end(), more.begin(), more.end());
  } else {
    // Xsp carries no triangles: the case's surface, on the matched nodes.
    net.surface_triangles = problem.surface.triangles;
    for (Eigen::Index t = 0; t < net.surface_triangles.rows(); ++t)
      for (int c = 0; c < 3; ++c)
        net.surface_triangles(t, c) = net.surface_nodes[std::size_t(net.surface_triangles(t, c))];
  }
  net.masses = n.mass ? *n.mass : lumped_masses(net, problem);
  return net;
}

// The file's tetrahedra (one tetrahedron each) and wedges (a shell prism: its three
// decompositions, weight 1/3 each, as msfem's three tiers have them) as volume elements.
ms::VolumeElements volume_elements(const cases::NetworkFile& n, double factor) {
  ms::VolumeElements e = ms::tetrahedron_elements(n.points, n.tetrahedra, 1.0);
  std::vector<double> modulus(n.bulk_modulus.data(), n.bulk_modulus.data() + n.bulk_modulus.size());
  Eigen::Index t = e.tets.rows();
  e.tets.conservativeResize(t + 9 * n.wedges.rows(), 4);
  e.tet_weight.conservativeResize(t + 9 * n.wedges.rows());
  e.rest_volume.conservativeResize(n.tetrahedra.rows() + n.wedges.rows());
  for (Eigen::Index w = 0; w < n.wedges.rows(); ++w) {
    double volume = 0.0;
    for (int r = 0; r < 3; ++r) {
      const int a = n.wedges(w, r), b = n.wedges(w, (r + 1) % 3), c = n.wedges(w, (r + 2) % 3);
      const int a2 = n.wedges(w, 3 + r), b2 = n.wedges(w, 3 + (r + 1) % 3),
                c2 = n.wedges(w, 3 + (r + 2) % 3);
      for (const auto& tet : {std::array<int, 4>{{a, b, c, a2}}, std::array<int, 4>{{b, c, a2, b2}},
                              std::array<int, 4>{{c, a2, b2, c2}}}) {
        e.tets.row(t) << tet[0], tet[1], tet[2], tet[3];
        e.tet_weight[t++] = 1.0 / 3.0;
        const Eigen::Vector3d p0 = n.points.row(tet[0]).transpose();
        volume += (n.points.row(tet[1]).transpose() - p0)
                      .cross(n.points.row(tet[2]).transpose() - p0)
                      .dot(n.points.row(tet[3]).transpose() - p0) /
                  18.0;
      }
    }
    e.tet_start.push_back(static_cast<int>(t));
    e.rest_volume[n.tetrahedra.rows() + w] = volume;
    modulus.push_back(n.wedge_bulk_modulus[w]);
  }
  e.modulus = factor * Eigen::Map<Eigen::VectorXd>(modulus.data(), Eigen::Index(modulus.size()));
  return e;
}

}  // namespace

void build_network_variant(BuiltVariant& variant, const Problem& problem) {
  const auto& p = problem.parameters;
  const std::string where = p.file.string() + ": mass spring/networks: " + variant.name + "=" +
                            variant.spec.network.string();
  cases::NetworkFile n;
  try {
    n = cases::read_network(variant.spec.network);
  } catch (const cases::InputError& e) {
    throw cases::InputError(where + ": " + e.what());
  }
  variant.youngs_modulus_range.include(p.material.youngs_modulus_pa);
  variant.tetrahedra = n.tetrahedra;
  variant.model = std::make_unique<ms::MassSpringModel>(spring_network(n, problem, where));
  ms::MassSpringModel& model = *variant.model;
  if (n.fixed) {
    for (std::size_t i = 0; i < n.fixed->size(); ++i)
      if ((*n.fixed)[i]) model.fix_node(static_cast<int>(i));
  } else {
    const auto& rest = model.network().rest_positions;
    for (int node = 0; node < model.num_nodes(); ++node)
      if (problem.fixed_region(rest.row(node).transpose())) model.fix_node(node);
  }
  scale_groups(model, p);
  if (n.tetrahedra.rows() + n.wedges.rows() > 0) {
    double factor = 1.0;
    for (const auto& [group, scale] : p.mass_spring.group_scales)
      if (group == volume_group) factor *= scale;
    model.set_volume(ms::VolumeForceField(model.num_nodes(), volume_elements(n, factor)));
  }
  if (!n.damping)
    model.set_damping(ms::damping_for_ratio(model.network(), p.mass_spring.damping_ratio));
  // Xsp's scene-wide values: the case's loads and damping apply to every variant alike.
  const Eigen::Vector3d& g = p.loads.gravity_m_per_s2;
  if (!n.gravity.isZero() && (n.gravity - g).norm() > 1e-9 * std::max(g.norm(), n.gravity.norm()))
    variant.warnings.push_back({Warning::Kind::file_setting_not_applied,
                                "the file's grav " + point_text(n.gravity) +
                                    " m/s^2 is not applied: the case's loads/gravity " +
                                    point_text(g) + " is, as for every variant"});
  if (n.viscosity && *n.viscosity != 0)
    variant.warnings.push_back(
        {Warning::Kind::file_setting_not_applied,
         "the file's visc (" + std::to_string(*n.viscosity) +
             ") is not applied: dampers come from mass spring/damping ratio"});
}

void check_networks_fit(const Problem& problem) {
  const auto& p = problem.parameters;
  for (const auto& network : p.mass_spring.networks) {
    const std::string where =
        p.file.string() + ": mass spring/networks: " + network.name + "=" + network.file.string();
    try {
      surface_nodes_of(cases::read_network(network.file), problem, where);
    } catch (const cases::InputError& e) {
      const std::string what = e.what();
      throw cases::InputError(what.rfind(where, 0) == 0 ? what : where + ": " + what);
    }
  }
}

std::vector<std::string> network_groups(const std::filesystem::path& file) {
  const cases::NetworkFile n = cases::read_network(file);
  std::vector<std::string> groups = n.group_names;
  if (n.tetrahedra.rows() + n.wedges.rows() > 0) groups.emplace_back(volume_group);
  return groups;
}

}  // namespace msfem::compare
