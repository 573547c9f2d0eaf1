#include "msfem/cases/units.hpp"

#include "msfem/cases/setting_names.hpp"

namespace msfem::cases {

LengthUnit parse_length_unit(std::string_view name) {
  return parse_setting<LengthUnit>(name, "length unit");
}

std::string to_string(LengthUnit unit) {
  return name_of(unit);
}

double metres_per(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::metre:
      return 1.0;
    case LengthUnit::centimetre:
      return 1e-2;
    case LengthUnit::millimetre:
      return 1e-3;
  }
  throw std::logic_error("metres_per: invalid LengthUnit");
}

}  // namespace msfem::cases
