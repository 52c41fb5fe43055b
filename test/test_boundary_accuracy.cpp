/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Boundary points of a labelled mesh and boundary distances, on hand-made cases.

#include <pcl_selective_seg/segmentation_metrics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace metrics = pcl::selective_seg::metrics;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Triangles = std::vector<std::array<pcl::index_t, 3>>;

namespace {

/** Two triangles seen from the origin: p0..p2 at z = 1, p3 farther away (z = 2). */
Cloud
square()
{
  Cloud c;
  c.push_back(pcl::PointXYZ(0.0f, 0.0f, 1.0f));
  c.push_back(pcl::PointXYZ(0.1f, 0.0f, 1.0f));
  c.push_back(pcl::PointXYZ(0.0f, 0.1f, 1.0f));
  c.push_back(pcl::PointXYZ(0.2f, 0.2f, 2.0f));
  return c;
}

const Triangles kTriangles = {{0, 1, 2}, {1, 3, 2}};

Cloud
line(std::initializer_list<float> xs)
{
  Cloud c;
  for (const float x : xs)
    c.push_back(pcl::PointXYZ(x, 0.0f, 0.0f));
  return c;
}

} // namespace

TEST(LabelBoundaryPoints, NearerEndPointOfEdgesBetweenLabels)
{
  pcl::Indices boundary;
  // Labels 1 1 2 2: the edges 0-2, 1-2 and 1-3 cross. 0-2 gives 0 (nearer); 1-2 is a
  // tie in range (both sqrt(1.01)) and gives the smaller index 1; 1-3 gives 1.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{0, 1}));
  // Unlabeled points end a region: 0 0 0 1 crosses 1-3 and 3-2 only.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {0, 0, 0, 1}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{1, 2}));
  // One label, or only zeros: no boundary.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {0, 0, 0, 0}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_TRUE(boundary.empty());
  // Seen from far along -z, point 3 is the nearer end of 1-3 and 3-2.
  ASSERT_TRUE(metrics::labelBoundaryPoints(square(),
                                           kTriangles,
                                           {0, 0, 0, 1},
                                           Eigen::Vector3f(0.0f, 0.0f, 10.0f),
                                           M_PI,
                                           boundary));
  EXPECT_EQ(boundary, (pcl::Indices{3}));
}

TEST(LabelBoundaryPoints, LongEdgesAreLeftOut)
{
  pcl::Indices boundary;
  // Edge 0-2 subtends atan(0.1) = 0.09967 rad, 1-2 0.14084 rad, 1-3 0.09918 rad.
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), 0.0994, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{1})); // from 1-3 only
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), 0.05, boundary));
  EXPECT_TRUE(boundary.empty());
}

