#pragma once
// One number in a report's text, printf-formatted ("%.4g"): report.md and calibration.md.

#include <cstdio>
#include <string>

namespace msfem::compare {

inline std::string fmt(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace msfem::compare
