#include <gtest/gtest.h>

#include "vislib/scene/scene.h"

using namespace vislib;

TEST(Scene, PositionIsPiecewiseLinearBetweenStates) {
  Scene s;
  s.positions = {{{0, 0, 0}}, {{2, 0, 0}}, {{2, 4, 0}}};
  EXPECT_EQ(s.position_at(0, 0.0), (Vec3{0, 0, 0}));
  EXPECT_EQ(s.position_at(0, 0.25), (Vec3{1, 0, 0}));
  EXPECT_EQ(s.position_at(0, 0.5), (Vec3{2, 0, 0}));
  EXPECT_EQ(s.position_at(0, 0.75), (Vec3{2, 2, 0}));
  EXPECT_EQ(s.position_at(0, 1.0), (Vec3{2, 4, 0}));
  EXPECT_TRUE(s.is_dynamic());
}

TEST(Scene, AppendKeepsIdsInOrderAndOffsetsIndices) {
  Scene a, b;
  a.positions = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  a.triangles = {{0, 1, 2}};
  a.triangle_object = {0};
  a.objects = {{"a"}};
  b = a;
  b.objects[0].name = "b";
  append_scene(a, b);
  ASSERT_EQ(a.triangle_count(), 2u);
  EXPECT_EQ(a.triangles[1], (std::array<uint32_t, 3>{3, 4, 5}));
  EXPECT_EQ(a.triangle_object[1], 1u);
  EXPECT_EQ(a.objects[1].name, "b");
  EXPECT_FALSE(a.is_dynamic());
}
