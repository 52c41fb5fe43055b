/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/delaunay_2d.h>

#include <gtest/gtest.h>

#include "delaunay_2d_backends.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace {

using pcl::index_t;
using pcl::selective_seg::computeTriangleNeighbours;
using pcl::selective_seg::delaunay2d;
using pcl::selective_seg::DelaunayBackend;
using pcl::selective_seg::isDelaunayBackendAvailable;
using pcl::selective_seg::kMaxDelaunayCoordinate;
using pcl::selective_seg::QuantizedPoint;
using pcl::selective_seg::Triangle;

using Points = std::vector<QuantizedPoint>;
using Triangles = std::vector<Triangle>;
using Edge = std::pair<index_t, index_t>;

__extension__ typedef __int128 Int128;

// ------------------------------------------------------------- exact predicates

/** Twice the signed area of (o, a, b); exact for |coordinate| <= 2^26. */
std::int64_t
cross(const QuantizedPoint& o, const QuantizedPoint& a, const QuantizedPoint& b)
{
  return (std::int64_t{a[0]} - o[0]) * (std::int64_t{b[1]} - o[1]) -
         (std::int64_t{a[1]} - o[1]) * (std::int64_t{b[0]} - o[0]);
}

/** Positive iff d is strictly inside the circumcircle of the counter-clockwise triangle
 * (a, b, c): the lifted 3x3 determinant with rows (dx, dy, dx^2 + dy^2) of b, c and d
 * relative to a (the library lifts relative to d instead), negated since it is negative
 * for d inside. Exact: the terms stay below 2^112 for |coordinate| <= 2^26. */
Int128
insideCircle(const QuantizedPoint& a,
             const QuantizedPoint& b,
             const QuantizedPoint& c,
             const QuantizedPoint& d)
{
  const auto row = [&](const QuantizedPoint& p) {
    const std::int64_t x = std::int64_t{p[0]} - a[0], y = std::int64_t{p[1]} - a[1];
    return std::array<std::int64_t, 3>{x, y, x * x + y * y};
  };
  const auto rb = row(b), rc = row(c), rd = row(d);
  const Int128 det = Int128{rb[2]} * (rc[0] * rd[1] - rc[1] * rd[0]) -
                     Int128{rc[2]} * (rb[0] * rd[1] - rb[1] * rd[0]) +
                     Int128{rd[2]} * (rb[0] * rc[1] - rb[1] * rc[0]);
  return -det;
}

// -------------------------------------------------------------------- helpers

Triangles
triangulate(const Points& points,
            DelaunayBackend backend = DelaunayBackend::BoostVoronoi)
{
  Triangles triangles;
  std::string error;
  EXPECT_TRUE(delaunay2d(points, backend, triangles, &error)) << error;
  return triangles;
}

/** Each triangle rotated to start at its smallest id, the list sorted. */
Triangles
canonical(Triangles triangles)
{
  for (auto& t : triangles)
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

/** Convex hull corners, counter-clockwise, no collinear points (monotone chain). */
Points
strictHull(Points points)
{
  std::sort(points.begin(), points.end());
  Points hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0)
      --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0)
      --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

/** For each point, whether it lies on the boundary of the convex hull (corners and
 * points collinear with a hull edge). */
std::vector<char>
onHullBoundary(const Points& points)
{
  const Points hull = strictHull(points);
  std::vector<char> on(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = 0; j < hull.size() && !on[i]; ++j) {
      const QuantizedPoint& a = hull[j];
      const QuantizedPoint& b = hull[(j + 1) % hull.size()];
      const QuantizedPoint& p = points[i];
      on[i] = cross(a, b, p) == 0 && std::min(a[0], b[0]) <= p[0] &&
              p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
              p[1] <= std::max(a[1], b[1]);
    }
  }
  return on;
}

std::int64_t
twiceHullArea(const Points& points)
{
  const Points hull = strictHull(points);
  std::int64_t area = 0;
  for (std::size_t j = 1; j + 1 < hull.size(); ++j)
    area += cross(hull[0], hull[j], hull[j + 1]);
  return area;
}

/** Directed edge (a, b) of a triangle -> (triangle, its third vertex). */
std::map<Edge, std::pair<index_t, index_t>>
directedEdges(const Triangles& triangles, bool& unique)
{
  std::map<Edge, std::pair<index_t, index_t>> edges;
  unique = true;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int i = 0; i < 3; ++i) {
      const Edge e{triangles[t][(i + 1) % 3], triangles[t][(i + 2) % 3]};
      unique =
          edges.emplace(e, std::make_pair(static_cast<index_t>(t), triangles[t][i]))
              .second &&
          unique;
    }
  }
  return edges;
}

std::size_t
cornerCount(const Triangle& t, index_t v)
{
  return static_cast<std::size_t>(std::count(t.begin(), t.end(), v));
}

index_t
findRoot(std::vector<index_t>& parent, index_t t)
{
  while (parent[t] != t)
    t = parent[t] = parent[parent[t]];
  return t;
}

/** A pair of triangles sharing an edge, and the vertex of u opposite that edge. */
struct InteriorEdge {
  index_t t, u, apex_u;
};

std::vector<InteriorEdge>
interiorEdges(const Triangles& triangles)
{
  bool unique = true;
  const auto edges = directedEdges(triangles, unique);
  std::vector<InteriorEdge> interior;
  for (const auto& [edge, owner] : edges) {
    const auto twin = edges.find({edge.second, edge.first});
    if (edge.first < edge.second && twin != edges.end())
      interior.push_back({owner.first, twin->second.first, twin->second.second});
  }
  return interior;
}

Int128
insideCircleAcross(const Points& points,
                   const Triangles& triangles,
                   const InteriorEdge& e)
{
  const Triangle& t = triangles[e.t];
  return insideCircle(points[t[0]], points[t[1]], points[t[2]], points[e.apex_u]);
}

std::size_t
countCoCircularEdges(const Points& points, const Triangles& triangles)
{
  std::size_t count = 0;
  for (const auto& e : interiorEdges(triangles))
    count += insideCircleAcross(points, triangles, e) == 0;
  return count;
}

// ---------------------------------------------------------------- the checker

::testing::AssertionResult
checkCanonicalOrder(const Triangles& triangles)
{
  for (const auto& t : triangles)
    if (!(t[0] < t[1] && t[0] < t[2]))
      return ::testing::AssertionFailure() << "triangle not rotated to its smallest id";
  if (!std::is_sorted(triangles.begin(), triangles.end()))
    return ::testing::AssertionFailure() << "triangle list not sorted";
  if (std::adjacent_find(triangles.begin(), triangles.end()) != triangles.end())
    return ::testing::AssertionFailure() << "repeated triangle";
  return ::testing::AssertionSuccess();
}

