// Tests of analysis/slab_projection (seed 000 §5).
#include <gtest/gtest.h>

#include "slab_projection.hpp"

namespace gs::analysis {
namespace {

TEST(SlabProjection, SelectsSlabAndProjects) {
  const std::vector<Eigen::Vector3d> x{
      {0.1, 0.2, 0.0}, {0.3, 0.4, 0.049}, {0.5, 0.6, -0.051}, {0.7, 0.8, 0.2}};
  const std::vector<Eigen::Vector3d> v{{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {1, 1, 1}};
  Slab s;
  s.thickness = 0.1;
  const auto p = project_slab(x, v, s);
  ASSERT_EQ(p.index, (std::vector<std::int32_t>{0, 1}));
  EXPECT_EQ(p.position[1], Eigen::Vector2d(0.3, 0.4));
  EXPECT_EQ(p.vector[1], Eigen::Vector2d(4, 5));
  // Vertical slice y = 0.5 (normal y), in-plane axes x and z (seed 000's x-z section).
  s.origin = Eigen::Vector3d(0, 0.5, 0);
  s.normal = Eigen::Vector3d(0, 2, 0);
  s.axis1 = Eigen::Vector3d(1, 0, 0);
  s.thickness = 0.25;
  const auto q = project_slab(x, v, s);
  ASSERT_EQ(q.index, (std::vector<std::int32_t>{1, 2}));
  EXPECT_LT((q.e2 - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);  // n x e1
  EXPECT_NEAR(q.position[1].x(), 0.5, 1e-15);
  EXPECT_NEAR(q.position[1].y(), 0.051, 1e-15);
  EXPECT_NEAR(q.vector[0].y(), -6.0, 1e-15);
}

TEST(SlabProjection, RejectsBadSlabs) {
  const std::vector<Eigen::Vector3d> x{{0, 0, 0}};
  Slab s;
  EXPECT_THROW(project_slab(x, {}, s), std::invalid_argument);  // thickness 0
  s.thickness = 1;
  s.normal = Eigen::Vector3d::Zero();
  EXPECT_THROW(project_slab(x, {}, s), std::invalid_argument);
  s.normal = Eigen::Vector3d::UnitX();
  EXPECT_THROW(project_slab(x, {}, s), std::invalid_argument);  // axis1 parallel to normal
  s.axis1 = Eigen::Vector3d::UnitY();
  EXPECT_THROW(project_slab(x, {{1, 1, 1}, {2, 2, 2}}, s), std::invalid_argument);
}

}  // namespace
}  // namespace gs::analysis
