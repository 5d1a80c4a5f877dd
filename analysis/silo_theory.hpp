// Slice-method (Janssen) silo loads that seed 004 §5.3.1 compares its DEM bottom force with
// (Table 5.3): Eq 5.1 for the bottom force and Eq 5.2 (Drescher) for the lateral pressure ratio.
//  * Eq 5.1: σ̄z(h) = γ·R/(K·μ)·(1 − exp(−K·μ·h/R)) and P = σ̄z(h)·A, with R the hydraulic
//    radius A/U of the walls that carry friction. In a plane silo of width b with friction on
//    its two side walls only (a slice of a deep silo), the balance of a horizontal slice gives
//    R = b/2. The seed prints R = b (its Table 5.3 follows from that); docs/silo.md notes the
//    slip, and silo_bottom_force takes R as an argument so that both can be computed.
//  * Eq 5.2: K = sin φi·sin(arcsin(sin φw / sin φi) + φw) / (1 − sin φi·cos(arcsin(sin φw /
//    sin φi) + φw)) / tan φw, defined for 0 < φw ≤ φi.
//  * EN 1991-4 uses the same Eq 5.1 with its own K (the seed: K = 0.45·1.4 = 0.63) and
//    μ = tan φw.
#pragma once

namespace gs::analysis {

/// Eq 5.2 (Drescher): lateral pressure ratio from the internal and wall friction angles (deg).
/// Throws std::invalid_argument unless 0 < φw ≤ φi < 90.
double drescher_lateral_ratio(double phi_i_deg, double phi_w_deg);

/// Eq 5.1: mean vertical stress (Pa) at depth h (m) below the free surface of a fill of unit
/// weight γ (N/m³), with lateral pressure ratio K, wall friction μ and hydraulic radius R (m).
/// Throws std::invalid_argument for a non-positive γ, K, μ or R, or a negative h.
double janssen_vertical_stress(double gamma, double K, double mu, double R, double h);

}  // namespace gs::analysis