/** Ids in range, every triangle counter-clockwise, areas summing to the hull's area and
 * the Euler count T = 2n - 2 - h. */
::testing::AssertionResult
checkCoverage(const Points& points, const Triangles& triangles, std::size_t h)
{
  const auto n = static_cast<index_t>(points.size());
  std::int64_t area = 0;
  for (const auto& t : triangles) {
    for (const index_t v : t)
      if (v < 0 || v >= n)
        return ::testing::AssertionFailure() << "vertex id " << v << " out of range";
    const std::int64_t o = cross(points[t[0]], points[t[1]], points[t[2]]);
    if (o <= 0)
      return ::testing::AssertionFailure()
             << "triangle " << t[0] << " " << t[1] << " " << t[2] << " not CCW";
    area += o;
  }
  if (area != twiceHullArea(points))
    return ::testing::AssertionFailure() << "triangles do not tile the convex hull";
  if (triangles.size() != 2 * points.size() - 2 - h)
    return ::testing::AssertionFailure()
           << triangles.size() << " triangles, expected 2 * " << points.size()
           << " - 2 - " << h;
  return ::testing::AssertionSuccess();
}

/** Every directed edge used once (so every edge by at most two triangles, oppositely),
 * and as many boundary edges as points on the hull boundary. */
::testing::AssertionResult
checkEdges(const Triangles& triangles, std::size_t h)
{
  bool unique = true;
  const auto edges = directedEdges(triangles, unique);
  if (!unique)
    return ::testing::AssertionFailure() << "a directed edge is used twice";
  std::size_t boundary = 0;
  for (const auto& entry : edges)
    boundary += edges.count({entry.first.second, entry.first.first}) == 0;
  if (boundary != h)
    return ::testing::AssertionFailure()
           << boundary << " boundary edges, " << h << " points on the hull boundary";
  return ::testing::AssertionSuccess();
}

/** No interior edge has its opposite vertex strictly inside the circumcircle. */
::testing::AssertionResult
checkEmptyCircles(const Points& points, const Triangles& triangles)
{
  for (const auto& e : interiorEdges(triangles))
    if (insideCircleAcross(points, triangles, e) > 0)
      return ::testing::AssertionFailure()
             << "vertex " << e.apex_u << " inside the circumcircle of triangle " << e.t;
  return ::testing::AssertionSuccess();
}

/** Each group of co-circular triangles is a fan from the group's lexicographically
 * smallest point: every triangle of the group contains that point. */
::testing::AssertionResult
checkCoCircularFans(const Points& points, const Triangles& triangles)
{
  std::vector<index_t> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& e : interiorEdges(triangles))
    if (insideCircleAcross(points, triangles, e) == 0)
      parent[findRoot(parent, e.u)] = findRoot(parent, e.t);
  std::vector<index_t> apex(triangles.size(), -1);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    index_t& a = apex[findRoot(parent, static_cast<index_t>(t))];
    for (const index_t v : triangles[t])
      if (a < 0 || points[v] < points[a])
        a = v;
  }
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const index_t a = apex[findRoot(parent, static_cast<index_t>(t))];
    if (cornerCount(triangles[t], a) == 0)
      return ::testing::AssertionFailure()
             << "co-circular triangle " << t << " misses the fan apex " << a;
  }
  return ::testing::AssertionSuccess();
}

/** The full check of a delaunay2d() result against independent computations. */
::testing::AssertionResult
isCanonicalDelaunay(const Points& points, const Triangles& triangles)
{
  const std::vector<char> on_hull = onHullBoundary(points);
  const auto h =
      static_cast<std::size_t>(std::count(on_hull.begin(), on_hull.end(), 1));
  auto result = checkCanonicalOrder(triangles);
  if (result)
    result = checkCoverage(points, triangles, h);
  if (result)
    result = checkEdges(triangles, h);
  if (result)
    result = checkEmptyCircles(points, triangles);
  if (result)
    result = checkCoCircularFans(points, triangles);
  return result;
}

// ------------------------------------------------------------- point sets

