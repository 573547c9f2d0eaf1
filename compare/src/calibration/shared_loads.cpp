// msfem calibrate under mpirun: the training and test loads shared out among the ranks.
#include "calibration/shared_loads.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <tuple>

#include "msfem/cases/errors.hpp"
#include "msfem/compare/pipeline/ranks.hpp"

namespace msfem::compare {
namespace {

nlohmann::json errors_json(std::size_t i, const LoadErrors& e) {
  return {{"i", i},
          {"load", e.load},
          {"rel_l2", e.rel_l2_error},
          {"mean", e.mean_error_over_max_disp},
          {"force_error", e.reaction_force_rel_error},
          {"force", {e.tool_force.x(), e.tool_force.y(), e.tool_force.z()}},
          {"patch", e.tool_patch_nodes}};
}

LoadErrors errors_from_json(const nlohmann::json& j) {
  LoadErrors e;
  j.at("load").get_to(e.load);
  j.at("rel_l2").get_to(e.rel_l2_error);
  j.at("mean").get_to(e.mean_error_over_max_disp);
  j.at("force_error").get_to(e.reaction_force_rel_error);
  for (int c = 0; c < 3; ++c)
    e.tool_force[c] = j.at("force").at(c).get<double>();
  j.at("patch").get_to(e.tool_patch_nodes);
  return e;
}

}  // namespace

bool owns_load(std::size_t i) {
  return static_cast<int>(i % static_cast<std::size_t>(ranks::count())) == ranks::index();
}

std::vector<LoadErrors> shared_errors(std::size_t loads,
                                      const std::function<LoadErrors(std::size_t)>& one) {
  std::vector<LoadErrors> errors(loads);
  if (ranks::count() == 1) {
    for (std::size_t i = 0; i < loads; ++i)
      errors[i] = one(i);
    return errors;
  }
  nlohmann::json own = nlohmann::json::array();
  for (std::size_t i = 0; i < loads; ++i) {
    if (!owns_load(i)) continue;
    try {
      own.push_back(errors_json(i, one(i)));
    } catch (const std::exception& e) {
      const bool input = dynamic_cast<const cases::InputError*>(&e) != nullptr;
      own.push_back({{"i", i}, {"failure", e.what()}, {"input", input}});
      break;
    }
  }
  std::vector<std::tuple<std::size_t, std::string, bool>> failures;
  for (const nlohmann::json& part : ranks::gather_json_on_all(own))
    for (const auto& entry : part) {
      const auto i = entry.at("i").get<std::size_t>();
      if (entry.contains("failure"))
        failures.emplace_back(i, entry.at("failure").get<std::string>(),
                              entry.at("input").get<bool>());
      else
        errors[i] = errors_from_json(entry);
    }
  if (failures.empty()) return errors;
  const auto& [load, what, input] = *std::min_element(failures.begin(), failures.end());
  if (input) throw cases::InputError(what);
  throw std::runtime_error(what);
}

// Every load's last equilibrium on every rank, from the rank that solved it.
std::vector<Eigen::VectorXd> shared_equilibria(const std::vector<Eigen::VectorXd>& mine) {
  if (ranks::count() == 1) return mine;
  nlohmann::json own = nlohmann::json::array();
  for (std::size_t i = 0; i < mine.size(); ++i)
    if (owns_load(i))
      own.push_back(
          {{"i", i}, {"x", std::vector<double>(mine[i].data(), mine[i].data() + mine[i].size())}});
  std::vector<Eigen::VectorXd> x(mine.size());
  for (const nlohmann::json& part : ranks::gather_json_on_all(own))
    for (const auto& entry : part) {
      const auto values = entry.at("x").get<std::vector<double>>();
      x[entry.at("i").get<std::size_t>()] = Eigen::Map<const Eigen::VectorXd>(
          values.data(), static_cast<Eigen::Index>(values.size()));
    }
  return x;
}

}  // namespace msfem::compare
