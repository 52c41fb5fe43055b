/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// The panoramic projection (ViewProjection::Panoramic): the periodic triangulation on
// its own (every triangle Delaunay on the cylinder, the mesh closed across the seam),
// and the segmentation of a room scanned all around from its middle.

#include <pcl_selective_seg/regions_of_interest.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>

using namespace pcl::selective_seg;
using pcl::index_t;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Seg = SelectiveSegmentation<pcl::PointXYZ>;

namespace {

__extension__ typedef __int128 Int128;

/** > 0: d strictly inside the circle of the counter-clockwise (a, b, c). */
Int128
inCircle(const std::array<std::int64_t, 2>& a,
         const std::array<std::int64_t, 2>& b,
         const std::array<std::int64_t, 2>& c,
         const std::array<std::int64_t, 2>& d)
{
  const Int128 adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0],
               bdy = b[1] - d[1], cdx = c[0] - d[0], cdy = c[1] - d[1];
  return (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) +
         (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
         (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
}

std::vector<QuantizedPoint>
randomCylinderPoints(std::size_t n,
                     std::int32_t period,
                     std::int32_t height,
                     unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::int32_t> x(-period / 2, period / 2 - 1),
      y(0, height);
  std::set<QuantizedPoint> seen;
  std::vector<QuantizedPoint> points;
  while (points.size() < n) {
    const QuantizedPoint p{x(rng), y(rng)};
    if (seen.insert(p).second)
      points.push_back(p);
  }
  return points;
}

/** Each triangle unwrapped next to its first corner: x of the others moved by a
 * multiple of the period to lie within half a period of it. */
std::array<std::array<std::int64_t, 2>, 3>
unwrap(const std::vector<QuantizedPoint>& points,
       const Triangle& t,
       std::int32_t period)
{
  std::array<std::array<std::int64_t, 2>, 3> out;
  for (int i = 0; i < 3; ++i) {
    std::int64_t x = points[t[i]][0];
    const std::int64_t x0 = points[t[0]][0];
    while (x - x0 > period / 2)
      x -= period;
    while (x0 - x > period / 2)
      x += period;
    out[i] = {x, points[t[i]][1]};
  }
  return out;
}

} // namespace

TEST(Delaunay2dPeriodic, EveryTriangleIsDelaunayOnTheCylinderAndTheMeshCloses)
{
  const std::int32_t period = 100000;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const auto points = randomCylinderPoints(300, period, 30000, seed);
    std::vector<Triangle> triangles, neighbours;
    bool closed = false;
    std::string why;
    ASSERT_TRUE(delaunay2dPeriodic(
        points, period, DelaunayBackend::Sweep, triangles, neighbours, closed, &why))
        << why;
    EXPECT_TRUE(closed);
    std::size_t across_seam = 0, boundary = 0;
    std::map<std::pair<index_t, index_t>, int> directed;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const auto c = unwrap(points, triangles[t], period);
      // Counter-clockwise once unwrapped; the seam crossed by some.
      ASSERT_GT((c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) -
                    (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]),
                0);
      across_seam += std::max({c[0][0], c[1][0], c[2][0]}) >= period / 2 ||
                     std::min({c[0][0], c[1][0], c[2][0]}) < -period / 2;
      // Empty circle against every point and its copies one period either way.
      for (std::size_t p = 0; p < points.size(); ++p)
        for (const std::int64_t shift : {-period, 0, period}) {
          const std::array<std::int64_t, 2> d{points[p][0] + shift, points[p][1]};
          ASSERT_LE(inCircle(c[0], c[1], c[2], d), 0)
              << "seed " << seed << ", triangle " << t << ", point " << p;
        }
      for (int i = 0; i < 3; ++i) {
        ++directed[{triangles[t][i], triangles[t][(i + 1) % 3]}];
        boundary += neighbours[t][(i + 2) % 3] < 0;
      }
    }
    EXPECT_GT(across_seam, 0u);
    for (const auto& [edge, uses] : directed)
      EXPECT_EQ(uses, 1);
    // A triangulated annulus: F = 2 V - B (Euler characteristic 0) when every point
    // is a corner; here the boundary is only the lower and upper ends.
    std::set<index_t> corners;
    for (const auto& t : triangles)
      corners.insert(t.begin(), t.end());
    EXPECT_EQ(static_cast<std::int64_t>(triangles.size()),
              2 * static_cast<std::int64_t>(corners.size()) -
                  static_cast<std::int64_t>(boundary));
    // The same triangles from the other exact backend.
    std::vector<Triangle> boost_triangles, boost_neighbours;
    bool boost_closed = false;
    ASSERT_TRUE(delaunay2dPeriodic(points,
                                   period,
                                   DelaunayBackend::BoostVoronoi,
                                   boost_triangles,
                                   boost_neighbours,
                                   boost_closed));
    EXPECT_EQ(boost_triangles, triangles);
    EXPECT_EQ(boost_neighbours, neighbours);
  }
}