Points
distinctShuffled(Points points, std::mt19937& rng)
{
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

Points
uniformPoints(std::size_t n, std::int32_t range, std::mt19937& rng)
{
  std::uniform_int_distribution<std::int32_t> coordinate(-range, range);
  Points points(n);
  for (auto& p : points)
    p = {coordinate(rng), coordinate(rng)};
  return distinctShuffled(points, rng);
}

/** Gaussian clusters of very different spreads over a sparse uniform background. */
Points
clusteredPoints(std::size_t n, std::mt19937& rng)
{
  std::uniform_int_distribution<std::int32_t> centre(-100000, 100000);
  Points points = uniformPoints(n / 10, 200000, rng);
  for (const double sigma : {3.0, 30.0, 300.0, 3000.0, 30000.0}) {
    const double cx = centre(rng), cy = centre(rng);
    std::normal_distribution<double> dx(cx, sigma), dy(cy, sigma);
    for (std::size_t i = 0; i < n / 6; ++i)
      points.push_back({static_cast<std::int32_t>(std::lround(dx(rng))),
                        static_cast<std::int32_t>(std::lround(dy(rng)))});
  }
  return distinctShuffled(points, rng);
}

/** Random points snapped to a coarse grid: many co-circular quadruples and more. */
Points
snappedPoints(std::size_t n, std::int32_t cells, std::int32_t step, std::mt19937& rng)
{
  Points points = uniformPoints(n, cells, rng);
  for (auto& p : points)
    p = {p[0] * step - 7, p[1] * step + 3};
  return points;
}

/** nx * ny points (x0 + i * dx, y0 + j * dy), id i * ny + j. */
Points
gridPoints(
    int nx, int ny, std::int32_t x0, std::int32_t y0, std::int32_t dx, std::int32_t dy)
{
  Points points;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      points.push_back({x0 + i * dx, y0 + j * dy});
  return points;
}

/** An nx * ny lattice spanned by (a, b) and (-b, a): squares tilted off the axes. */
Points
rotatedLatticePoints(int nx, int ny, std::int32_t a, std::int32_t b)
{
  Points points;
  for (std::int32_t i = 0; i < nx; ++i)
    for (std::int32_t j = 0; j < ny; ++j)
      points.push_back({a * i - b * j, b * i + a * j});
  return points;
}

/** The lattice points of the circle of radius r around (cx, cy). */
Points
circleLatticePoints(std::int64_t r, std::int32_t cx, std::int32_t cy)
{
  Points points;
  for (std::int64_t x = -r; x <= r; ++x) {
    const std::int64_t y2 = r * r - x * x;
    const auto root = static_cast<std::int64_t>(std::sqrt(static_cast<double>(y2)));
    for (std::int64_t y = std::max<std::int64_t>(root - 1, 0); y <= root + 1; ++y) {
      if (y * y != y2)
        continue;
      points.push_back(
          {static_cast<std::int32_t>(cx + x), static_cast<std::int32_t>(cy + y)});
      if (y != 0)
        points.push_back(
            {static_cast<std::int32_t>(cx + x), static_cast<std::int32_t>(cy - y)});
    }
  }
  return points;
}

/** Whether the circumcircle of t lies inside the box [lo, hi] (floating point, for
 * selecting triangles well away from the hull). */
bool
circumcircleInsideBox(const Points& points,
                      const Triangle& t,
                      const QuantizedPoint& lo,
                      const QuantizedPoint& hi)
{
  const QuantizedPoint& a = points[t[0]];
  const double bx = points[t[1]][0] - a[0], by = points[t[1]][1] - a[1];
  const double cx = points[t[2]][0] - a[0], cy = points[t[2]][1] - a[1];
  const double d = 2 * (bx * cy - by * cx);
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double x = a[0] + (cy * b2 - by * c2) / d, y = a[1] + (bx * c2 - cx * b2) / d;
  const double r = std::hypot(x - a[0], y - a[1]) * 1.001;
  return x - r > lo[0] && x + r < hi[0] && y - r > lo[1] && y + r < hi[1];
}

/** Triangulates a shuffled copy and maps the ids back to \a points. */
Triangles
triangulatePermuted(const Points& points,
                    std::mt19937& rng,
                    DelaunayBackend backend = DelaunayBackend::BoostVoronoi)
{
  std::vector<index_t> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  Points shuffled(points.size());
  for (std::size_t k = 0; k < points.size(); ++k)
    shuffled[k] = points[order[k]];
  Triangles triangles = triangulate(shuffled, backend);
  for (auto& t : triangles)
    for (auto& v : t)
      v = order[v];
  return canonical(triangles);
}

Triangles
bruteForceNeighbours(const Triangles& triangles)
{
  Triangles neighbours(triangles.size(), Triangle{-1, -1, -1});
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int i = 0; i < 3; ++i)
      for (std::size_t u = 0; u < triangles.size(); ++u)
        for (int k = 0; k < 3; ++k)
          if (u != t && triangles[u][(k + 1) % 3] == triangles[t][(i + 2) % 3] &&
              triangles[u][(k + 2) % 3] == triangles[t][(i + 1) % 3])
            neighbours[t][i] = static_cast<index_t>(u);
  return neighbours;
}

/** A depth camera's pixel grid in (theta, phi): cols x rows points step apart, each
 * moved by up to x_jitter and y_jitter (x jitter of a unit or two splits a column into
 * interleaved sub-columns, as float rounding does in real scans), pixels dropped at
 * random and, if \a holes, in a few discs (missing depth); sorted like the vertices of
 * SphericalDelaunay. */
Points
depthImagePoints(int cols,
                 int rows,
                 std::int32_t step,
                 std::int32_t x_jitter,
                 std::int32_t y_jitter,
                 bool holes,
                 std::mt19937& rng)
{
  std::uniform_int_distribution<std::int32_t> dx(-x_jitter, x_jitter),
      dy(-y_jitter, y_jitter);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto in_hole = [&](int i, int j) {
    const double u = static_cast<double>(i) / cols, v = static_cast<double>(j) / rows;
    return holes && (std::hypot(u - 0.3, v - 0.6) < 0.08 ||
                     std::hypot(u - 0.7, v - 0.3) < 0.05 ||
                     (u > 0.95 && v > 0.5 + 10 * (1 - u)));
  };
  Points points;
  for (int i = 0; i < cols; ++i)
    for (int j = 0; j < rows; ++j)
      if (!in_hole(i, j) && unit(rng) > (holes ? 0.02 : 0.0))
        points.push_back({-step * cols / 2 + i * step + dx(rng),
                          -step * rows / 2 + j * step + dy(rng)});
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

/** Whether the sweep gives Boost's triangles exactly. */
::testing::AssertionResult
sweepMatchesBoost(const Points& points)
{
  const Triangles boost = triangulate(points, DelaunayBackend::BoostVoronoi);
  const Triangles sweep = triangulate(points, DelaunayBackend::Sweep);
  if (sweep == boost) {
    // The adjacency each backend gives with its triangles (the sweep's read off its
    // half-edges, across re-fanned co-circular groups) is the computed one.
    Triangles expected;
    computeTriangleNeighbours(boost, points.size(), expected);
    // Large inputs take the parallel paths: the same result for any thread count (the
    // sweep triangulates one slab of the points per thread and stitches them).
    for (const auto backend : {DelaunayBackend::Sweep, DelaunayBackend::BoostVoronoi})
      for (const unsigned int threads : {1u, 2u, 3u, 5u}) {
        if (backend == DelaunayBackend::BoostVoronoi && threads > 2)
          continue;
        Triangles triangles, neighbours;
        if (!pcl::selective_seg::delaunay2d(
                points, backend, triangles, neighbours, nullptr, threads) ||
            triangles != boost || neighbours != expected)
          return ::testing::AssertionFailure()
                 << points.size() << " points: the triangles or adjacency given by "
                 << pcl::selective_seg::toString(backend) << " with " << threads
                 << " threads differ";
      }
    return ::testing::AssertionSuccess();
  }
  const auto differ =
      std::mismatch(boost.begin(), boost.end(), sweep.begin(), sweep.end());
  return ::testing::AssertionFailure()
         << points.size() << " points: " << boost.size() << " triangles from boost, "
         << sweep.size() << " from the sweep, first difference at position "
         << (differ.first - boost.begin());
}

} // namespace

TEST(TriangleNeighbours, VertexIdsBeyondTheCountAreRefused)
{
  std::vector<pcl::selective_seg::Triangle> neighbours{{0, 0, 0}};
  pcl::selective_seg::computeTriangleNeighbours({{0, 1, 100000000}}, 3, neighbours);
  EXPECT_TRUE(neighbours.empty());
  pcl::selective_seg::computeTriangleNeighbours({{0, 1, 2}, {2, 1, 3}}, 4, neighbours);
  ASSERT_EQ(neighbours.size(), 2u);
  EXPECT_EQ(neighbours[0][0], 1); // the edge 1-2 opposite vertex 0
}

