// The replay itself: the model on one thread at its own rate, the haptic loop on another at the
// device's, joined by a local contact model (docs/haptics.md).
#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <memory>
#include <thread>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/compare/pipeline/haptic.hpp"
#include "msfem/compare/pipeline/progress.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/stepper.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;

// What the model hands the haptic loop after each batch of steps (Cavusoglu & Tendick 2000's
// local model, reduced to the tool): the force at the centre the model stepped with, and the
// normal stiffness that its last two answers imply, for the device's motion in between.
struct LocalContactModel {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double stiffness = 0.0;  // N/m along the normal

  // The tissue pushes, never pulls: the normal part is first-order in the device's motion and
  // clipped at zero; the tangential part is held.
  Eigen::Vector3d render(const Eigen::Vector3d& c) const {
    const double push0 = force.dot(normal);
    if (!(push0 > 0.0)) return Eigen::Vector3d::Zero();
    const double push = std::max(0.0, push0 - stiffness * (c - center).dot(normal));
    return force + (push - push0) * normal;
  }
};

// A single writer and a single reader, neither waiting on the other: the writer fills the slot
// the reader is not told to read, then points the reader at it; the reader checks its copy by the
// slot's sequence number. A plain seqlock would let the haptic thread (real-time, on one core)
// spin on a model thread it pre-empted half way through a write.
class LocalModelMailbox {
 public:
  void publish(const LocalContactModel& m) {
    const int w = 1 - current_.load(std::memory_order_relaxed);
    Slot& slot = slots_[w];
    // Odd before any value changes: the fence keeps the stores below from being seen before it.
    const unsigned sequence = slot.sequence.load(std::memory_order_relaxed);
    slot.sequence.store(sequence + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    const std::array<double, 10> v = {{m.center.x(), m.center.y(), m.center.z(), m.force.x(),
                                       m.force.y(), m.force.z(), m.normal.x(), m.normal.y(),
                                       m.normal.z(), m.stiffness}};
    for (std::size_t i = 0; i < v.size(); ++i)
      slot.values[i].store(v[i], std::memory_order_relaxed);
    slot.sequence.store(sequence + 2, std::memory_order_release);
    current_.store(w, std::memory_order_release);
  }
  LocalContactModel read() const {
    std::array<double, 10> v;
    for (;;) {
      const Slot& slot = slots_[current_.load(std::memory_order_acquire)];
      const unsigned before = slot.sequence.load(std::memory_order_acquire);
      if (before & 1u) continue;  // the writer moved on to this slot: read the other one
      for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = slot.values[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (slot.sequence.load(std::memory_order_relaxed) == before) break;
    }
    return {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}, v[9]};
  }

 private:
  struct Slot {
    std::atomic<unsigned> sequence{0};
    std::array<std::atomic<double>, 10> values{};
  };
  Slot slots_[2];
  std::atomic<int> current_{0};
};

// The device's position as the haptic loop last read it, for the model's next batch.
class DevicePosition {
 public:
  void store(const Eigen::Vector3d& c) {
    for (int i = 0; i < 3; ++i)
      xyz_[i].store(c[i], std::memory_order_relaxed);
  }
  Eigen::Vector3d load() const {
    return {xyz_[0].load(std::memory_order_relaxed), xyz_[1].load(std::memory_order_relaxed),
            xyz_[2].load(std::memory_order_relaxed)};
  }