namespace {

/** When \a closed: every triangle narrower than half the period and Delaunay on the
 * cylinder (its circle empty of every point and its copies one period either way). */
void
expectDelaunayOnTheCylinder(const std::vector<QuantizedPoint>& points,
                            std::int32_t period,
                            const std::vector<Triangle>& triangles,
                            const std::string& what)
{
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto c = unwrap(points, triangles[t], period);
    EXPECT_LT(std::max({c[0][0], c[1][0], c[2][0]}) -
                  std::min({c[0][0], c[1][0], c[2][0]}),
              period / 2)
        << what << ", triangle " << t;
    for (std::size_t p = 0; p < points.size(); ++p)
      for (const std::int64_t shift : {-period, 0, period}) {
        const std::array<std::int64_t, 2> d{points[p][0] + shift, points[p][1]};
        ASSERT_LE(inCircle(c[0], c[1], c[2], d), 0)
            << what << ", triangle " << t << ", point " << p;
      }
  }
}

} // namespace

// Found by review (session 24): the checks near the seam were local only, and a mesh of
// a few points spread over more than half a period matched two different edges of the
// cylinder by their ids. Closed now means Delaunay on the cylinder, or the result is
// the open planar triangulation.
TEST(Delaunay2dPeriodic, ClosedMeansDelaunayOnTheCylinderForSparseAndTallInputs)
{
  std::vector<Triangle> triangles, neighbours;
  bool closed = false;
  const std::vector<QuantizedPoint> sparse{{-19, 105},
                                           {203, 107},
                                           {-242, 140},
                                           {39, 92},
                                           {236, 82},
                                           {-95, -10},
                                           {249, -99},
                                           {-237, -20},
                                           {86, -31},
                                           {-314, 51},
                                           {-123, 135},
                                           {-296, 117},
                                           {-204, 53},
                                           {-311, -148}};
  ASSERT_TRUE(delaunay2dPeriodic(
      sparse, 628, DelaunayBackend::Sweep, triangles, neighbours, closed));
  if (closed)
    expectDelaunayOnTheCylinder(sparse, 628, triangles, "sparse");
  const std::vector<QuantizedPoint> tall{{-5, 26}, {0, 24}, {-6, 33}, {-6, 10}};
  ASSERT_TRUE(delaunay2dPeriodic(
      tall, 14, DelaunayBackend::Sweep, triangles, neighbours, closed));
  EXPECT_FALSE(closed);
  // Random small and sparse inputs, tall ones among them.
  std::mt19937 rng(17);
  std::size_t num_closed = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const std::int32_t period =
        2 * std::uniform_int_distribution<std::int32_t>(2, 500)(rng);
    const std::int32_t height =
        std::uniform_int_distribution<std::int32_t>(1, 3 * period)(rng);
    const std::size_t n = std::uniform_int_distribution<std::size_t>(3, 60)(rng);
    if (static_cast<std::int64_t>(period) * (height + 1) <
        static_cast<std::int64_t>(2 * n))
      continue;
    const auto points = randomCylinderPoints(n, period, height, rng());
    ASSERT_TRUE(delaunay2dPeriodic(
        points, period, DelaunayBackend::Sweep, triangles, neighbours, closed));
    if (!closed)
      continue;
    ++num_closed;
    expectDelaunayOnTheCylinder(
        points, period, triangles, "trial " + std::to_string(trial));
  }
  std::printf("%zu of the random inputs closed\n", num_closed);
  EXPECT_GT(num_closed, 0u);
}

