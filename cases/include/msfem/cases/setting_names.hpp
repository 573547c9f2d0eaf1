#pragma once
// The names of every enumerated case setting, one table per enumeration. The case language's
// Selection patterns, the case-file and command-line parsers and the names written into results
// come from these tables and nowhere else (step-44's Parameters structs, with the list in one
// place): name_of(), parse_setting<Enum>(), selection_of<Enum>() and all_values<Enum>().

#include <string>
#include <string_view>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/massspring/name_table.hpp"

namespace msfem::cases {

template <typename Enum, std::size_t N>
using NameTable = massspring::NameTable<Enum, N>;

inline constexpr NameTable<Variant, 4> variant_table{{{
    {Variant::three_tier, "three_tier"},
    {Variant::single_layer, "single_layer"},
    {Variant::tet_edges, "tet_edges"},
    {Variant::skeleton, "skeleton"},
}}};

inline constexpr NameTable<FemSolver, 3> fem_solver_table{{{
    {FemSolver::cg_gamg, "cg_gamg"},
    {FemSolver::cg_boomeramg, "cg_boomeramg"},
    {FemSolver::mumps, "mumps"},
}}};

inline constexpr NameTable<CalibrationModel, 2> calibration_model_table{{{
    {CalibrationModel::nonlinear, "nonlinear"},
    {CalibrationModel::linear, "linear"},
}}};

inline constexpr NameTable<massspring::TetStiffnessRule, 2> stiffness_model_table{{{
    {massspring::TetStiffnessRule::lloyd, "lloyd"},
    {massspring::TetStiffnessRule::van_gelder, "van_gelder"},
}}};

inline constexpr NameTable<massspring::InnerTierMethod, 3> inner_tiers_table{{{
    {massspring::InnerTierMethod::scaling, "scaled"},
    {massspring::InnerTierMethod::normal_offset, "offset"},
    {massspring::InnerTierMethod::distance_field, "distance_field"},
}}};

inline constexpr NameTable<ToolParameters::Mode, 3> tool_mode_table{{{
    {ToolParameters::Mode::prescribed, "bonded"},
    {ToolParameters::Mode::prescribed, "prescribed"},
    {ToolParameters::Mode::contact, "contact"},
}}};

inline constexpr NameTable<SupportParameters::Kind, 3> support_kind_table{{{
    {SupportParameters::Kind::inner_core, "inner core"},
    {SupportParameters::Kind::half_space, "half space"},
    {SupportParameters::Kind::sphere, "sphere"},
}}};

inline constexpr NameTable<FemParameters::ErrorEstimate, 5> error_estimate_table{{{
    {FemParameters::ErrorEstimate::automatic, "auto"},
    {FemParameters::ErrorEstimate::refine, "refine"},
    {FemParameters::ErrorEstimate::degree, "degree"},
    {FemParameters::ErrorEstimate::lower_degree, "lower_degree"},
    {FemParameters::ErrorEstimate::none, "none"},
}}};

inline constexpr NameTable<LengthUnit, 3> length_unit_table{{{
    {LengthUnit::metre, "m"},
    {LengthUnit::centimetre, "cm"},
    {LengthUnit::millimetre, "mm"},
}}};

// Which table an enumeration has (overload resolution picks it; the argument is a tag).
inline constexpr const auto& names_of(Variant) {
  return variant_table;
}
inline constexpr const auto& names_of(FemSolver) {
  return fem_solver_table;
}
inline constexpr const auto& names_of(CalibrationModel) {
  return calibration_model_table;
}
inline constexpr const auto& names_of(massspring::TetStiffnessRule) {
  return stiffness_model_table;
}
inline constexpr const auto& names_of(massspring::InnerTierMethod) {
  return inner_tiers_table;
}
inline constexpr const auto& names_of(massspring::IntegratorKind) {
  return massspring::integrator_table;
}
inline constexpr const auto& names_of(ToolParameters::Mode) {
  return tool_mode_table;
}
inline constexpr const auto& names_of(SupportParameters::Kind) {
  return support_kind_table;
}
inline constexpr const auto& names_of(FemParameters::ErrorEstimate) {
  return error_estimate_table;
}
inline constexpr const auto& names_of(LengthUnit) {
  return length_unit_table;
}

/// The value's name as a case file writes it.
template <typename Enum>
std::string name_of(Enum value) {
  return names_of(Enum{}).name(value);
}

/// The Selection pattern of a case key ("a|b|c", aliases included).
template <typename Enum>
std::string selection_of() {
  return names_of(Enum{}).names("|");
}

/// Every value, each once, in table order.
template <typename Enum>
std::vector<Enum> all_values() {
  return names_of(Enum{}).values();
}

/// The value named `name`; throws InputError "`where`: unknown value 'x' (a, b, c)" otherwise.
template <typename Enum>
Enum parse_setting(std::string_view name, const std::string& where) {
  const auto& table = names_of(Enum{});
  if (const auto value = table.find(name)) return *value;
  throw InputError(where + ": unknown value '" + std::string(name) + "' (" + table.names(", ") +
                   ")");
}

}  // namespace msfem::cases
