#pragma once

#include "msfem/cases/case_parameters.hpp"

namespace msfem::cases {

/// Makes the case's relative paths (the surface or its image or network, the modulus image, the
/// networks) relative to `c.file`'s folder, and refuses a network file that does not exist.
void resolve_paths(CaseParameters& c);

}  // namespace msfem::cases
