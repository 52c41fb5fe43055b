/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// insertDelaunayPoints(): inserting points into an exact triangulation gives exactly
// delaunay2d() of the union (same numbering, same canonical triangle list, same
// adjacency), on random, co-circular (grid), hull-growing and degenerate inputs.

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/delaunay_2d_update.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>

using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::DelaunayInsertion;
using pcl::selective_seg::QuantizedPoint;
using pcl::selective_seg::Triangle;
using Points = std::vector<QuantizedPoint>;

namespace {

Points
sortedUnique(Points p)
{
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  return p;
}

/** Removes from \a extra the points of \a base and its own repeats. */
Points
without(const Points& base, Points extra)
{
  extra = sortedUnique(extra);
  Points out;
  std::set_difference(
      extra.begin(), extra.end(), base.begin(), base.end(), std::back_inserter(out));
  return out;
}

/** Inserts \a extra into the triangulation of \a base on \a threads threads and checks
 * every output against a from-scratch triangulation of the union. Returns the
 * insertion record. */
DelaunayInsertion
insertAndCompare(const Points& base_in,
                 const Points& extra_in,
                 std::mt19937& rng,
                 unsigned int threads = 1)
{
  const Points base = sortedUnique(base_in);
  Points extra = without(base, extra_in);
  std::shuffle(extra.begin(), extra.end(), rng); // any order is accepted
  std::vector<Triangle> triangles, neighbours;
  EXPECT_TRUE(pcl::selective_seg::delaunay2d(base, DelaunayBackend::Sweep, triangles));
  pcl::selective_seg::computeTriangleNeighbours(triangles, base.size(), neighbours);
  const std::vector<Triangle> old_triangles = triangles;

  Points points = base;
  DelaunayInsertion info;
  std::string why;
  EXPECT_TRUE(pcl::selective_seg::insertDelaunayPoints(
      points, triangles, neighbours, extra, info, &why, threads))
      << why;

  Points all = base;
  all.insert(all.end(), extra.begin(), extra.end());
  all = sortedUnique(all);
  std::vector<Triangle> expected, expected_neighbours;
  EXPECT_TRUE(pcl::selective_seg::delaunay2d(all, DelaunayBackend::Sweep, expected));
  pcl::selective_seg::computeTriangleNeighbours(expected, all.size(), expected_neighbours);
  EXPECT_EQ(points, all);
  EXPECT_EQ(triangles, expected);
  EXPECT_EQ(neighbours, expected_neighbours);

  // The record: old points keep their coordinates, kept triangles their corners.
  EXPECT_EQ(info.old_to_new_point.size(), base.size());
  for (std::size_t i = 0; i < base.size() && i < info.old_to_new_point.size(); ++i)
    EXPECT_EQ(all[info.old_to_new_point[i]], base[i]);
  EXPECT_EQ(info.inserted_points.size(), extra.size());
  std::vector<bool> is_new(triangles.size(), false);
  for (const auto t : info.new_triangles)
    is_new[t] = true;
  std::size_t kept = 0;
  for (std::size_t t = 0; t < old_triangles.size(); ++t) {
    const auto id = info.old_to_new_triangle[t];
    if (id < 0)
      continue;
    ++kept;
    EXPECT_FALSE(is_new[id]);
    for (int i = 0; i < 3; ++i)
      EXPECT_EQ(triangles[id][i], info.old_to_new_point[old_triangles[t][i]]);
  }
  EXPECT_EQ(kept + info.new_triangles.size(), triangles.size());
  EXPECT_EQ(kept + info.replaced_triangles, old_triangles.size());
  return info;
}

Points
uniform(std::size_t n, std::int32_t lo, std::int32_t hi, std::mt19937& rng)
{
  std::uniform_int_distribution<std::int32_t> d(lo, hi);
  Points p(n);
  for (auto& q : p)
    q = {d(rng), d(rng)};
  return p;
}

Points
grid(std::int32_t x0, std::int32_t x1, std::int32_t y0, std::int32_t y1, std::int32_t step)
{
  Points p;
  for (std::int32_t x = x0; x <= x1; x += step)
    for (std::int32_t y = y0; y <= y1; y += step)
      p.push_back({x, y});
  return p;
}

} // namespace

