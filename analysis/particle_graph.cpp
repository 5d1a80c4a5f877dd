// Seed 002 §3: particle graph from contacts (periodic images across the cell boundary).
#include "particle_graph.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/LU>

namespace gs::analysis {

ParticleGraph make_particle_graph(std::vector<Eigen::Vector2d> positions,
                                  const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs,
                                  bool periodic, const Eigen::Matrix2d& cell) {
  ParticleGraph g;
  g.position = std::move(positions);
  g.periodic = periodic;
  g.cell = cell;
  for (std::size_t i = 0; i < g.position.size(); ++i) {
    if (!g.position[i].allFinite()) {
      throw std::invalid_argument("non-finite particle position (index " + std::to_string(i) + ")");
    }
  }
  Eigen::Matrix2d inv = Eigen::Matrix2d::Identity();
  if (periodic) {
    if (!(std::abs(cell.determinant()) > 0.0) || !cell.allFinite()) {
      throw std::invalid_argument("degenerate periodic cell");
    }
    inv = cell.inverse();
  }
  const auto n = static_cast<std::int32_t>(g.position.size());
  std::vector<std::pair<std::int32_t, std::int32_t>> sorted;
  sorted.reserve(pairs.size());
  for (auto [a, b] : pairs) {
    if (a < 0 || b < 0 || a >= n || b >= n) {
      throw std::invalid_argument("contact index out of range (" + std::to_string(a) + ", " +
                                  std::to_string(b) + ")");
    }
    if (a == b) throw std::invalid_argument("self contact (index " + std::to_string(a) + ")");
    sorted.emplace_back(std::min(a, b), std::max(a, b));
  }
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  g.edges.reserve(sorted.size());
  for (auto [a, b] : sorted) {
    GraphEdge e;
    e.a = a;
    e.b = b;
    if (periodic) {
      const Eigen::Vector2d d =
          g.position[static_cast<std::size_t>(b)] - g.position[static_cast<std::size_t>(a)];
      const Eigen::Vector2d f = inv * d;
      e.shift = Eigen::Vector2i(static_cast<int>(-std::round(f.x())),
                                static_cast<int>(-std::round(f.y())));
    }
    g.edges.push_back(e);
    if (!(g.branch(g.edges.size() - 1).squaredNorm() > 0.0)) {
      throw std::invalid_argument("contacting particles with coincident centres (indices " +
                                  std::to_string(a) + " and " + std::to_string(b) + ")");
    }
  }
  return g;
}

ParticleGraph particle_graph(const Frame& frame) {
  std::unordered_map<std::int64_t, std::int32_t> index;
  std::vector<Eigen::Vector2d> pos;
  pos.reserve(frame.particles.size());
  for (std::size_t i = 0; i < frame.particles.size(); ++i) {
    index.emplace(frame.particles[i].id, static_cast<std::int32_t>(i));
    pos.push_back(frame.particles[i].position.head<2>());
  }
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  for (const auto& c : frame.contacts) {
    const auto i1 = index.find(c.id1), i2 = index.find(c.id2);
    if (i1 == index.end() || i2 == index.end()) continue;  // wall contact
    if (i1->second == i2->second) continue;
    pairs.emplace_back(i1->second, i2->second);
  }
  Eigen::Matrix2d cell = frame.domain.cell.topLeftCorner<2, 2>();
  return make_particle_graph(std::move(pos), pairs, frame.domain.periodic, cell);
}

}  // namespace gs::analysis
