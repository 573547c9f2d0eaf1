// A variant's share as bytes (pipeline/byte_packing.hpp).
#include "variant_share.hpp"

#include <type_traits>

#include "pipeline/byte_packing.hpp"

namespace msfem::compare::detail {
namespace {

// One function per structure for both directions, so that a field cannot be written and not read.
template <typename Io, typename Curve>
void curve_fields(Io& io, Curve& curve) {
  long long n = static_cast<long long>(curve.size());
  io.io(n);
  curve.resize(static_cast<std::size_t>(n));
  // A spring variant's curve has no FEM contact report (only the reference's does).
  for (auto& point : curve)
    io.io(point.depth_m), io.io(point.force_n), io.io(point.inverted_elements);
}

template <typename Io, typename L>
void load_fields(Io& io, L& o) {  // ToolLoadVariant (kind and name come from the variant)
  load_error_fields(io, o);
  io.io(o.volume_change);
  io.io(o.inverted_elements);
  curve_fields(io, o.force_depth);
  io.io(o.force_depth_monotone), io.io(o.lost_tool), io.io(o.patch_mean_displacement);
  io.io(o.patch_displacement_rel_error), io.io(o.newton_iterations);
  io.io(o.equilibrium), io.io(o.surface_displacement), io.io(o.error);
}

template <typename Io, typename W>
void warning_fields(Io& io, W& w) {  // Warning
  int kind = static_cast<int>(w.kind);
  long long load = w.load ? static_cast<long long>(*w.load) : -1;
  long long n = static_cast<long long>(w.metrics.size());
  io.io(kind), io.io(w.text), io.io(load), io.io(n);
  w.kind = static_cast<Warning::Kind>(kind);
  w.load = load < 0 ? std::nullopt : std::optional<std::size_t>(static_cast<std::size_t>(load));
  w.metrics.resize(static_cast<std::size_t>(n));
  for (Metric& m : w.metrics) {
    int code = static_cast<int>(m);
    io.io(code);
    m = static_cast<Metric>(code);
  }
}

template <typename Io, typename T>
void timing_fields(Io& io, T& t) {
  io.io(t.integrator), io.io(t.stepper), io.io(t.precision), io.io(t.dt_s);
  io.io(t.steps_per_second);
  io.io(t.stable_dt_s), io.io(t.predicted_stable_dt_s), io.io(t.realtime_factor);
  io.io(t.settle_time_s), io.io(t.settled), io.io(t.settle_distance);
  io.io(t.ms_per_60hz_frame);
}

template <typename Io, typename P>
void parameter_fields(Io& io, P& p) {  // VariantParameters
  long long n = static_cast<long long>(p.spring_groups.size());
  io.io(n);
  std::vector<std::pair<std::string, VariantParameters::SpringGroup>> groups(
      p.spring_groups.begin(), p.spring_groups.end());
  groups.resize(static_cast<std::size_t>(n));
  for (auto& [name, g] : groups)
    io.io(name), io.io(g.springs), io.io(g.mean_stiffness_n_per_m), io.io(g.mean_damping_n_s_per_m);
  p.spring_groups = {groups.begin(), groups.end()};
  io.io(p.total_mass_kg), io.io(p.anchors), io.io(p.constrained_nodes);
  bool volume = p.volume_preservation.has_value();
  io.io(volume);
  if (volume) {
    if (!p.volume_preservation) p.volume_preservation.emplace();
    io.io(p.volume_preservation->elements), io.io(p.volume_preservation->mean_modulus_pa);
  }
  io.io(p.youngs_modulus_min_pa), io.io(p.youngs_modulus_max_pa);
  n = static_cast<long long>(p.external_files.size());
  io.io(n);
  p.external_files.resize(static_cast<std::size_t>(n));
  for (auto& f : p.external_files)
    io.io(f);
}

template <typename Io, typename S>
void share_fields(Io& io, S& s) {
  io.io(s.variant), io.io(s.timed), io.io(s.tetrahedra), io.io(s.failure_order), io.io(s.failure);
  VariantResult& r = s.result;
  int builtin = r.spec.builtin ? static_cast<int>(*r.spec.builtin) : -1;
  std::string network = r.spec.network.string();
  io.io(builtin), io.io(r.spec.name), io.io(network);
  if (builtin >= 0) r.spec.builtin = static_cast<cases::Variant>(builtin);
  r.spec.network = network;
  io.io(r.name), io.io(r.nodes), io.io(r.springs), io.io(r.refinement_added_nodes);
  timing_fields(io, r.timing);
  parameter_fields(io, r.parameters);
  long long n = static_cast<long long>(r.warnings.size());
  io.io(n);
  r.warnings.resize(static_cast<std::size_t>(n));
  for (auto& w : r.warnings)
    warning_fields(io, w);
  n = static_cast<long long>(s.load_indices.size());
  io.io(n);
  s.load_indices.resize(static_cast<std::size_t>(n));
  r.loads.resize(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < s.load_indices.size(); ++i) {
    io.io(s.load_indices[i]);
    r.loads[i].name = r.name;
    load_fields(io, r.loads[i]);
  }
}

}  // namespace

std::string to_bytes(std::vector<VariantShare> shares) {
  Writer w;
  w.io(static_cast<long long>(shares.size()));
  for (VariantShare& s : shares)
    share_fields(w, s);
  return w.p.bytes();
}

std::vector<VariantShare> shares_from_bytes(const std::string& bytes) {
  Reader r{Unpacker(bytes)};
  long long n = 0;
  r.io(n);
  std::vector<VariantShare> shares(static_cast<std::size_t>(n));
  for (VariantShare& s : shares)
    share_fields(r, s);
  if (!r.u.done()) throw std::runtime_error("a rank's variant results have bytes left over");
  return shares;
}

}  // namespace msfem::compare::detail