TEST(DelaunayInsertion, RandomPointsAnywhere)
{
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Points base = uniform(2000, -100000, 100000, rng);
    const Points extra = uniform(1 + trial * 25, -100000, 100000, rng);
    const auto info = insertAndCompare(base, extra, rng);
    EXPECT_GT(info.replaced_triangles, 0u);
  }
}

TEST(DelaunayInsertion, DenseWindowReplacesOnlyItsRegion)
{
  std::mt19937 rng(2);
  const Points base = uniform(20000, -1000000, 1000000, rng);
  const Points extra = uniform(1000, -100000, 100000, rng); // 1% of the area
  const auto info = insertAndCompare(base, extra, rng);
  // The window holds about 200 old points (400 triangles); the region is that plus a
  // rim, far from the 40,000 triangles of the whole mesh.
  EXPECT_LT(info.replaced_triangles, 2000u);
  EXPECT_LT(info.local_points, 3000u);
}

TEST(DelaunayInsertion, FinerGridWithCoCircularPoints)
{
  std::mt19937 rng(3);
  // Every grid square is four co-circular points: the canonical fan decides.
  const Points base = grid(-400, 400, -300, 300, 20);
  insertAndCompare(base, grid(-100, 100, -60, 60, 10), rng);
  insertAndCompare(base, grid(-100, 100, -60, 60, 5), rng);
  insertAndCompare(base, grid(-400, 400, -300, 300, 10), rng); // everywhere
  insertAndCompare(base, {{10, 10}}, rng);                     // a square's centre
  insertAndCompare(base, {{0, 10}, {10, 0}}, rng);             // edge midpoints
}

TEST(DelaunayInsertion, PointsOutsideTheHullGrowIt)
{
  std::mt19937 rng(4);
  const Points base = uniform(3000, -10000, 10000, rng);
  insertAndCompare(base, uniform(200, 10001, 30000, rng), rng); // a strip to the right
  insertAndCompare(base, {{1000000, 5}}, rng);                  // far away
  insertAndCompare(base, {{-1000000, -1000000}, {1000000, 1000000}}, rng);
  insertAndCompare(base, uniform(500, -40000, 40000, rng), rng); // around and inside
  // On the extension of a hull edge, and on a hull edge of a square.
  const Points square = grid(0, 100, 0, 100, 10);
  insertAndCompare(square, {{200, 0}}, rng);
  insertAndCompare(square, {{55, 0}}, rng);
  insertAndCompare(square, {{-50, 50}, {150, 50}, {50, -50}, {50, 150}}, rng);
  insertAndCompare(square, grid(-100, 200, -100, 200, 10), rng); // surrounds it
}

TEST(DelaunayInsertion, TinyTriangulations)
{
  std::mt19937 rng(5);
  const Points tri = {{0, 0}, {10, 0}, {0, 10}};
  insertAndCompare(tri, {{3, 3}}, rng);
  insertAndCompare(tri, {{10, 10}}, rng); // co-circular with the three
  insertAndCompare(tri, {{20, 0}}, rng);  // collinear with an edge
  insertAndCompare(tri, uniform(50, -20, 30, rng), rng);
}

TEST(DelaunayInsertion, ScanLikeColumnsRefinedInAWindow)
{
  std::mt19937 rng(6);
  // Columns of a range image, jittered by one unit as float rounding does, and a
  // window scanned again at twice the density.
  std::normal_distribution<double> jitter(0.0, 1.0);
  Points base, extra;
  for (int c = 0; c < 120; ++c)
    for (int r = 0; r < 90; ++r)
      base.push_back({c * 1000 + static_cast<std::int32_t>(jitter(rng)),
                      r * 1000 + static_cast<std::int32_t>(jitter(rng))});
  for (int c = 60; c < 100; ++c)
    for (int r = 40; r < 70; ++r)
      extra.push_back({c * 500 + 250 + static_cast<std::int32_t>(jitter(rng)),
                       r * 500 + 250 + static_cast<std::int32_t>(jitter(rng))});
  insertAndCompare(base, extra, rng);
}