TEST(DelaunayBackend, NamesAndAvailability)
{
  EXPECT_STREQ(pcl::selective_seg::toString(DelaunayBackend::BoostVoronoi), "boost");
  EXPECT_STREQ(pcl::selective_seg::toString(DelaunayBackend::Vtk), "vtk");
  EXPECT_STREQ(pcl::selective_seg::toString(DelaunayBackend::Sweep), "sweep");
  EXPECT_TRUE(isDelaunayBackendAvailable(DelaunayBackend::BoostVoronoi));
  EXPECT_TRUE(isDelaunayBackendAvailable(DelaunayBackend::Sweep));
  EXPECT_FALSE(isDelaunayBackendAvailable(static_cast<DelaunayBackend>(7)));
}

TEST(DelaunayBackend, UnavailableBackendFails)
{
  std::vector<DelaunayBackend> unavailable{static_cast<DelaunayBackend>(7)};
  if (!isDelaunayBackendAvailable(DelaunayBackend::Vtk))
    unavailable.push_back(DelaunayBackend::Vtk);
  const Points points{{0, 0}, {5, 0}, {0, 5}};
  for (const auto backend : unavailable) {
    Triangles triangles{{0, 1, 2}};
    std::string error;
    EXPECT_FALSE(delaunay2d(points, backend, triangles, &error));
    EXPECT_TRUE(triangles.empty());
    EXPECT_NE(error.find("not available"), std::string::npos) << error;
  }
}

TEST(DelaunayBackend, DuplicatePointsAreRejectedWithOneMessage)
{
  // Sorted input too: the sweep checks sorted input separately.
  for (const Points& points : {Points{{0, 0}, {5, 0}, {0, 5}, {3, 3}, {5, 0}},
                               Points{{0, 0}, {0, 5}, {3, 3}, {5, 0}, {5, 0}}}) {
    std::string boost_error;
    for (const auto backend : {DelaunayBackend::BoostVoronoi,
                               DelaunayBackend::Sweep,
                               DelaunayBackend::Vtk}) {
      if (!isDelaunayBackendAvailable(backend))
        continue;
      Triangles triangles{{0, 1, 2}};
      std::string error;
      EXPECT_FALSE(delaunay2d(points, backend, triangles, &error));
      EXPECT_TRUE(triangles.empty());
      EXPECT_NE(error.find("duplicate"), std::string::npos) << error;
      if (backend == DelaunayBackend::BoostVoronoi)
        boost_error = error;
      if (backend == DelaunayBackend::Sweep) {
        EXPECT_EQ(error, boost_error);
      }
    }
  }
}

namespace pcl {
namespace selective_seg {

/** Test lists name the backend parameter ("boost", "sweep"). */
void
PrintTo(DelaunayBackend backend, std::ostream* os)
{
  *os << toString(backend);
}

} // namespace selective_seg
} // namespace pcl

/** The exact backends: every exactness test runs on each of them. */
class Delaunay2D : public ::testing::TestWithParam<DelaunayBackend> {};

INSTANTIATE_TEST_SUITE_P(Exact,
                         Delaunay2D,
                         ::testing::Values(DelaunayBackend::BoostVoronoi,
                                           DelaunayBackend::Sweep),
                         [](const ::testing::TestParamInfo<DelaunayBackend>& info) {
                           return std::string(pcl::selective_seg::toString(info.param));
                         });

TEST_P(Delaunay2D, ThreePointsGiveOneCounterClockwiseTriangle)
{
  // Given clockwise: (0, 0), (0, 10), (10, 0).
  const Points points{{0, 0}, {0, 10}, {10, 0}};
  EXPECT_EQ(triangulate(points, GetParam()), (Triangles{{0, 2, 1}}));
}

TEST_P(Delaunay2D, SquareIsSplitByTheFanFromItsSmallestPoint)
{
  // The smallest point (0, 0) is id 1, so the diagonal is 1 - 0, not 2 - 3.
  const Points points{{1, 1}, {0, 0}, {1, 0}, {0, 1}};
  const Triangles triangles = triangulate(points, GetParam());
  EXPECT_EQ(triangles, (Triangles{{0, 1, 2}, {0, 3, 1}}));
  EXPECT_TRUE(isCanonicalDelaunay(points, triangles));
}

TEST_P(Delaunay2D, CoCircularQuadrilateralsFollowTheFanInEveryInputOrder)
{
  // Corners counter-clockwise from the smallest one: the fan is (0, 1, 2), (0, 2, 3).
  const std::vector<Points> shapes{{{0, 0}, {2, 0}, {2, 1}, {0, 1}},
                                   {{0, 0}, {6, 0}, {4, 3}, {2, 3}},
                                   {{-5, 0}, {0, -5}, {5, 0}, {0, 5}}};
  for (const Points& corners : shapes) {
    std::array<index_t, 4> order{0, 1, 2, 3};
    do {
      Points points(4);
      std::array<index_t, 4> id{};
      for (index_t k = 0; k < 4; ++k) {
        points[k] = corners[order[k]];
        id[order[k]] = k;
      }
      EXPECT_EQ(triangulate(points, GetParam()),
                canonical({{id[0], id[1], id[2]}, {id[0], id[2], id[3]}}));
    } while (std::next_permutation(order.begin(), order.end()));
  }
}

TEST_P(Delaunay2D, RegularGridFollowsTheCanonicalDiagonals)
{
  // 5 x 10 grid of 7 x 5 rectangles (each co-circular), id i * 10 + j at column i, row
  // j. The smallest corner of a cell is its lower left one: every diagonal starts
  // there.
  const Points points = gridPoints(5, 10, -20, -30, 7, 5);
  const Triangles triangles = triangulate(points, GetParam());
  ASSERT_EQ(triangles.size(), 2u * (5 - 1) * (10 - 1));
  Triangles expected;
  for (index_t i = 0; i + 1 < 5; ++i) {
    for (index_t j = 0; j + 1 < 10; ++j) {
      const index_t ll = i * 10 + j, lr = ll + 10, ur = ll + 11, ul = ll + 1;
      expected.push_back({ll, lr, ur});
      expected.push_back({ll, ur, ul});
    }
  }
  EXPECT_EQ(triangles, canonical(expected));
  // Cell (0, 0): corners 0, 10, 11, 1; cell (3, 8): corners 38, 48, 49, 39.
  const auto has = [&](const Triangle& t) {
    return std::binary_search(triangles.begin(), triangles.end(), t);
  };
  EXPECT_TRUE(has({0, 10, 11}) && has({0, 11, 1}));
  EXPECT_TRUE(has({38, 48, 49}) && has({38, 49, 39}));
  EXPECT_FALSE(has({1, 10, 11}) || has({0, 10, 1}));
  EXPECT_TRUE(isCanonicalDelaunay(points, triangles));
  // The same ids for the grid spread over most of the coordinate range.
  const std::int32_t step = 1 << 23;
  const Points wide =
      gridPoints(5, 10, -4 * step + 3, -9 * (step / 2) - 1, 2 * step, step);
  EXPECT_EQ(triangulate(wide, GetParam()), triangles);
}

