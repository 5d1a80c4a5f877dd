// Strain from a DIC displacement grid by a least-squares plane fit of u and v over a window of
// (2m+1)^2 POIs centred on each POI (Ncorr-style). The virtual strain gauge is
// VSG = 2*m*step + subset px (Pan et al. 2009).
#pragma once

#include <vector>

#include "reliability_guided.hpp"

namespace gs::dic {

struct StrainField {
  int window_radius = 0;  // m
  double vsg_px = 0.0;
  // Displacement gradients and strains per POI (NaN where invalid).
  std::vector<double> ux, uy, vx, vy;
  std::vector<double> exx, eyy, exy;  // Green–Lagrange
  std::vector<double> sxx, syy, sxy;  // small (infinitesimal) strain
  std::vector<std::uint8_t> valid;
};

/// u, v per POI (reference grid, px) with validity; the plane fit uses the valid POIs of the
/// window and needs at least (2m+1)^2/2 of them. Throws std::invalid_argument for m < 1.
StrainField plane_fit_strain(const PoiGrid& grid, const std::vector<double>& u,
                             const std::vector<double>& v, const std::vector<std::uint8_t>& valid,
                             int m, int subset_px);

}  // namespace gs::dic
