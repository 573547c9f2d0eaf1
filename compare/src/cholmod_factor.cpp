#include "cholmod_factor.hpp"

#include <Eigen/CholmodSupport>

namespace msfem::compare {
namespace {

class CholmodFactor final : public massspring::SparseSpdFactor {
 public:
  // An indefinite tangent is an expected outcome the solver handles (it falls back to the definite
  // linearisation), not something CHOLMOD should print: by default it writes a warning to stdout,
  // which would corrupt `--json` output.
  CholmodFactor() { llt_.cholmod().print = 0; }
  void analyze(const Eigen::SparseMatrix<double>& k) override { llt_.analyzePattern(k); }
  bool factorize(const Eigen::SparseMatrix<double>& k) override {
    llt_.factorize(k);
    return llt_.info() == Eigen::Success;  // CHOLMOD stops at the first non-positive pivot
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const override { return llt_.solve(r); }

 private:
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> llt_;
};

}  // namespace

std::function<std::unique_ptr<massspring::SparseSpdFactor>()> cholmod_factorization() {
  return [] { return std::make_unique<CholmodFactor>(); };
}

}  // namespace msfem::compare
