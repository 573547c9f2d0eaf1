#pragma once

#include <string>
#include <string_view>

namespace msfem::cases {

/// Length units a surface file may be written in. Everything inside msfem is SI (metres); a unit is
/// named only where a file is read or written.
enum class LengthUnit { metre, centimetre, millimetre };

/// Parses "m", "cm" or "mm"; throws InputError naming the value otherwise.
LengthUnit parse_length_unit(std::string_view name);

/// "m", "cm" or "mm".
std::string to_string(LengthUnit unit);

/// Metres per unit: 1, 1e-2 or 1e-3.
double metres_per(LengthUnit unit);

}  // namespace msfem::cases