TEST(Delaunay2dPeriodic, RefusesBadInput)
{
  std::vector<Triangle> triangles, neighbours;
  bool closed = true;
  std::string why;
  const std::vector<QuantizedPoint> points{{0, 0}, {10, 0}, {5, 10}};
  EXPECT_FALSE(delaunay2dPeriodic(
      points, 7, DelaunayBackend::Sweep, triangles, neighbours, closed, &why));
  EXPECT_NE(why.find("period"), std::string::npos) << why;
  EXPECT_FALSE(delaunay2dPeriodic(
      points, 16, DelaunayBackend::Sweep, triangles, neighbours, closed, &why));
  EXPECT_NE(why.find("outside"), std::string::npos) << why;
  // Duplicates are named by their input ids (not by the strip's).
  EXPECT_FALSE(delaunay2dPeriodic({{0, 0}, {100, 10}, {-50, 30}, {200, 40}, {100, 10}},
                                  1000,
                                  DelaunayBackend::Sweep,
                                  triangles,
                                  neighbours,
                                  closed,
                                  &why));
  EXPECT_NE(why.find("points 1 and 4 at (100, 10)"), std::string::npos) << why;
  EXPECT_FALSE(closed);
  // Fewer than three points, or a few points far apart: no closed mesh, no failure.
  EXPECT_TRUE(delaunay2dPeriodic(
      {{0, 0}, {1, 1}}, 1000, DelaunayBackend::Sweep, triangles, neighbours, closed));
  EXPECT_TRUE(triangles.empty());
  EXPECT_FALSE(closed);
}

namespace {

/** A box room, x in +-3, y (up) in +-1.5, z in +-4 m, scanned from its middle by a
 * spinning sensor: jittered rays all around in azimuth, +-40 deg in elevation.
 * \a face gets the wall each point lies on (0..5). */
Cloud::Ptr
scanRoom(std::vector<int>& face, unsigned seed = 7)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(0.0, 1.0);
  const int num_azimuth = 600, num_elevation = 80;
  const double half[3] = {3.0, 1.5, 4.0};
  auto cloud = pcl::make_shared<Cloud>();
  face.clear();
  for (int i = 0; i < num_azimuth; ++i)
    for (int j = 0; j < num_elevation; ++j) {
      const double az = -M_PI + (i + jitter(rng)) * 2.0 * M_PI / num_azimuth;
      const double el = -0.7 + (j + jitter(rng)) * 1.4 / num_elevation;
      const double d[3] = {
          std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
      int axis = 0;
      double t = 1e30;
      for (int k = 0; k < 3; ++k)
        if (std::abs(d[k]) > 0 && half[k] / std::abs(d[k]) < t) {
          t = half[k] / std::abs(d[k]);
          axis = k;
        }
      cloud->push_back(pcl::PointXYZ(static_cast<float>(t * d[0]),
                                     static_cast<float>(t * d[1]),
                                     static_cast<float>(t * d[2])));
      face.push_back(2 * axis + (d[axis] > 0));
    }
  cloud->width = static_cast<std::uint32_t>(cloud->size());
  cloud->height = 1;
  return cloud;
}

SelectiveSegmentationParameters
panoramic()
{
  SelectiveSegmentationParameters p;
  p.projection = ViewProjection::Panoramic;
  p.normal_spread_frame = NormalSpreadFrame::MeanNormal;
  return p;
}

} // namespace

// A point straight behind the sensor has theta = +pi, which is -pi: its quantized
// angle must be -period / 2 (vertex_angles lie in [-period / 2, period / 2)), the
// same vertex as a point just left of it. Left at +period / 2, it lay outside the
// periodic triangulation's range and the whole scan failed to triangulate.
TEST(PanoramicTriangulation, PointStraightBehindTheSensorIsOnTheSeam)
{
  Cloud::Ptr cloud(new Cloud);
  cloud->push_back({0.f, 0.f, -1.f});    // theta = +pi exactly
  cloud->push_back({-1e-8f, 0.f, -1.f}); // theta just above -pi: the same cell
  for (int k = 0; k < 12; ++k)
    for (const float y : {-0.3f, 0.3f}) {
      const double t = (k + 0.5) * 2.0 * M_PI / 12.0;
      cloud->push_back(
          {static_cast<float>(std::sin(t)), y, static_cast<float>(std::cos(t))});
    }
  SphericalDelaunay<pcl::PointXYZ> delaunay;
  delaunay.setInputCloud(cloud);
  delaunay.setAngleQuantization(1e-7);
  delaunay.setProjection(ViewProjection::Panoramic);
  ASSERT_TRUE(delaunay.triangulate());
  const auto& t = delaunay.getTriangulation();
  const std::int32_t period = panoramicPeriod(1e-7);
  for (const auto& q : t.vertex_angles) {
    EXPECT_GE(q[0], -period / 2);
    EXPECT_LT(q[0], period / 2);
  }
  ASSERT_GE(t.point_vertex[0], 0);
  EXPECT_EQ(t.point_vertex[0], t.point_vertex[1]);
  EXPECT_EQ(t.vertex_angles[t.point_vertex[0]], (QuantizedPoint{-period / 2, 0}));
}

