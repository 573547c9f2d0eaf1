#include "msfem/compare/pipeline/progress.hpp"

#include <cstdio>

namespace msfem::compare {

void Progress::stage(const std::string& what) const {
  if (!quiet_) std::fprintf(stderr, "msfem: %s\n", what.c_str());
}

void Progress::advance(const std::string& what, int done, int total, double elapsed_s) const {
  if (quiet_) return;
  const double left = done > 0 ? elapsed_s / done * (total - done) : 0.0;
  std::fprintf(stderr, "msfem: %s %d/%d (%.0f %%, %.1f s, about %.0f s left)\n", what.c_str(), done,
               total, 100.0 * done / total, elapsed_s, left);
}

}  // namespace msfem::compare
