// Seed 002 (Kuhn) eq 10-12: consistent Q^m matrices, Table 1 for m = 3..6.
#include "consistent_q_matrices.hpp"

#include <stdexcept>
#include <string>

namespace gs::analysis {

std::vector<double> consistent_q_separations(int m) {
  if (m < 2) throw std::invalid_argument("Q^m needs m >= 2 (" + std::to_string(m) + ")");
  std::vector<double> q(2, 0.0);  // eq 12: Q^2 = 0
  for (int mm = 2; mm < m; ++mm) {
    // eq 11: from Q^mm (separations mod mm) to Q^{mm+1} (separations s = q - p mod mm+1).
    std::vector<double> next(static_cast<std::size_t>(mm + 1), 0.0);
    const auto old = [&](int s) { return q[static_cast<std::size_t>(((s % mm) + mm) % mm)]; };
    const double inv = 1.0 / (mm + 1);
    for (int s = 1; s <= mm; ++s) {
      double v;
      if (s == 1) {
        v = inv * (mm * old(1) + 3.0);
      } else if (s == mm) {
        // Printed as Q^m_pq with q - p = m (= 0 mod m), which would give -3/(m+1) and contradict
        // Table 1 (m = 4: -6/4). The reading that reproduces Table 1, and the antisymmetry
        // Q_pq = -Q_qp that every exact Q^m has, is Q^m_{p,q-1} (separation m - 1).
        v = inv * (mm * old(mm - 1) - 3.0);
      } else {
        // Q^m_{pq} has separation s (mod m), Q^m_{p,q-1} separation s - 1.
        v = inv * ((mm + 1 - s) * old(s) + s * old(s - 1));
      }
      next[static_cast<std::size_t>(s)] = v;
    }
    q = std::move(next);
  }
  return q;
}

Eigen::MatrixXd consistent_q_matrix(int m) {
  const auto sep = consistent_q_separations(m);
  Eigen::MatrixXd out(m, m);
  for (int p = 0; p < m; ++p)
    for (int qq = 0; qq < m; ++qq)
      out(p, qq) = sep[static_cast<std::size_t>(((qq - p) % m + m) % m)];
  return out;
}

}  // namespace gs::analysis