TEST(PanoramicSegmentation, EveryWallOfARoomIsOneSegmentTheOneBehindTheSeamToo)
{
  std::vector<int> face;
  const auto cloud = scanRoom(face);
  {
    const auto params = panoramic();
    Seg seg;
    seg.setParameters(params);
    seg.setInputCloud(cloud);
    std::vector<pcl::PointIndices> segments;
    ASSERT_TRUE(seg.extract(segments));
    EXPECT_TRUE(seg.getTriangulation().seam_closed);
    const auto& labels = seg.getResult().labels;
    // Every point has an image; each wall's largest segment holds nearly all of it
    // and little of another wall. Wall 4 (z = -4 m) lies across the seam.
    EXPECT_EQ(seg.getResult().counts.behind_sensor, 0u);
    std::map<int, std::map<std::uint32_t, std::size_t>> per_face;
    std::map<std::uint32_t, std::map<int, std::size_t>> per_label;
    for (std::size_t i = 0; i < labels.size(); ++i) {
      ++per_face[face[i]][labels[i]];
      ++per_label[labels[i]][face[i]];
    }
    ASSERT_EQ(per_face.size(), 6u);
    for (const auto& [f, counts] : per_face) {
      std::size_t total = 0, largest = 0;
      std::uint32_t label = 0;
      for (const auto& [l, c] : counts) {
        total += c;
        if (c > largest && l != 0) {
          largest = c;
          label = l;
        }
      }
      EXPECT_GE(largest, 0.95 * total) << "wall " << f;
      std::size_t elsewhere = 0;
      for (const auto& [g, c] : per_label[label])
        elsewhere += (g != f) * c;
      // The points along the room's 90-degree corners, whose normals mix both walls,
      // go to either wall: 0.9-1.8% of a wall here.
      EXPECT_LE(elsewhere, 0.025 * largest) << "wall " << f;
    }
  }
}

