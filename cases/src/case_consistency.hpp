#pragma once

#include "msfem/cases/case_parameters.hpp"

namespace msfem::cases {

/// Refuses (InputError, naming the key) a case whose keys each pass their own pattern but not each
/// other: a setting that would be ignored, or a value the rest of the case makes meaningless.
void check_consistency(const CaseParameters& c);

}  // namespace msfem::cases