TEST_P(Delaunay2D, CollinearPointsGiveNoTriangles)
{
  Points points;
  for (std::int32_t k : {5, -3, 0, 11, 2, -9})
    points.push_back({100 + 3 * k, -50 - 2 * k});
  Triangles triangles{{0, 1, 2}};
  std::string error;
  EXPECT_TRUE(delaunay2d(points, GetParam(), triangles, &error));
  EXPECT_TRUE(triangles.empty());
  EXPECT_TRUE(error.empty());
}

TEST_P(Delaunay2D, FewerThanThreePointsGiveNoTriangles)
{
  for (const Points& points : {Points{}, Points{{1, 2}}, Points{{1, 2}, {3, 4}}}) {
    Triangles triangles{{0, 1, 2}};
    EXPECT_TRUE(delaunay2d(points, GetParam(), triangles));
    EXPECT_TRUE(triangles.empty());
  }
}

TEST_P(Delaunay2D, OutOfRangeCoordinatesAreRejected)
{
  const std::int32_t max = kMaxDelaunayCoordinate;
  for (const QuantizedPoint& bad :
       {QuantizedPoint{max + 1, 0},
        QuantizedPoint{0, -max - 1},
        QuantizedPoint{std::numeric_limits<std::int32_t>::min(), 0}}) {
    const Points points{{0, 0}, {5, 0}, {0, 5}, bad};
    Triangles triangles{{0, 1, 2}};
    std::string error;
    EXPECT_FALSE(delaunay2d(points, GetParam(), triangles, &error));
    EXPECT_TRUE(triangles.empty());
    EXPECT_FALSE(error.empty());
  }
  // The limits themselves are accepted.
  const Points corners{{-max, -max}, {max, -max}, {max, max}, {-max, max}, {1, 2}};
  EXPECT_TRUE(isCanonicalDelaunay(corners, triangulate(corners, GetParam())));
}

TEST_P(Delaunay2D, RandomPointsAreDelaunay)
{
  std::mt19937 rng(42);
  const Points small_range = uniformPoints(3000, 1000, rng);
  EXPECT_TRUE(isCanonicalDelaunay(small_range, triangulate(small_range, GetParam())));
  const Points full_range = uniformPoints(3000, kMaxDelaunayCoordinate, rng);
  EXPECT_TRUE(isCanonicalDelaunay(full_range, triangulate(full_range, GetParam())));
  const Points clustered = clusteredPoints(4000, rng);
  EXPECT_TRUE(isCanonicalDelaunay(clustered, triangulate(clustered, GetParam())));
}

TEST_P(Delaunay2D, SnappedPointsAreDelaunayAndCanonical)
{
  std::mt19937 rng(42);
  for (const std::int32_t cells : {20, 45}) {
    const Points points = snappedPoints(2500, cells, 64, rng);
    const Triangles triangles = triangulate(points, GetParam());
    EXPECT_TRUE(isCanonicalDelaunay(points, triangles));
    EXPECT_GT(countCoCircularEdges(points, triangles), points.size() / 10);
  }
}

TEST_P(Delaunay2D, NearlyCoCircularPointsAreTriangulatedExactly)
{
  // Far from the origin, Boost.Polygon merges the circumcentres of these four points
  // (1/(2R) apart, a few ULPs); they are not co-circular, so the triangulation must
  // still be the exact one: the diagonal avoiding the point just outside the circle.
  const std::int32_t c = 1 << 25, r = 9765625; // r = 5^10
  const Points left_moved{{c + r, c}, {c, c - r}, {c - r, c + 1}, {c, c + r}};
  EXPECT_EQ(triangulate(left_moved, GetParam()), (Triangles{{0, 3, 1}, {1, 3, 2}}));
  const Points top_moved{{c + r, c}, {c, c - r}, {c - r, c}, {c + 1, c + r}};
  EXPECT_EQ(triangulate(top_moved, GetParam()), (Triangles{{0, 2, 1}, {0, 3, 2}}));
  const Points on_circle{{c + r, c}, {c, c - r}, {c - r, c}, {c, c + r}};
  EXPECT_EQ(triangulate(on_circle, GetParam()), (Triangles{{0, 2, 1}, {0, 3, 2}}));
}

TEST_P(Delaunay2D, CoCircularGroupNextToANearlyCoCircularPointIsAFan)
{
  // Twelve lattice points of one circle, point 2 moved just outside along the tangent.
  // Boost.Polygon merges all of them into one vertex; the eleven co-circular ones must
  // still form the fan from their smallest point, 9, and point 2 caps edge 7 - 9.
  const std::int32_t c = 1 << 25, r = 9765625, a = r / 5 * 3, b = r / 5 * 4;
  const Points points{{c + r, c},
                      {c, c + r},
                      {c - r, c + 1},
                      {c, c - r},
                      {c + a, c + b},
                      {c + b, c + a},
                      {c - a, c + b},
                      {c - b, c + a},
                      {c - a, c - b},
                      {c - b, c - a},
                      {c + a, c - b},
                      {c + b, c - a}};
  const Triangles triangles = triangulate(points, GetParam());
  EXPECT_EQ(triangles,
            (Triangles{{0, 5, 9},
                       {0, 9, 11},
                       {1, 6, 9},
                       {1, 9, 4},
                       {2, 9, 7},
                       {3, 9, 8},
                       {3, 10, 9},
                       {4, 9, 5},
                       {6, 7, 9},
                       {9, 10, 11}}));
  EXPECT_TRUE(isCanonicalDelaunay(points, triangles));
}

TEST_P(Delaunay2D, CoCircularAndNearlyCoCircularStress)
{
  std::mt19937 rng(42);
  const std::int32_t c = 1 << 25;
  // r = 5^2 * 13 * 17 * 29: 540 lattice points on one circle, a third of them moved by
  // one unit, roughly along the tangent.
  Points points = circleLatticePoints(160225, c, -c);
  ASSERT_EQ(points.size(), 540u);
  for (std::size_t k = 0; k < points.size(); k += 3) {
    const std::int64_t dx = points[k][0] - c, dy = points[k][1] + c;
    points.push_back(std::abs(dx) > std::abs(dy)
                         ? QuantizedPoint{points[k][0], points[k][1] + 1}
                         : QuantizedPoint{points[k][0] + 1, points[k][1]});
  }
  // Far-away circles through four axis points, one of them moved along the tangent.
  std::int32_t r = 9765625;
  for (const std::int32_t cx : {-c, c}) {
    for (const std::int32_t cy : {c, -3 * (c / 2)}) {
      const Points quad{{cx + r, cy}, {cx, cy - r}, {cx - r, cy + 1}, {cx + 1, cy + r}};
      points.insert(points.end(), quad.begin(), quad.end());
      r = r / 5 * 3;
    }
  }
  points = distinctShuffled(points, rng);
  const Triangles triangles = triangulate(points, GetParam());
  EXPECT_TRUE(isCanonicalDelaunay(points, triangles));
  EXPECT_EQ(triangulatePermuted(points, rng, GetParam()), triangles);
}