TEST(PanoramicSegmentation, PointOrderDoesNotMatter)
{
  std::vector<int> face;
  const auto cloud = scanRoom(face, 11);
  std::vector<int> order(cloud->size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  auto shuffled = pcl::make_shared<Cloud>();
  for (const int i : order)
    shuffled->push_back((*cloud)[i]);
  Seg a, b;
  a.setParameters(panoramic());
  b.setParameters(panoramic());
  a.setInputCloud(cloud);
  b.setInputCloud(shuffled);
  std::vector<pcl::PointIndices> sa, sb;
  ASSERT_TRUE(a.extract(sa));
  ASSERT_TRUE(b.extract(sb));
  ASSERT_EQ(sa.size(), sb.size());
  const auto& la = a.getResult().labels;
  const auto& lb = b.getResult().labels;
  for (std::size_t k = 0; k < order.size(); ++k)
    ASSERT_EQ(la[order[k]], lb[k]) << k;
}

TEST(PanoramicSegmentation, UpdateRunsFromScratchAndEqualsExtract)
{
  std::vector<int> face;
  const auto cloud = scanRoom(face, 5);
  const std::size_t half = cloud->size() / 2;
  auto first = pcl::make_shared<Cloud>(), second = pcl::make_shared<Cloud>();
  first->points.assign(cloud->begin(), cloud->begin() + half);
  second->points.assign(cloud->begin() + half, cloud->end());
  first->width = static_cast<std::uint32_t>(first->size());
  second->width = static_cast<std::uint32_t>(second->size());
  first->height = second->height = 1;
  Seg seg;
  seg.setParameters(panoramic());
  seg.setInputCloud(first);
  std::vector<pcl::PointIndices> segments;
  ASSERT_TRUE(seg.extract(segments));
  ASSERT_TRUE(seg.update(*second, segments));
  EXPECT_FALSE(seg.getUpdateStatistics().incremental);
  Seg whole;
  auto params = panoramic();
  params.min_voxel_size = seg.getResult().min_voxel_size;
  whole.setParameters(params);
  whole.setInputCloud(cloud);
  std::vector<pcl::PointIndices> expected;
  ASSERT_TRUE(whole.extract(expected));
  EXPECT_EQ(seg.getResult().labels, whole.getResult().labels);
}

TEST(PanoramicSegmentation, BadParametersAreRefused)
{
  auto p = panoramic();
  std::string why;
  EXPECT_TRUE(p.validate(&why)) << why;
  p.angle_quantization = 5e-8; // the periodic strip would leave the exact range
  EXPECT_FALSE(p.validate(&why));
  EXPECT_NE(why.find("panoramic"), std::string::npos) << why;
  p = panoramic();
  p.delaunay_backend = DelaunayBackend::Vtk;
  EXPECT_FALSE(p.validate(&why));
  p = panoramic();
  p.normal_spread_frame = NormalSpreadFrame::Sensor; // ill-conditioned all around
  EXPECT_FALSE(p.validate(&why));
  EXPECT_NE(why.find("mean_normal"), std::string::npos) << why;
  p.projection = static_cast<ViewProjection>(7);
  EXPECT_FALSE(p.validate(&why));
  EXPECT_NE(why.find("projection"), std::string::npos) << why;

  std::vector<int> face;
  const auto cloud = scanRoom(face);
  Seg seg;
  seg.setParameters(panoramic());
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  ASSERT_TRUE(seg.extract(segments));
  // The forward projection leaves out the half of the room behind the sensor.
  Seg forward;
  forward.setInputCloud(cloud);
  ASSERT_TRUE(forward.extract(segments));
  EXPECT_GT(forward.getResult().counts.behind_sensor, cloud->size() / 3);
}

TEST(PanoramicRegions, WindowsOnBothSidesOfTheSeamWithExactSolidAngles)
{
  // The room turned about its vertical so that the corner (3, y, -4), at azimuth
  // atan2(3, -4), lies on the seam at theta = +-pi.
  std::vector<int> face;
  const auto room = scanRoom(face, 9);
  const double turn = M_PI - std::atan2(3.0, -4.0);
  auto cloud = pcl::make_shared<Cloud>();
  for (const auto& p : *room)
    cloud->push_back(pcl::PointXYZ(
        static_cast<float>(p.x * std::cos(turn) + p.z * std::sin(turn)),
        p.y,
        static_cast<float>(-p.x * std::sin(turn) + p.z * std::cos(turn))));
  Seg seg;
  seg.setParameters(panoramic());
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> segments;
  ASSERT_TRUE(seg.extract(segments));
  ASSERT_TRUE(seg.getTriangulation().seam_closed);
  std::vector<RegionOfInterest> regions;
  RegionOfInterestStats stats;
  ASSERT_TRUE(
      computeRegionsOfInterest(seg, RegionOfInterestParameters(), regions, &stats));
  std::printf("%zu windows, evidence: %zu transition, %zu small segment, %zu sparse\n",
              regions.size(),
              stats.transition_vertices,
              stats.small_segment_vertices,
              stats.sparse_vertices);
  ASSERT_FALSE(regions.empty());
  bool below_seam = false, above_seam = false;
  for (const auto& r : regions) {
    EXPECT_EQ(r.projection, ViewProjection::Panoramic);
    EXPECT_GE(r.theta_min, -M_PI);
    EXPECT_LE(r.theta_max, M_PI);
    EXPECT_LT(r.theta_min, r.theta_max);
    EXPECT_NEAR(r.solid_angle,
                (r.theta_max - r.theta_min) *
                    (std::sin(r.phi_max) - std::sin(r.phi_min)),
                1e-12);
    if (r.reasons & kTransition) {
      below_seam |= r.theta_min < -M_PI + 0.05;
      above_seam |= r.theta_max > M_PI - 0.05;
    }
  }
  // The corner's evidence, on both sides of the seam.
  EXPECT_TRUE(below_seam);
  EXPECT_TRUE(above_seam);
  // The spacing of a vertex next to the seam is measured the short way round: an
  // evenly sampled room has no sparse evidence (without it, every vertex along the
  // seam would be "2 pi" from its neighbours across it).
  EXPECT_EQ(stats.sparse_vertices, 0u);
}
