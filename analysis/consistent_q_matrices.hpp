// Consistent matrices Q^m of seed 002 (Kuhn): eq 11 recursion from the seed Q^2 = 0 (eq 12);
// Q^m_pq depends only on the directed separation (q - p) mod m (consistency, eq 10). Used in
// eq 7: L^i = 1/(6 A^i) sum_{j1,j2} Q^m_{j1 j2} vhat^{i,j1} (x) b^{i,j2}.
// Closed form of the result: Q^m(s) = 3 (m - 2 s) / m for s = 1..m-1, Q^m(0) = 0. Note Table 1
// of the seed prints Q^5(4) = -3/5; antisymmetry and the recursion give -9/5 (see docs/strain.md).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace gs::analysis {

/// Q^m (m x m) by the recursion eq 11 from Q^2 = 0. Throws std::invalid_argument for m < 2.
Eigen::MatrixXd consistent_q_matrix(int m);

/// Row 0 of Q^m (the value for each directed separation 0..m-1), by eq 11.
std::vector<double> consistent_q_separations(int m);

}  // namespace gs::analysis