TEST_P(Delaunay2D, ResultIsPermutationInvariant)
{
  std::mt19937 rng(42);
  const std::vector<Points> sets{uniformPoints(2000, 5000, rng),
                                 snappedPoints(2000, 30, 16, rng),
                                 gridPoints(23, 17, -100, 40, 3, 3),
                                 rotatedLatticePoints(20, 30, 1234567, 654321),
                                 circleLatticePoints(5525, 0, 0)};
  for (const Points& points : sets) {
    const Triangles triangles = triangulate(points, GetParam());
    EXPECT_TRUE(isCanonicalDelaunay(points, triangles));
    for (int round = 0; round < 3; ++round)
      EXPECT_EQ(triangulatePermuted(points, rng, GetParam()), triangles);
  }
}

// The sweep must give exactly Boost's triangles: same canonical lists, on general
// position, co-circular and collinear points, sorted and unsorted input.

TEST(SweepMatchesBoost, RandomAndClusteredPoints)
{
  std::mt19937 rng(7);
  for (const std::size_t n : {10, 100, 1000, 20000}) {
    for (const std::int32_t range : {50, 1000, 1 << 20, kMaxDelaunayCoordinate}) {
      Points points = uniformPoints(n, range, rng);
      EXPECT_TRUE(sweepMatchesBoost(points)) << "uniform, range " << range;
      std::sort(points.begin(), points.end());
      EXPECT_TRUE(sweepMatchesBoost(points)) << "uniform sorted, range " << range;
    }
  }
  EXPECT_TRUE(sweepMatchesBoost(clusteredPoints(20000, rng)));
}

TEST(SweepMatchesBoost, CoCircularAndLatticePoints)
{
  std::mt19937 rng(7);
  for (const std::int32_t cells : {3, 10, 45, 200})
    EXPECT_TRUE(sweepMatchesBoost(snappedPoints(5000, cells, 64, rng))) << cells;
  EXPECT_TRUE(sweepMatchesBoost(gridPoints(1, 50, 0, 0, 3, 5)));
  EXPECT_TRUE(sweepMatchesBoost(gridPoints(2, 50, 0, 0, 3, 5)));
  EXPECT_TRUE(sweepMatchesBoost(gridPoints(60, 40, -100, 40, 3, 7)));
  EXPECT_TRUE(sweepMatchesBoost(rotatedLatticePoints(20, 30, 1234567, 654321)));
  EXPECT_TRUE(sweepMatchesBoost(rotatedLatticePoints(30, 40, 4, 3)));
  EXPECT_TRUE(sweepMatchesBoost(circleLatticePoints(5525, 0, 0)));
  Points circle_and_centre = circleLatticePoints(160225, 1 << 25, -(1 << 25));
  circle_and_centre.push_back({1 << 25, -(1 << 25)});
  EXPECT_TRUE(sweepMatchesBoost(circle_and_centre));
}

TEST(SweepMatchesBoost, DepthImageLikeGrids)
{
  std::mt19937 rng(7);
  // Sorted, as SphericalDelaunay passes them: exact grid, jittered, sub-columns.
  EXPECT_TRUE(sweepMatchesBoost(depthImagePoints(640, 480, 16000, 0, 0, false, rng)));
  EXPECT_TRUE(sweepMatchesBoost(depthImagePoints(640, 480, 16000, 1, 1, false, rng)));
  EXPECT_TRUE(sweepMatchesBoost(depthImagePoints(640, 480, 16000, 1, 40, true, rng)));
  EXPECT_TRUE(
      sweepMatchesBoost(depthImagePoints(320, 240, 16000, 2000, 2000, true, rng)));
  // Unsorted.
  Points points = depthImagePoints(320, 240, 16000, 1, 1, true, rng);
  std::shuffle(points.begin(), points.end(), rng);
  EXPECT_TRUE(sweepMatchesBoost(points));
}

TEST(SweepMatchesBoost, TinyAndDegenerateInputs)
{
  std::mt19937 rng(7);
  for (int round = 0; round < 3000; ++round) {
    // A few points in a tiny range: collinear and co-circular subsets everywhere.
    const std::int32_t range = 1 + round % 6;
    Points points = uniformPoints(3 + round % 30, range, rng);
    EXPECT_TRUE(sweepMatchesBoost(points)) << "round " << round;
    // The same far from the origin, stretched.
    const std::int32_t scale = 1 + static_cast<std::int32_t>(rng() % 4000000);
    const std::int32_t offset = static_cast<std::int32_t>(rng() % 20000000) - 10000000;
    for (auto& p : points)
      p = {p[0] * scale / 8 + offset, p[1] * scale / 8 - offset};
    EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(points, rng))) << "round " << round;
  }
  for (int round = 0; round < 300; ++round) {
    // Points on a line, plus none to three others.
    const std::int32_t dx = static_cast<std::int32_t>(rng() % 5) - 2;
    const std::int32_t dy = dx == 0 ? 1 : static_cast<std::int32_t>(rng() % 5) - 2;
    Points points;
    for (std::int32_t k = 0; k < 2 + round % 40; ++k)
      points.push_back({k * dx, k * dy});
    for (int extra = round % 4; extra > 0; --extra)
      points.push_back({static_cast<std::int32_t>(rng() % 21) - 10,
                        static_cast<std::int32_t>(rng() % 21) - 10});
    EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(points, rng))) << "round " << round;
  }
}

TEST(SweepMatchesBoost, PointsAtTheCoordinateLimits)
{
  std::mt19937 rng(7);
  const std::int32_t max = kMaxDelaunayCoordinate;
  std::uniform_int_distribution<std::int32_t> any(-max, max), near(0, 2);
  for (int round = 0; round < 200; ++round) {
    Points corners, flat;
    for (int k = 0; k < 3 + round % 50; ++k) {
      const bool at_limit = rng() % 3 == 0;
      corners.push_back({at_limit ? (rng() % 2 ? max : -max) : any(rng),
                         rng() % 3 == 0 ? (rng() % 2 ? max : -max) : any(rng)});
      flat.push_back({rng() % 2 ? max - near(rng) : -max + near(rng), any(rng) % 4});
    }
    EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(corners, rng))) << "round " << round;
    EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(flat, rng))) << "round " << round;
  }
}

