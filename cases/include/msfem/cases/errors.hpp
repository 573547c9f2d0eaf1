#pragma once

#include <stdexcept>
#include <string>

namespace msfem::cases {

/// Bad input from a user's file or option. The message is one line and names the file and the line,
/// the key or the element at fault, so that the command-line tool can print it as it is and exit
/// non-zero.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace msfem::cases
