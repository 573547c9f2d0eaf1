#pragma once

#include <stdexcept>
#include <string>

namespace msfem::massspring {

/// Bad model input: a negative or non-finite stiffness, a non-positive mass or time step, a
/// zero-length spring, an index out of range. The message is one line naming the item at fault
/// ("spring 12: stiffness -3 must be finite and >= 0").
class ModelError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A dynamic run that blew up (non-finite state or energy growth). Carries the time step that
/// failed and an estimate of the stable one, which the message states.
class DivergenceError : public std::runtime_error {
 public:
  DivergenceError(const std::string& message, double failed_dt, double stable_dt)
      : std::runtime_error(message), failed_dt_(failed_dt), stable_dt_(stable_dt) {}
  double failed_dt() const { return failed_dt_; }
  double stable_dt() const { return stable_dt_; }

 private:
  double failed_dt_;
  double stable_dt_;
};

}  // namespace msfem::massspring