TEST(SweepMatchesBoost, LinesAndCurves)
{
  // Long collinear runs beside a single point, and points along concave curves, on
  // which the sweep gives up after its flip budget and returns Boost's triangles.
  const std::int32_t n = 3000;
  for (const QuantizedPoint& single : {QuantizedPoint{n / 2, 5},
                                       QuantizedPoint{n / 2, -5},
                                       QuantizedPoint{-5, n / 2},
                                       QuantizedPoint{n + 5, n / 2}}) {
    Points row, column;
    for (std::int32_t k = 0; k < n; ++k) {
      row.push_back({k, 0});
      column.push_back({0, k});
    }
    row.push_back(single);
    column.push_back({single[1], single[0]});
    EXPECT_TRUE(sweepMatchesBoost(row));
    EXPECT_TRUE(sweepMatchesBoost(column));
  }
  const std::int32_t m = 20000;
  Points opening_right, opening_up;
  for (std::int32_t k = -m / 2; k < m / 2; ++k) {
    const auto bend = static_cast<std::int32_t>(std::int64_t{k} * k / (m / 16));
    opening_right.push_back({bend, k});
    opening_up.push_back({k, bend});
  }
  EXPECT_TRUE(sweepMatchesBoost(opening_right));
  EXPECT_TRUE(sweepMatchesBoost(opening_up));
}

// The sweep on several threads triangulates slabs of the points (split between
// distinct x) and re-triangulates the triangles whose circumdisks reach a neighbouring
// slab. Inputs that stress the stitching: every split inside a run of equal x, lattices
// (co-circular groups across the seams), flat strips (most circumdisks cross the
// seams), far-apart clusters (wide gaps between the slabs' hulls), a collinear slab (no
// triangulation of its own: the sweep runs in one piece), and slabs of very different
// sizes.
/** Whether the sweep's slab path, with 1 to 7 slabs, gives Boost's triangles and their
 * adjacency; \a applies: whether it is expected to apply (no collinear slab). */
::testing::AssertionResult
slabsMatchBoost(Points points, bool applies = true)
{
  std::sort(points.begin(), points.end());
  const Triangles boost = triangulate(points, DelaunayBackend::BoostVoronoi);
  Triangles expected;
  computeTriangleNeighbours(boost, points.size(), expected);
  for (const int slabs : {1, 2, 3, 4, 7}) {
    Triangles triangles, neighbours;
    const bool done = pcl::selective_seg::detail::delaunaySweepInSlabs(
        points, slabs, triangles, neighbours);
    if (done != applies)
      return ::testing::AssertionFailure()
             << points.size() << " points, " << slabs << " slabs: the slab path "
             << (done ? "applied" : "did not apply");
    if (done && (triangles != boost || neighbours != expected))
      return ::testing::AssertionFailure()
             << points.size() << " points, " << slabs << " slabs: "
             << triangles.size() << " triangles against " << boost.size()
             << " from Boost, or a different adjacency";
  }
  return ::testing::AssertionSuccess();
}

TEST(SweepMatchesBoost, SlabsAreStitchedExactly)
{
  std::mt19937 rng(11);
  // The slab path called directly, with 1 to 7 slabs whatever the size.
  EXPECT_TRUE(slabsMatchBoost(gridPoints(40, 30, -300, 500, 4, 6)));
  EXPECT_TRUE(slabsMatchBoost(gridPoints(31, 31, 0, 0, 1, 1)));
  EXPECT_TRUE(slabsMatchBoost(rotatedLatticePoints(20, 25, 4, 3)));
  EXPECT_TRUE(slabsMatchBoost(circleLatticePoints(5525, 0, 0)));
  EXPECT_TRUE(slabsMatchBoost(depthImagePoints(60, 50, 16000, 1, 40, true, rng)));
  EXPECT_TRUE(slabsMatchBoost(depthImagePoints(60, 50, 16000, 0, 0, false, rng)));
  EXPECT_TRUE(slabsMatchBoost(uniformPoints(2000, 1 << 20, rng)));
  EXPECT_TRUE(slabsMatchBoost(gridPoints(1, 50, 0, 0, 3, 5), false));
  // Small inputs in a tiny range: collinear and co-circular subsets everywhere, and
  // slabs of a few points. Where a slab is collinear the path does not apply.
  int applied = 0;
  for (int round = 0; round < 2000; ++round) {
    Points points = uniformPoints(12 + round % 40, 2 + round % 7, rng);
    std::sort(points.begin(), points.end());
    const Triangles boost = triangulate(points, DelaunayBackend::BoostVoronoi);
    Triangles expected;
    computeTriangleNeighbours(boost, points.size(), expected);
    for (const int slabs : {2, 3}) {
      Triangles triangles, neighbours;
      if (!pcl::selective_seg::detail::delaunaySweepInSlabs(
              points, slabs, triangles, neighbours))
        continue;
      ++applied;
      EXPECT_TRUE(triangles == boost && neighbours == expected)
          << "round " << round << ", " << slabs << " slabs";
    }
  }
  EXPECT_GT(applied, 2000); // of 4000: most inputs have no collinear slab
  // Through delaunay2d() on several threads (slabs of at least 2,048 points):
  // Columns of 200 points with equal x: the slab ends move to the next column.
  EXPECT_TRUE(sweepMatchesBoost(gridPoints(150, 200, -3000, -5000, 40, 50)));
  // Axis-aligned and tilted lattices: co-circular squares at every seam.
  EXPECT_TRUE(sweepMatchesBoost(gridPoints(181, 181, 7, -9, 3, 3)));
  EXPECT_TRUE(sweepMatchesBoost(rotatedLatticePoints(130, 140, 4, 3)));
  // A flat strip: circumdisks far larger than the slabs.
  Points strip;
  for (int k = 0; k < 40000; ++k)
    strip.push_back({static_cast<std::int32_t>(rng() % 20000000),
                     static_cast<std::int32_t>(rng() % 50)});
  EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(strip, rng)));
  // Clusters far apart in x, and one column holding half of the points.
  Points clusters, column;
  for (int k = 0; k < 36000; ++k) {
    const std::int32_t centre = (k % 3) * 20000000 - 20000000;
    clusters.push_back({centre + static_cast<std::int32_t>(rng() % 2001) - 1000,
                        static_cast<std::int32_t>(rng() % 2001) - 1000});
    if (k % 2)
      column.push_back({0, k});
    else
      column.push_back({1 + static_cast<std::int32_t>(rng() % 30000),
                        static_cast<std::int32_t>(rng() % 30000)});
  }
  EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(clusters, rng)));
  EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(column, rng)));
  // Dense and sparse halves (slabs of equal counts, very different widths), and
  // random points at the coordinate limits.
  Points uneven = uniformPoints(30000, 1000, rng);
  for (const QuantizedPoint& p : uniformPoints(30000, 1 << 24, rng))
    uneven.push_back({p[0] / 2 + (1 << 23) + 2000, p[1]});
  EXPECT_TRUE(sweepMatchesBoost(distinctShuffled(uneven, rng)));
  EXPECT_TRUE(sweepMatchesBoost(uniformPoints(50000, kMaxDelaunayCoordinate, rng)));
}

