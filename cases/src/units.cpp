#include "msfem/cases/units.hpp"

#include "msfem/cases/errors.hpp"

namespace msfem::cases {

LengthUnit parse_length_unit(std::string_view name) {
  if (name == "m") return LengthUnit::metre;
  if (name == "cm") return LengthUnit::centimetre;
  if (name == "mm") return LengthUnit::millimetre;
  throw InputError("unknown length unit '" + std::string(name) + "' (expected m, cm or mm)");
}

std::string to_string(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::metre:
      return "m";
    case LengthUnit::centimetre:
      return "cm";
    case LengthUnit::millimetre:
      return "mm";
  }
  throw std::logic_error("to_string: invalid LengthUnit");
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