TEST(LabelBoundaryPoints, BadInput)
{
  pcl::Indices boundary{7};
  EXPECT_FALSE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_TRUE(boundary.empty());
  EXPECT_FALSE(metrics::labelBoundaryPoints(
      square(), {{0, 1, 4}}, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_FALSE(metrics::labelBoundaryPoints(
      square(), kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), 0.0, boundary));
  // Non-finite points make no boundary.
  Cloud c = square();
  c[0].x = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(metrics::labelBoundaryPoints(
      c, kTriangles, {1, 1, 2, 2}, Eigen::Vector3f::Zero(), M_PI, boundary));
  EXPECT_EQ(boundary, (pcl::Indices{1}));
}

TEST(BoundaryDistances, HandComputed)
{
  metrics::BoundaryDistances d;
  std::vector<float> per_point;
  Cloud from = line({0.0f, 1.0f, 3.0f, 10.0f});
  from.push_back(pcl::PointXYZ(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
  metrics::boundaryDistances(from, line({0.0f, 2.0f}), d, &per_point);
  // Distances 0, 1, 1, 8; nearest-rank median = 2nd of 4, p90 = 4th of 4.
  EXPECT_EQ(d.num_from, 4u);
  EXPECT_EQ(d.num_to, 2u);
  EXPECT_DOUBLE_EQ(d.mean, 2.5);
  EXPECT_DOUBLE_EQ(d.median, 1.0);
  EXPECT_DOUBLE_EQ(d.p90, 8.0);
  EXPECT_DOUBLE_EQ(d.max, 8.0);
  ASSERT_EQ(per_point.size(), 5u);
  EXPECT_FLOAT_EQ(per_point[3], 8.0f);
  EXPECT_TRUE(std::isnan(per_point[4]));
  // The reverse direction: 0 -> 0, 2 -> 1 or 3.
  metrics::boundaryDistances(line({0.0f, 2.0f}), line({0.0f, 1.0f, 3.0f, 10.0f}), d);
  EXPECT_DOUBLE_EQ(d.mean, 0.5);
  EXPECT_DOUBLE_EQ(d.max, 1.0);
}

TEST(BoundaryDistances, PointsBeyondTheSearchRangeAreSkipped)
{
  // Squared distances of 1e30 m overflow the search's float: such a point would be
  // taken as nearest at random. It is skipped like a non-finite one.
  metrics::BoundaryDistances d;
  std::vector<float> per_point;
  metrics::boundaryDistances(
      line({0.0f, 1e30f}), line({1e30f, -5e29f, 3.0f}), d, &per_point);
  EXPECT_EQ(d.num_from, 1u);
  EXPECT_EQ(d.num_to, 1u);
  EXPECT_DOUBLE_EQ(d.max, 3.0);
  EXPECT_FLOAT_EQ(per_point[0], 3.0f);
  EXPECT_TRUE(std::isnan(per_point[1]));
  // At the limit itself points still count.
  const float edge = metrics::kMaxMetricCoordinate;
  metrics::boundaryDistances(line({edge}), line({edge, 0.0f}), d);
  EXPECT_EQ(d.num_from, 1u);
  EXPECT_EQ(d.num_to, 2u);
  EXPECT_DOUBLE_EQ(d.max, 0.0);
}

TEST(BoundaryDistances, EmptySetsGiveNaN)
{
  metrics::BoundaryDistances d;
  metrics::boundaryDistances(line({1.0f}), Cloud(), d);
  EXPECT_EQ(d.num_from, 1u);
  EXPECT_EQ(d.num_to, 0u);
  EXPECT_TRUE(std::isnan(d.mean));
  EXPECT_TRUE(std::isnan(d.p90));
  metrics::boundaryDistances(Cloud(), line({1.0f}), d);
  EXPECT_EQ(d.num_from, 0u);
  EXPECT_TRUE(std::isnan(d.median));
}

namespace {

/** A 5 x 3 grid in x (-0.2 .. 0.2) and y (0 .. 0.2) seen from the origin: columns with
 * x <= 0 carry label 1 and lie on z = 2 + x tan(a), the others label 2 on
 * z = 2 - x tan(b) (both meet at x = 0); with a jump_scale > 0, label 2 lies on z = 2
 * instead and every point of it is moved along its ray to jump_scale times its range.
 * Each grid cell gives two triangles. */
struct Grid {
  Cloud cloud;
  Triangles triangles;
  std::vector<std::uint32_t> labels;
};

Grid
twoFaces(double a, double b, double jump_scale = 0.0)
{
  Grid g;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 3; ++j) {
      const double x = 0.1 * (i - 2);
      const double z = x <= 0.0         ? 2.0 + x * std::tan(a)
                       : jump_scale > 0 ? 2.0
                                        : 2.0 - x * std::tan(b);
      const double s = x > 0.0 && jump_scale > 0 ? jump_scale : 1.0;
      g.cloud.push_back(pcl::PointXYZ(static_cast<float>(s * x),
                                      static_cast<float>(s * 0.1 * j),
                                      static_cast<float>(s * z)));
      g.labels.push_back(x <= 0.0 ? 1u : 2u);
    }
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 2; ++j) {
      const pcl::index_t v = 3 * i + j;
      g.triangles.push_back({v, v + 3, v + 1});
      g.triangles.push_back({v + 1, v + 3, v + 4});
    }
  return g;
}

/** describeBoundaryPoints() of the listed points of \a g (sensor at the origin, every
 * edge, 85 deg incidence). */
std::vector<metrics::BoundaryEdgeKind>
describeListed(const Grid& g, const pcl::Indices& boundary)
{
  std::vector<metrics::BoundaryEdgeKind> kinds;
  EXPECT_TRUE(metrics::describeBoundaryPoints(g.cloud,
                                              g.triangles,
                                              g.labels,
                                              Eigen::Vector3f::Zero(),
                                              M_PI,
                                              85.0 * M_PI / 180.0,
                                              boundary,
                                              kinds));
  EXPECT_EQ(kinds.size(), boundary.size());
  return kinds;
}

/** describeListed() of the boundary points labelBoundaryPoints() finds. */
std::vector<metrics::BoundaryEdgeKind>
describe(const Grid& g, pcl::Indices* boundary_out = nullptr)
{
  pcl::Indices boundary;
  EXPECT_TRUE(metrics::labelBoundaryPoints(
      g.cloud, g.triangles, g.labels, Eigen::Vector3f::Zero(), M_PI, boundary));
  if (boundary_out)
    *boundary_out = boundary;
  return describeListed(g, boundary);
}

} // namespace

TEST(DescribeBoundaryPoints, CreaseAngleIsTheAngleBetweenTheFaces)
{
  // Faces tilted by 45 deg each way: a 90 deg crease (a box's edge seen from inside).
  // The boundary points are the nearer ends of the edges x = 0 -> x = 0.1: the
  // column x = 0.1 (z = 1.9 < 2).
  pcl::Indices boundary;
  auto kinds = describe(twoFaces(M_PI / 4, M_PI / 4), &boundary);
  ASSERT_EQ(boundary, (pcl::Indices{9, 10, 11}));
  for (const auto& k : kinds) {
    EXPECT_FALSE(k.depth_jump);
    EXPECT_NEAR(k.crease_angle, M_PI / 2, 1e-5);
  }
  // Degenerate triangles (a corner repeated) add no side normal: the same angles.
  Grid with_degenerate = twoFaces(M_PI / 4, M_PI / 4);
  with_degenerate.triangles.push_back({9, 9, 12});
  with_degenerate.triangles.push_back({6, 9, 9});
  for (const auto& k : describe(with_degenerate))
    EXPECT_NEAR(k.crease_angle, M_PI / 2, 1e-5);
  // 10 and 15 deg tilts: a 25 deg crease, the merge angle.
  for (const auto& k : describe(twoFaces(10.0 * M_PI / 180, 15.0 * M_PI / 180))) {
    EXPECT_FALSE(k.depth_jump);
    EXPECT_NEAR(k.crease_angle, 25.0 * M_PI / 180, 1e-5);
  }
  // One plane, two labels: a smooth border, angle 0 (a float's worth of rounding).
  for (const auto& k : describe(twoFaces(0.3, -0.3))) {
    EXPECT_FALSE(k.depth_jump);
    EXPECT_NEAR(k.crease_angle, 0.0, 1e-6);
  }
}

TEST(DescribeBoundaryPoints, DepthJumpsAreEdgesAlongTheLineOfSight)
{
  // Label 2 pushed back along its rays to three times its range: every edge across
  // the border runs within about 2 deg of its line of sight (the lateral step of 0.1
  // or 0.14 m against 4 m of depth), inside 90 - 85 deg: depth jumps, at the nearer
  // column x = 0.
  pcl::Indices boundary;
  const auto kinds = describe(twoFaces(0.0, 0.0, 3.0), &boundary);
  ASSERT_EQ(boundary, (pcl::Indices{6, 7, 8}));
  for (const auto& k : kinds) {
    EXPECT_TRUE(k.depth_jump);
    EXPECT_TRUE(std::isnan(k.crease_angle)); // no crease edge at these points
  }
  // Pushed back by 10% only (0.2 m of depth against the same lateral step: edges 25
  // deg or more from their line of sight): no jump; the two sides are parallel planes.
  for (const auto& k : describe(twoFaces(0.0, 0.0, 1.1))) {
    EXPECT_FALSE(k.depth_jump);
    EXPECT_NEAR(k.crease_angle, 0.0, 1e-6);
  }
}

TEST(DescribeBoundaryPoints, NoSideOfItsOwnGivesNaN)
{
  // Labels alternating by column: no triangle has one label at all three corners.
  Grid g = twoFaces(0.0, 0.0);
  for (std::size_t i = 0; i < g.labels.size(); ++i)
    g.labels[i] = 1 + static_cast<std::uint32_t>((i / 3) % 2);
  const auto kinds = describe(g);
  ASSERT_FALSE(kinds.empty());
  for (const auto& k : kinds) {
    EXPECT_FALSE(k.depth_jump);
    EXPECT_TRUE(std::isnan(k.crease_angle));
  }
}

TEST(DescribeBoundaryPoints, BadInput)
{
  const Grid g = twoFaces(0.0, 0.0);
  std::vector<metrics::BoundaryEdgeKind> kinds(1);
  EXPECT_FALSE(metrics::describeBoundaryPoints(
      g.cloud, g.triangles, g.labels, Eigen::Vector3f::Zero(), M_PI, 0.0, {}, kinds));
  EXPECT_TRUE(kinds.empty());
  EXPECT_FALSE(metrics::describeBoundaryPoints(g.cloud,
                                               g.triangles,
                                               g.labels,
                                               Eigen::Vector3f::Zero(),
                                               M_PI,
                                               1.0,
                                               {static_cast<pcl::index_t>(15)},
                                               kinds));
  EXPECT_FALSE(metrics::describeBoundaryPoints(
      g.cloud, g.triangles, {1u, 2u}, Eigen::Vector3f::Zero(), M_PI, 1.0, {}, kinds));
  // A boundary point listed by the caller but with no boundary edge: default kind.
  ASSERT_TRUE(metrics::describeBoundaryPoints(g.cloud,
                                              g.triangles,
                                              g.labels,
                                              Eigen::Vector3f::Zero(),
                                              M_PI,
                                              1.0,
                                              {static_cast<pcl::index_t>(0)},
                                              kinds));
  ASSERT_EQ(kinds.size(), 1u);
  EXPECT_FALSE(kinds[0].depth_jump);
  EXPECT_TRUE(std::isnan(kinds[0].crease_angle));
}

TEST(DescribeBoundaryPoints, PointListedTwiceIsDescribedTwice)
{
  const Grid g = twoFaces(0.3, 0.0);
  pcl::Indices boundary;
  const auto kinds = describe(g, &boundary);
  ASSERT_FALSE(boundary.empty());
  pcl::Indices twice = boundary;
  twice.push_back(boundary.front());
  const auto again = describeListed(g, twice);
  ASSERT_EQ(again.size(), twice.size());
  for (std::size_t k = 0; k < twice.size(); ++k) {
    const auto& expected = kinds[k < boundary.size() ? k : 0];
    EXPECT_EQ(again[k].depth_jump, expected.depth_jump) << k;
    if (std::isnan(expected.crease_angle))
      EXPECT_TRUE(std::isnan(again[k].crease_angle)) << k;
    else
      EXPECT_FLOAT_EQ(again[k].crease_angle, expected.crease_angle) << k;
  }
  EXPECT_FALSE(std::isnan(again.front().crease_angle));
}
