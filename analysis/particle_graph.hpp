// Particle graph of a 2D assembly (seed 002 §3, after Satake 1993): vertices at particle centres,
// edges between contacting pairs. In a periodic cell an edge joins vertex a to the image of
// vertex b shifted by whole cell vectors (minimum image), so the graph lives on a torus.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

struct GraphEdge {
  std::int32_t a = 0;
  std::int32_t b = 0;
  Eigen::Vector2i shift = Eigen::Vector2i::Zero();  // b's image: x_b + cell * shift
};

struct ParticleGraph {
  std::vector<Eigen::Vector2d> position;  // one vertex per particle (index = input order)
  std::vector<GraphEdge> edges;           // no self loops, no duplicate pairs
  bool periodic = false;
  Eigen::Matrix2d cell = Eigen::Matrix2d::Identity();  // columns: in-plane cell vectors

  /// Branch vector of edge e from a to (the image of) b.
  Eigen::Vector2d branch(std::size_t e) const {
    const auto& g = edges[e];
    return position[static_cast<std::size_t>(g.b)] + cell * g.shift.cast<double>() -
           position[static_cast<std::size_t>(g.a)];
  }
};

/// Graph from index pairs. Self pairs are rejected, repeated pairs merged. In a periodic cell the
/// shift of each edge is the minimum image of x_b - x_a. Throws std::invalid_argument on an
/// index out of range, a self pair, non-finite positions, or a contact between coincident centres
/// (its direction, needed to order the edges around a vertex, is undefined).
ParticleGraph make_particle_graph(std::vector<Eigen::Vector2d> positions,
                                  const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs,
                                  bool periodic = false,
                                  const Eigen::Matrix2d& cell = Eigen::Matrix2d::Identity());

/// Graph of a 2D frame (x, y of the particles; particle-particle contacts only, wall contacts
/// skipped; periodic cell from the domain). Vertex i is frame.particles[i].
ParticleGraph particle_graph(const Frame& frame);

}  // namespace gs::analysis
