#pragma once
// A number as the model's error messages print it.

#include <sstream>
#include <string>

namespace msfem::massspring::detail {

inline std::string number_text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace msfem::massspring::detail
