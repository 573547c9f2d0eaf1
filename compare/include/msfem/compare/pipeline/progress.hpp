#pragma once

#include <chrono>
#include <string>

namespace msfem::compare {

/// Progress lines on stderr ("stage, percent, time left"); silent when quiet.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet) {}
  void stage(const std::string& what) const;
  /// Item `done` of `total` finished, `elapsed_s` since the stage began.
  void advance(const std::string& what, int done, int total, double elapsed_s) const;

 private:
  bool quiet_;
};

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

}  // namespace msfem::compare