TEST(ComputeTriangleNeighbours, MatchesBruteForceOnDelaunayTriangulations)
{
  std::mt19937 rng(42);
  for (const Points& points :
       {uniformPoints(800, 100000, rng), snappedPoints(800, 20, 10, rng)}) {
    Triangles triangles = triangulate(points);
    std::shuffle(triangles.begin(), triangles.end(), rng);
    for (auto& t : triangles)
      std::rotate(t.begin(), t.begin() + rng() % 3, t.end());
    Triangles neighbours;
    computeTriangleNeighbours(triangles, points.size(), neighbours);
    EXPECT_EQ(neighbours, bruteForceNeighbours(triangles));
    const auto boundary =
        std::count(&neighbours[0][0], &neighbours[0][0] + 3 * neighbours.size(), -1);
    const std::vector<char> on_hull = onHullBoundary(points);
    EXPECT_EQ(boundary, std::count(on_hull.begin(), on_hull.end(), 1));
  }
}

TEST(ComputeTriangleNeighbours, ClosedSurfaceAndEdgeCases)
{
  // Tetrahedron surface (outward orientation): every edge is shared.
  const Triangles tetra{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  Triangles neighbours;
  computeTriangleNeighbours(tetra, 4, neighbours);
  EXPECT_EQ(neighbours, bruteForceNeighbours(tetra));
  EXPECT_EQ(neighbours[0], (Triangle{2, 1, 3}));
  // Two triangles sharing edge 1 - 2, with an unused vertex 4.
  const Triangles pair{{0, 1, 2}, {2, 1, 3}};
  computeTriangleNeighbours(pair, 5, neighbours);
  EXPECT_EQ(neighbours, (Triangles{{1, -1, -1}, {-1, -1, 0}}));
  computeTriangleNeighbours({}, 0, neighbours);
  EXPECT_TRUE(neighbours.empty());
}

TEST(Delaunay2DVtk, MatchesBoostAwayFromTheHull)
{
  if (!isDelaunayBackendAvailable(DelaunayBackend::Vtk))
    GTEST_SKIP() << "library built without VTK";
  std::mt19937 rng(42);
  // Large random coordinates: general position (checked below), so that the Delaunay
  // triangulation is unique and the floating-point backend has no ties to break.
  const Points points = uniformPoints(2000, 1 << 24, rng);
  const Triangles boost = triangulate(points);
  ASSERT_TRUE(isCanonicalDelaunay(points, boost));
  ASSERT_EQ(countCoCircularEdges(points, boost), 0u);
  const Triangles vtk = triangulate(points, DelaunayBackend::Vtk);
  EXPECT_TRUE(checkCanonicalOrder(vtk));
  for (const auto& t : vtk)
    EXPECT_GT(cross(points[t[0]], points[t[1]], points[t[2]]), 0);
  // vtkDelaunay2D only drops triangles, never invents any.
  EXPECT_TRUE(std::includes(boost.begin(), boost.end(), vtk.begin(), vtk.end()));
  // It drops those whose circumcircle reaches its bounding points: hull triangles, and
  // also some of the next layer (their circumcircles can be huge). Away from the hull
  // both backends agree.
  const std::vector<char> on_hull = onHullBoundary(points);
  QuantizedPoint lo{kMaxDelaunayCoordinate, kMaxDelaunayCoordinate}, hi{-lo[0], -lo[1]};
  for (const auto& p : points)
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  Triangles away;
  for (const auto& t : boost)
    if (!on_hull[t[0]] && !on_hull[t[1]] && !on_hull[t[2]] &&
        circumcircleInsideBox(points, t, lo, hi))
      away.push_back(t);
  EXPECT_GT(away.size(), boost.size() * 9 / 10);
  EXPECT_TRUE(std::includes(vtk.begin(), vtk.end(), away.begin(), away.end()));
  EXPECT_LT(boost.size() - vtk.size(), boost.size() / 50);
}

TEST(Delaunay2DVtk, FailsInsteadOfReturningABrokenMesh)
{
  if (!isDelaunayBackendAvailable(DelaunayBackend::Vtk))
    GTEST_SKIP() << "library built without VTK";
  // Points 1 apart beside points 2^26 away: vtkDelaunay2D logged "Edge is
  // non-manifold" and gave no triangle, which was returned as a success.
  const Points non_manifold{{-67108864, -67108864},
                            {-67108863, 0},
                            {-67108864, -1},
                            {-67108863, -67108864},
                            {-67108864, 1},
                            {0, -67108864},
                            {-67108864, 67108864}};
  for (const Points& points : {non_manifold}) {
    Triangles triangles{{0, 1, 2}};
    std::string error;
    EXPECT_FALSE(delaunay2d(points, DelaunayBackend::Vtk, triangles, &error));
    EXPECT_TRUE(triangles.empty());
    EXPECT_NE(error.find("vtk"), std::string::npos) << error;
    // The exact backends triangulate them.
    EXPECT_TRUE(isCanonicalDelaunay(points, triangulate(points)));
  }
  // Well spread points over the whole range are triangulated.
  std::mt19937 rng(5);
  const Points spread = uniformPoints(300, kMaxDelaunayCoordinate, rng);
  Triangles triangles;
  std::string error;
  EXPECT_TRUE(delaunay2d(spread, DelaunayBackend::Vtk, triangles, &error)) << error;
  EXPECT_FALSE(triangles.empty());
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  // The tests run the sweep on up to 7 threads. LLVM's libomp (14) loses a few
  // kilobytes of thread descriptors when a team grows by two or more threads after a
  // team of several (2 then 5 threads: LeakSanitizer reports it in a ten-line program
  // with no code of this project). Opening the largest team first keeps every later
  // team within it, so the sanitizer suite reports this project's leaks only.
  int largest_team = 0;
#pragma omp parallel num_threads(8)
  {
#pragma omp atomic
    ++largest_team;
  }
  return largest_team > 0 ? RUN_ALL_TESTS() : 1;
}