TEST(DelaunayInsertion, SameResultForAnyThreadCount)
{
  // Large enough (over 16,384 old points and triangles) for the renumbering, assembly
  // and adjacency passes to split into chunks; several windows, one of them a grid
  // over a grid (co-circular squares), and points outside the hull.
  std::mt19937 rng(8);
  Points base = uniform(30000, -3000000, 3000000, rng);
  const Points lattice = grid(1000000, 1400000, 1000000, 1300000, 10000);
  base.insert(base.end(), lattice.begin(), lattice.end());
  Points extra = uniform(1500, -200000, 200000, rng);
  const Points left = uniform(800, -2900000, -2700000, rng);
  const Points finer = grid(1100000, 1300000, 1100000, 1200000, 5000);
  const Points outside = uniform(300, 3000001, 3100000, rng);
  for (const Points* more : {&left, &finer, &outside})
    extra.insert(extra.end(), more->begin(), more->end());
  for (const unsigned int threads : {1u, 2u, 3u}) {
    SCOPED_TRACE(threads);
    std::mt19937 order(9); // the same shuffle of the new points each time
    const auto info = insertAndCompare(base, extra, order, threads);
    EXPECT_GT(info.replaced_triangles, 1000u);
  }
}

TEST(DelaunayInsertion, RejectsBadInputWithoutChangingIt)
{
  Points points = {{0, 0}, {0, 10}, {10, 0}}; // sorted
  std::vector<Triangle> triangles, neighbours;
  ASSERT_TRUE(pcl::selective_seg::delaunay2d(points, DelaunayBackend::Sweep, triangles));
  pcl::selective_seg::computeTriangleNeighbours(triangles, points.size(), neighbours);
  const auto p0 = points;
  const auto t0 = triangles;
  DelaunayInsertion info;
  std::string why;
  EXPECT_FALSE(pcl::selective_seg::insertDelaunayPoints(
      points, triangles, neighbours, {{10, 0}}, info, &why)); // already there
  EXPECT_NE(why.find("already"), std::string::npos);
  EXPECT_FALSE(pcl::selective_seg::insertDelaunayPoints(
      points, triangles, neighbours, {{5, 5}, {5, 5}}, info)); // repeated
  EXPECT_FALSE(pcl::selective_seg::insertDelaunayPoints(
      points,
      triangles,
      neighbours,
      {{pcl::selective_seg::kMaxDelaunayCoordinate + 1, 0}},
      info)); // out of range
  // INT_MIN: std::abs() of it is undefined (it passed the range check).
  EXPECT_FALSE(pcl::selective_seg::insertDelaunayPoints(
      points,
      triangles,
      neighbours,
      {{std::numeric_limits<std::int32_t>::min(), 0}},
      info));
  EXPECT_EQ(points, p0);
  EXPECT_EQ(triangles, t0);
  // An old point out of range (not from delaunay2d(), which refuses it).
  {
    Points far = {{std::numeric_limits<std::int32_t>::min(), 0}, {0, 10}, {10, 0}};
    auto far_triangles = triangles;
    auto far_neighbours = neighbours;
    std::string far_why;
    EXPECT_FALSE(pcl::selective_seg::insertDelaunayPoints(
        far, far_triangles, far_neighbours, {{5, 2}}, info, &far_why));
    EXPECT_NE(far_why.find("out of range"), std::string::npos) << far_why;
  }
  // Nothing to insert: the identity.
  EXPECT_TRUE(
      pcl::selective_seg::insertDelaunayPoints(points, triangles, neighbours, {}, info));
  EXPECT_EQ(triangles, t0);
  EXPECT_EQ(info.old_to_new_triangle, (std::vector<pcl::index_t>{0}));
  // No triangles to insert into (collinear points): refused, the caller starts over.
  Points line = {{0, 0}, {1, 1}, {2, 2}};
  std::vector<Triangle> none, none_nb;
  EXPECT_FALSE(
      pcl::selective_seg::insertDelaunayPoints(line, none, none_nb, {{0, 5}}, info));
}

TEST(DelaunayInsertion, ThousandsOfSmallDegenerateInputs)
{
  // Points on a 9 x 9 grid: collinear and co-circular groups everywhere.
  std::mt19937 rng(7);
  int compared = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Points base = sortedUnique(uniform(3 + trial % 30, 0, 8, rng));
    std::vector<Triangle> tris;
    ASSERT_TRUE(pcl::selective_seg::delaunay2d(base, DelaunayBackend::Sweep, tris));
    const Points extra = without(base, uniform(1 + trial % 7, -2, 10, rng));
    if (tris.empty() || extra.empty())
      continue; // collinear base: nothing to insert into
    insertAndCompare(base, extra, rng);
    ++compared;
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "trial " << trial;
      break;
    }
  }
  EXPECT_GT(compared, 2000);
}
