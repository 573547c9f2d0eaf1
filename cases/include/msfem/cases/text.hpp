#pragma once
// The one way msfem's readers trim a field, a list entry or a line of text, and split a list.

#include <sstream>
#include <string>
#include <vector>

namespace msfem::cases {

/// `text` without its leading and trailing blanks: spaces, tabs, and a CRLF file's line ends.
inline std::string trimmed(const std::string& text) {
  const char* blanks = " \t\r\n";
  const auto first = text.find_first_not_of(blanks);
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(blanks) - first + 1);
}

/// The entries of a comma-separated list, each trimmed, empty ones left out.
inline std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> entries;
  std::stringstream in(text);
  for (std::string entry; std::getline(in, entry, ',');)
    if (std::string t = trimmed(entry); !t.empty()) entries.push_back(std::move(t));
  return entries;
}

}  // namespace msfem::cases
