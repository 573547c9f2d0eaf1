#include "cholmod_factor.hpp"

#include <Eigen/CholmodSupport>
#include <mutex>

namespace msfem::compare {
namespace {

// One CHOLMOD call at a time in the process: the BLAS under it need not be thread-safe (Debian's
// serial OpenBLAS is not: two workers factorising at once got garbage factors, "singular tangent",
// where one at a time converged). The workers of `msfem run` still overlap everything else.
std::mutex blas_mutex;

class CholmodFactor final : public massspring::SparseSpdFactor {
 public:
  // An indefinite tangent is an expected outcome the solver handles (it falls back to the definite
  // linearisation), not something CHOLMOD should print: by default it writes a warning to stdout,
  // which would corrupt `--json` output.
  CholmodFactor() { llt_.cholmod().print = 0; }
  void analyze(const Eigen::SparseMatrix<double>& k) override {
    const std::lock_guard<std::mutex> lock(blas_mutex);
    llt_.analyzePattern(k);
  }
  bool factorize(const Eigen::SparseMatrix<double>& k) override {
    const std::lock_guard<std::mutex> lock(blas_mutex);
    llt_.factorize(k);
    return llt_.info() == Eigen::Success;  // CHOLMOD stops at the first non-positive pivot
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const override {
    const std::lock_guard<std::mutex> lock(blas_mutex);
    return llt_.solve(r);
  }

 private:
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> llt_;
};

}  // namespace

std::function<std::unique_ptr<massspring::SparseSpdFactor>()> cholmod_factorization() {
  return [] { return std::make_unique<CholmodFactor>(); };
}

}  // namespace msfem::compare
