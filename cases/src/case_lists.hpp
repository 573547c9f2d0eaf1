#pragma once

#include <string>
#include <utility>
#include <vector>

#include "msfem/cases/case_parameters.hpp"

namespace msfem::cases {

/// `mass spring/group scales`: GROUP:FACTOR entries, each factor finite and > 0.
std::vector<std::pair<std::string, double>> parse_group_scales(
    const std::vector<std::string>& list);

/// `mass spring/networks`: NAME=FILE entries separated by ';'. A name is letters, digits and '_',
/// not a built-in variant's and not repeated; paths stay as written (read_case resolves them).
std::vector<MassSpringParameters::Network> parse_networks(const std::string& text);

/// `mass spring/results`: NAME=FILE[,FILE...] entries separated by ';', named as networks are and
/// not as one of `networks`.
std::vector<MassSpringParameters::Result> parse_results(
    const std::string& text, const std::vector<MassSpringParameters::Network>& networks);

}  // namespace msfem::cases
