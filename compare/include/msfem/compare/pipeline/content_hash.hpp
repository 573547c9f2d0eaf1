#pragma once
// 64-bit FNV-1a over bytes: the FEM cache keys and the regression baselines' case and mesh hashes.
// Not cryptographic; it only has to change when what it covers changes.

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <string>

namespace msfem::compare {

class ContentHash {
 public:
  ContentHash& bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i)
      hash_ = (hash_ ^ p[i]) * 1099511628211ull;
    return *this;
  }
  ContentHash& text(const std::string& s) { return bytes(s.data(), s.size() + 1); }
  ContentHash& number(double x) { return bytes(&x, sizeof x); }
  /// Every entry as a double, row by row (so int and double arrays of equal values agree).
  template <typename Derived>
  ContentHash& matrix(const Eigen::DenseBase<Derived>& m) {
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      for (Eigen::Index j = 0; j < m.cols(); ++j)
        number(static_cast<double>(m(i, j)));
    return *this;
  }
  /// 16 hex digits.
  std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash_));
    return text;
  }

 private:
  std::uint64_t hash_ = 14695981039346656037ull;
};

}  // namespace msfem::compare
