// msfem calibrate under mpirun: the training and test loads shared out among the ranks.
#include "calibration/shared_loads.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>

#include "msfem/cases/errors.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "pipeline/byte_packing.hpp"

namespace msfem::compare {
namespace {

template <typename Io, typename E>
void error_fields(Io& io, E& e) {  // CalibrationErrors
  detail::load_error_fields(io, e);
  io.io(e.load), io.io(e.tool_patch_nodes);
}

}  // namespace

bool owns_load(std::size_t i) {
  return static_cast<int>(i % static_cast<std::size_t>(ranks::count())) == ranks::index();
}

std::vector<CalibrationErrors> shared_errors(
    std::size_t loads, const std::function<CalibrationErrors(std::size_t)>& one) {
  std::vector<CalibrationErrors> errors(loads);
  if (ranks::count() == 1) {
    for (std::size_t i = 0; i < loads; ++i)
      errors[i] = one(i);
    return errors;
  }
  // Each owned load: its index, whether it failed, then its errors or the failure.
  detail::Writer own;
  for (std::size_t i = 0; i < loads; ++i) {
    if (!owns_load(i)) continue;
    long long index = static_cast<long long>(i);
    try {
      CalibrationErrors e = one(i);
      char failed = 0;
      own.io(index), own.io(failed), error_fields(own, e);
    } catch (const std::exception& e) {
      char failed = 1, input = dynamic_cast<const cases::InputError*>(&e) != nullptr;
      own.io(index), own.io(failed), own.io(std::string(e.what())), own.io(input);
      break;
    }
  }
  std::vector<std::tuple<std::size_t, std::string, bool>> failures;
  for (const std::string& part : ranks::gather_on_all(own.p.bytes())) {
    detail::Reader from{detail::Unpacker(part)};
    while (!from.u.done()) {
      long long index = 0;
      char failed = 0;
      from.io(index), from.io(failed);
      const auto i = static_cast<std::size_t>(index);
      if (!failed) {
        error_fields(from, errors.at(i));
        continue;
      }
      std::string what;
      char input = 0;
      from.io(what), from.io(input);
      failures.emplace_back(i, what, input != 0);
    }
  }
  if (failures.empty()) return errors;
  const auto& [load, what, input] = *std::min_element(failures.begin(), failures.end());
  if (input) throw cases::InputError(what);
  throw std::runtime_error(what);
}

// Every load's last equilibrium on every rank, from the rank that solved it.
std::vector<Eigen::VectorXd> shared_equilibria(const std::vector<Eigen::VectorXd>& mine) {
  if (ranks::count() == 1) return mine;
  detail::Writer own;
  for (std::size_t i = 0; i < mine.size(); ++i)
    if (owns_load(i)) {
      long long index = static_cast<long long>(i);
      own.io(index), own.io(mine[i]);
    }
  std::vector<Eigen::VectorXd> x(mine.size());
  for (const std::string& part : ranks::gather_on_all(own.p.bytes())) {
    detail::Reader from{detail::Unpacker(part)};
    while (!from.u.done()) {
      long long index = 0;
      from.io(index);
      from.io(x.at(static_cast<std::size_t>(index)));
    }
  }
  return x;
}

}  // namespace msfem::compare
