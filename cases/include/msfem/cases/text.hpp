#pragma once
// The one way msfem's readers trim a field, a list entry or a line of text.

#include <string>

namespace msfem::cases {

/// `text` without its leading and trailing blanks: spaces, tabs, and a CRLF file's line ends.
inline std::string trimmed(const std::string& text) {
  const char* blanks = " \t\r\n";
  const auto first = text.find_first_not_of(blanks);
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(blanks) - first + 1);
}

}  // namespace msfem::cases