 private:
  std::array<std::atomic<double>, 3> xyz_{};
};

double group_factor(const cases::CaseParameters& p, const std::string& group) {
  double factor = 1.0;  // scale_groups applies every entry that names the group
  for (const auto& [name, f] : p.mass_spring.group_scales)
    if (name == group) factor *= f;
  return factor;
}

// The model becomes what the case with the change would have built: its groups' stiffness, its
// masses from the density, and (for msfem's own variants, or when the ratio itself changes) its
// dampers from the damping ratio.
void apply_change(ms::MassSpringModel& model, const VariantSpec& spec,
                  const cases::CaseParameters& before, const cases::CaseParameters& after) {
  for (const std::string& group : model.network().spring_group_names) {
    const double ratio = group_factor(after, group) / group_factor(before, group);
    if (ratio != 1.0) model.scale_group_stiffness(group, ratio);
  }
  const double mass_ratio = after.material.density_kg_per_m3 / before.material.density_kg_per_m3;
  if (mass_ratio != 1.0) model.set_masses(model.network().masses * mass_ratio);
  if (spec.builtin || after.mass_spring.damping_ratio != before.mass_spring.damping_ratio)
    model.set_damping(ms::damping_for_ratio(model.network(), after.mass_spring.damping_ratio));
}

// Real-time scheduling where the system grants it, and a timer slack of 1 µs: a haptic thread
// that wakes 50 µs late (the default slack) spends a tenth of its period waiting.
bool ask_for_realtime() {
  prctl(PR_SET_TIMERSLACK, 1000UL, 0, 0, 0);
  sched_param parameter{};
  parameter.sched_priority = std::min(80, sched_get_priority_max(SCHED_FIFO));
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameter) == 0;
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size()))) - 1;
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(std::min(k, values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

struct Shared {
  LocalModelMailbox mailbox;
  DevicePosition device;
  std::atomic<bool> stop{false};
  std::exception_ptr failure;
  Clock::time_point start;
};

// The haptic loop: one tick per period against the wall clock; each reads the device (here the
// path), renders the latest local model and records the tick.
void haptic_loop(Shared& shared, const ToolPath& path, const HapticSettings& settings,
                 HapticReplay& out) {
  out.realtime_priority = ask_for_realtime();
  const auto ticks = static_cast<int>(std::floor(settings.seconds * settings.rate_hz)) + 1;
  const auto period = std::chrono::duration<double>(1.0 / settings.rate_hz);
  std::vector<double> latency_ms(static_cast<std::size_t>(ticks));
  out.trace.resize(static_cast<std::size_t>(ticks));
  int done = 0;
  auto last_finished = shared.start;
  for (int i = 0; i < ticks && !shared.stop.load(std::memory_order_relaxed); ++i, ++done) {
    const auto due = shared.start + std::chrono::duration_cast<Clock::duration>(i * period);
    std::this_thread::sleep_until(due);
    const double t = i / settings.rate_hz;
    const Eigen::Vector3d c = path.at(path.start() + t);
    shared.device.store(c);
    const Eigen::Vector3d force = shared.mailbox.read().render(c);
    const auto finished = Clock::now();
    last_finished = finished;
    out.trace[static_cast<std::size_t>(i)] = {t, c, force};
    const double late = std::chrono::duration<double>(finished - due).count();
    latency_ms[static_cast<std::size_t>(i)] = 1e3 * late;
    if (late > period.count()) {
      ++out.deadline_misses;
      if (out.miss_times_s.size() < 100) out.miss_times_s.push_back(t);
    }
  }
  shared.stop.store(true);
  out.ticks = done;
  out.trace.resize(static_cast<std::size_t>(done));
  latency_ms.resize(static_cast<std::size_t>(done));
  // Ticks after the first over the time from the first one's due time to the last one's end.
  const double span = std::chrono::duration<double>(last_finished - shared.start).count();
  out.rate_hz = done > 1 && span > 0 ? (done - 1) / span : 0.0;
  out.tick = {percentile(latency_ms, 0.5), percentile(latency_ms, 0.99),
              latency_ms.empty() ? 0.0 : *std::max_element(latency_ms.begin(), latency_ms.end())};
}

// The model loop: steps to keep up with the wall clock (never more than half a millisecond's
// worth per batch, so that the tool moves with the device), then hands over a local model.
void model_loop(Shared& shared, BuiltVariant& variant, ms::ToolContact& contact,
                ms::Stepper& stepper, double dt, const cases::CaseParameters& parameters,
                const std::vector<ParameterChange>& changes, HapticReplay& out) {
  ms::MassSpringModel& model = *variant.model;
  const double max_lag_s = 0.02;  // a model this far behind drops the debt: it runs slow motion
  double t_model = 0.0, step_s = dt, busy_s = 0.0;
  long long steps = 0, updates = 0;
  std::size_t next_change = 0;
  const cases::CaseParameters* current = &parameters;
  LocalContactModel last;
  bool have_last = false;
  while (!shared.stop.load(std::memory_order_relaxed)) {
    const double now = seconds_since(shared.start);
    for (; next_change < changes.size() && changes[next_change].t_s <= now; ++next_change) {
      apply_change(model, variant.spec, *current, changes[next_change].after);
      stepper.update_parameters(model);
      current = &changes[next_change].after;
      out.changes_applied.emplace_back(now,
                                       changes[next_change].key + "=" + changes[next_change].value);
    }
    const Eigen::Vector3d c = shared.device.load();
    contact.move_tool(c);
    const double debt = now - t_model;
    if (debt < dt) {
      std::this_thread::sleep_for(std::chrono::duration<double>(std::min(dt - debt, 2e-4)));
      continue;
    }
    const int batch_cap = std::max(1, static_cast<int>(5e-4 / step_s));
    const int count = std::clamp(static_cast<int>(debt / dt), 1, batch_cap);
    const auto batch_start = Clock::now();
    stepper.step(dt, count);
    const double batch_s = seconds_since(batch_start);
    busy_s += batch_s;
    step_s = batch_s / count;
    steps += count;
    t_model = std::max(t_model + count * dt, now - max_lag_s);
    const ms::State s = stepper.state();
    LocalContactModel m;
    m.center = c;
    m.force = ms::contact_reaction_force(model, s.x);
    if (!m.force.allFinite() || !s.x.allFinite())
      throw ms::DivergenceError("variant " + variant.name + " diverged during the replay at t = " +
                                    std::to_string(now) + " s (dt " + std::to_string(dt) + " s)",
                                dt, 0.5 * dt);
    if (m.force.norm() > 0.0) m.normal = m.force.normalized();
    if (have_last) {
      if (!(m.force.norm() > 0.0)) m.normal = last.normal;
      m.stiffness = last.stiffness;
      const double moved = (m.center - last.center).dot(m.normal);
      if (std::abs(moved) > 1e-6) {
        const double k = -(m.force - last.force).dot(m.normal) / moved;
        if (k >= 0.0 && k <= contact.penalty_stiffness()) m.stiffness = k;
      }
    }
    shared.mailbox.publish(m);
    last = m;
    have_last = true;
    ++updates;
  }
  const double wall = std::max(seconds_since(shared.start), 1e-9);
  out.model_rate_hz = steps / wall;
  out.model_update_hz = updates / wall;
  out.realtime_factor = steps * dt / wall;
  out.model_busy_fraction = busy_s / wall;
  out.model_capacity_hz = busy_s > 0 ? steps / busy_s : 0.0;
}

}  // namespace

const std::vector<std::string>& changeable_keys() {
  static const std::vector<std::string> keys = {"mass spring/group scales",
                                                "mass spring/damping ratio", "material/density"};
  return keys;
}

std::vector<ParameterChange> parse_parameter_changes(const std::vector<std::string>& options,
                                                     const std::filesystem::path& case_file,
                                                     std::vector<std::string> sets,
                                                     double last_tick_s) {
  std::vector<ParameterChange> changes;
  for (const std::string& option : options) {
    const std::string what = "--set-at '" + option + "'";
    const auto colon = option.find(':');
    const auto equals = option.find('=', colon == std::string::npos ? 0 : colon);
    if (colon == std::string::npos || equals == std::string::npos)
      throw cases::InputError(what + ": expected T:SECTION/KEY=VALUE (T in seconds of the replay)");
    ParameterChange change;
    char* end = nullptr;
    const std::string time = option.substr(0, colon);
    change.t_s = std::strtod(time.c_str(), &end);
    if (time.empty() || end != time.c_str() + time.size() || !std::isfinite(change.t_s) ||
        change.t_s < 0 || change.t_s > last_tick_s)
      throw cases::InputError(what + ": the time '" + time +
                              "' is not a number of seconds in [0, " + std::to_string(last_tick_s) +
                              "] (the replay's last tick)");
    change.key = option.substr(colon + 1, equals - colon - 1);
    change.value = option.substr(equals + 1);
    const auto& keys = changeable_keys();
    if (std::find(keys.begin(), keys.end(), change.key) == keys.end()) {
      std::string list;
      for (const auto& k : keys)
        list += (list.empty() ? "" : ", ") + k;
      throw cases::InputError(what + ": '" + change.key +
                              "' cannot change while the model runs; these can: " + list);
    }
    changes.push_back(std::move(change));
  }
  std::stable_sort(changes.begin(), changes.end(),
                   [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  cases::CaseParameters previous = cases::read_case(case_file, sets);
  for (ParameterChange& change : changes) {
    sets.push_back(change.key + "=" + change.value);
    change.after = cases::read_case(case_file, sets);  // checks the value as the case file would
    if (group_factor(change.after, volume_group) != group_factor(previous, volume_group))
      throw cases::InputError("--set-at '" + change.key + "=" + change.value +
                              "': the volume group is fixed while the model runs (its elements' "
                              "modulus is set when the model is built)");
    check_group_names(change.after);
    previous = change.after;
  }
  return changes;
}

namespace {

// One replay at model step dt, from rest, the tool at the path's start.
HapticReplay replay_once(BuiltVariant& variant, const cases::CaseParameters& parameters,
                         const ToolPath& path, const HapticSettings& settings,
                         const std::vector<ParameterChange>& changes, double dt) {
  ms::MassSpringModel& model = *variant.model;
  HapticReplay out;
  out.name = variant.name;
  out.integrator = ms::to_string(parameters.timing.integrator);
  out.model_dt_s = dt;
  const std::shared_ptr<ms::ToolContact> contact = model.contact()->clone();
  contact->move_tool(path.at(path.start()));
  model.set_field<ms::ToolContact>(contact);
  const int cores = static_cast<int>(std::max(2u, std::thread::hardware_concurrency()));
  out.model_threads = settings.model_threads > 0 ? settings.model_threads : std::min(2, cores - 1);
  const auto stepper =
      ms::make_stepper(model, parameters.timing.integrator, ms::initial_state(model),
                       {out.model_threads, parameters.timing.single_precision});
  out.stepper = stepper->name();
  out.precision = stepper->precision();

  Shared shared;
  shared.device.store(path.at(path.start()));
  shared.mailbox.publish(
      {path.at(path.start()), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0});
  shared.start = Clock::now() + std::chrono::milliseconds(20);  // both threads up before tick 0
  std::exception_ptr haptic_failure;
  std::thread haptic([&] {
    try {
      haptic_loop(shared, path, settings, out);
    } catch (...) {
      haptic_failure = std::current_exception();
      shared.stop.store(true);
    }
  });
  try {
    model_loop(shared, variant, *contact, *stepper, dt, parameters, changes, out);
  } catch (...) {
    shared.failure = std::current_exception();
    shared.stop.store(true);
  }
  haptic.join();
  if (shared.failure) std::rethrow_exception(shared.failure);
  if (haptic_failure) std::rethrow_exception(haptic_failure);
  return out;
}

}  // namespace

HapticReplay replay_variant(BuiltVariant& variant, const cases::CaseParameters& parameters,
                            const ToolPath& path, const HapticSettings& settings,
                            const std::vector<ParameterChange>& changes) {
  if (!variant.model->contact())
    throw std::logic_error("replay_variant: the variant was built without its tool's contact");
  // The step msfem run times, found with the tool at the case's full depth (the stiffest
  // contact), and no larger than what the model after each --set-at change keeps stable.
  const ms::MassSpringModel original = *variant.model;
  double dt = timed_dt(original, parameters.timing);
  if (parameters.timing.dt_s <= 0 &&
      parameters.timing.integrator != ms::IntegratorKind::implicit_euler) {
    ms::MassSpringModel changed = original;
    const cases::CaseParameters* before = &parameters;
    for (const ParameterChange& change : changes) {
      apply_change(changed, variant.spec, *before, change.after);
      before = &change.after;
      dt = std::min(dt, timed_dt(changed, parameters.timing));
    }
  }
  // As msfem run does: the stable step is bisected on the generic integrator; the fast kernels
  // under a moving contact may need half of it. Halve and replay again, at most twice.
  for (int attempt = 0;; ++attempt) {
    try {
      HapticReplay out = replay_once(variant, parameters, path, settings, changes, dt);
      out.halvings = attempt;
      return out;
    } catch (const ms::DivergenceError&) {
      if (parameters.timing.dt_s > 0 || attempt == 2) throw;
      *variant.model = original;
      dt *= 0.5;
    }
  }
}

}  // namespace msfem::compare
