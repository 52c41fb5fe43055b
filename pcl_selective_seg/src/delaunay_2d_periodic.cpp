/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/delaunay_2d.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "delaunay_2d_backends.h"

namespace pcl {
namespace selective_seg {

namespace {

using detail::inCircle;
using detail::setError;

// QuantizedPoint is a std::array: its operator< is the (x, y) lexicographic order the
// strip, the kept-copy rule and the canonical fan use.

/** The strip: the points and the sentinels, and copies shifted by -+ period of those
 * within a margin of the ends. Sorted by (x, y) when the points are (the sweep then
 * skips its sort). */
struct Strip {
  std::vector<QuantizedPoint> points;
  /** Per strip point: the point it is or repeats (ids of the points, then of the
   * sentinels after them). */
  std::vector<index_t> source;
  /** Per strip point: whether it is a copy. */
  std::vector<std::uint8_t> copy;

  void clear()
  {
    points.clear();
    source.clear();
    copy.clear();
  }
  void add(const QuantizedPoint& p, index_t from, bool is_copy)
  {
    points.push_back(p);
    source.push_back(from);
    copy.push_back(is_copy);
  }
};

/** \a points (ids from \a first_id) and their copies in \a out: those within \a
 * margin of the right end shifted left by the period, the points, those within the
 * margin of the left end shifted right (sorted when \a points are). */
void
appendWithCopies(const std::vector<QuantizedPoint>& points,
                 index_t first_id,
                 std::int32_t period,
                 std::int32_t margin,
                 Strip& out)
{
  const std::int32_t half = period / 2;
  // margin <= half: no point is repeated on both sides.
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i][0] >= half - margin)
      out.add({points[i][0] - period, points[i][1]},
              first_id + static_cast<index_t>(i),
              true);
  for (std::size_t i = 0; i < points.size(); ++i)
    out.add(points[i], first_id + static_cast<index_t>(i), false);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i][0] < -half + margin)
      out.add({points[i][0] + period, points[i][1]},
              first_id + static_cast<index_t>(i),
              true);
}

/** The strip of \a points and \a sentinels (sorted by (x, y)): both with their copies,
 * merged in (x, y) order. */
void
makeStrip(const std::vector<QuantizedPoint>& points,
          const std::vector<QuantizedPoint>& sentinels,
          std::int32_t period,
          std::int32_t margin,
          Strip& strip)
{
  Strip data, guard;
  appendWithCopies(points, 0, period, margin, data);
  appendWithCopies(
      sentinels, static_cast<index_t>(points.size()), period, margin, guard);
  strip.clear();
  strip.points.reserve(data.points.size() + guard.points.size());
  std::size_t i = 0, j = 0;
  while (i < data.points.size() || j < guard.points.size()) {
    const bool from_data = j == guard.points.size() ||
                           (i < data.points.size() && data.points[i] < guard.points[j]);
    const Strip& from = from_data ? data : guard;
    std::size_t& k = from_data ? i : j;
    strip.add(from.points[k], from.source[k], from.copy[k]);
    ++k;
  }
}

/** The strip's triangles whose smallest corner is not a copy: each triangle of the
 * cylinder once; of those, the triangles over the \a num_points points (no sentinel
 * corner). \a kept over point ids, \a unwrapped over strip ids. */
void
keepOneCopy(const Strip& strip,
            std::size_t num_points,
            const std::vector<Triangle>& strip_triangles,
            std::vector<Triangle>& kept,
            std::vector<Triangle>& unwrapped)
{
  kept.clear();
  unwrapped.clear();
  kept.reserve(strip_triangles.size());
  unwrapped.reserve(strip_triangles.size());
  for (const Triangle& t : strip_triangles) {
    index_t smallest = t[0];
    for (int i = 1; i < 3; ++i)
      if (strip.points[t[i]] < strip.points[smallest])
        smallest = t[i];
    if (strip.copy[smallest])
      continue;
    const Triangle mapped{strip.source[t[0]], strip.source[t[1]], strip.source[t[2]]};
    // A triangle wider than the period (two corners one point: a hull edge from a
    // point to its own copy, where one point rises above all others) is no triangle
    // of the cylinder's mesh.
    if (mapped[0] == mapped[1] || mapped[1] == mapped[2] || mapped[2] == mapped[0])
      continue;
    if (static_cast<std::size_t>(std::max({mapped[0], mapped[1], mapped[2]})) >=
        num_points)
      continue;
    kept.push_back(mapped);
    unwrapped.push_back(t);
  }
}

/** Whether every boundary loop of the kept triangles winds once around the cylinder:
 * the lower and upper hulls do; a seam left open, or a hole, makes a loop that does
 * not (its steps in x, each measured within its triangle, add up to 0 instead of the
 * period). At most one loop each way; no vertex starts two boundary edges. */
bool
boundaryWindsAround(const Strip& strip,
                    std::int32_t period,
                    const std::vector<Triangle>& kept,
                    const std::vector<Triangle>& unwrapped,
                    const std::vector<Triangle>& neighbours)
{
  struct Edge {
    index_t from, to;
    std::int64_t dx;
  };
  std::vector<Edge> edges;
  for (std::size_t t = 0; t < kept.size(); ++t)
    for (int i = 0; i < 3; ++i)
      if (neighbours[t][i] < 0) {
        const int a = (i + 1) % 3, b = (i + 2) % 3;
        edges.push_back({kept[t][a],
                         kept[t][b],
                         std::int64_t{strip.points[unwrapped[t][b]][0]} -
                             strip.points[unwrapped[t][a]][0]});
      }
  std::sort(edges.begin(), edges.end(), [](const Edge& e, const Edge& f) {
    return e.from < f.from;
  });
  for (std::size_t k = 1; k < edges.size(); ++k)
    if (edges[k].from == edges[k - 1].from)
      return false;
  const auto next = [&](index_t from) -> std::ptrdiff_t {
    const auto it = std::lower_bound(
        edges.begin(), edges.end(), from, [](const Edge& e, index_t v) {
          return e.from < v;
        });
    return it != edges.end() && it->from == from ? it - edges.begin() : -1;
  };
  std::vector<bool> visited(edges.size(), false);
  int forward = 0, backward = 0;
  for (std::size_t start = 0; start < edges.size(); ++start) {
    if (visited[start])
      continue;
    std::int64_t winding = 0;
    for (std::ptrdiff_t e = static_cast<std::ptrdiff_t>(start); !visited[e];) {
      visited[e] = true;
      winding += edges[e].dx;
      e = next(edges[e].to);
      if (e < 0)
        return false; // a boundary that does not close
    }
    if (winding == period)
      ++forward;
    else if (winding == -std::int64_t{period})
      ++backward;
    else
      return false;
  }
  return forward <= 1 && backward <= 1;
}

/** Whether strip triangle \a t is a triangle of the cylinder for certain: narrower
 * than half the period (so that each of its edges is one edge of the cylinder), and
 * the part of its circle inside the band [y_low, y_high], where every point and
 * sentinel lies, within the strip's x range. The strip holds every copy of a point in
 * that range and the circle is empty of the strip's points (a Delaunay triangle of the
 * strip), so it is empty of every point on the cylinder. Computed from exact integer
 * determinants, compared with a margin of a few steps and of 1e-9 of the radius (far
 * above the rounding): a borderline triangle only makes the margin grow. */
bool
withinStrip(const Strip& strip,
            const Triangle& t,
            std::int32_t period,
            std::int32_t margin,
            std::int32_t y_low,
            std::int32_t y_high)
{
  const QuantizedPoint &a = strip.points[t[0]], &b = strip.points[t[1]],
                       &c = strip.points[t[2]];
  const std::int32_t x_min = std::min({a[0], b[0], c[0]});
  const std::int32_t x_max = std::max({a[0], b[0], c[0]});
  if (std::int64_t{x_max} - x_min >= period / 2)
    return false;
  // Circumcentre relative to a: (u, v) = (num_u, num_v) / d.
  const std::int64_t bx = std::int64_t{b[0]} - a[0], by = std::int64_t{b[1]} - a[1];
  const std::int64_t cx = std::int64_t{c[0]} - a[0], cy = std::int64_t{c[1]} - a[1];
  const std::int64_t d = 2 * (bx * cy - by * cx);
  if (d <= 0)
    return false;
  const detail::Int128 b2 = detail::Int128{bx} * bx + detail::Int128{by} * by;
  const detail::Int128 c2 = detail::Int128{cx} * cx + detail::Int128{cy} * cy;
  using Real = double;
  const Real u = static_cast<Real>(b2 * cy - c2 * by) / d;
  const Real v = static_cast<Real>(c2 * bx - b2 * cx) / d;
  const Real radius = std::sqrt(u * u + v * v);
  const Real centre_x = a[0] + u, centre_y = a[1] + v;
  // Half the width of the circle's part in the band.
  Real half_width = radius;
  const Real off = centre_y < y_low    ? y_low - centre_y
                   : centre_y > y_high ? centre_y - y_high
                                       : Real(0);
  if (off > 0) {
    if (off >= radius)
      return true; // the circle misses the band: no point can be in it
    half_width = std::sqrt((radius - off) * (radius + off));
  }
  const Real slack = 4 + radius * Real(1e-9);
  const Real half = period / 2;
  return centre_x - half_width - slack > -half - margin &&
         centre_x + half_width + slack < half + margin;
}

/** Whether the kept triangles triangulate the cylinder (delaunay2dPeriodic()'s tests).
 * \a neighbours: their adjacency. */
bool
closesCylinder(const Strip& strip,
               std::int32_t period,
               std::int32_t margin,
               std::int32_t y_low,
               std::int32_t y_high,
               const std::vector<Triangle>& kept,
               const std::vector<Triangle>& unwrapped,
               const std::vector<Triangle>& neighbours)
{
  for (const Triangle& t : unwrapped)
    if (!withinStrip(strip, t, period, margin, y_low, y_high))
      return false;
  if (!boundaryWindsAround(strip, period, kept, unwrapped, neighbours))
    return false;
  // Away from the seam the kept triangles are the strip's, a planar triangulation.
  const std::int32_t half = period / 2;
  const auto near_seam = [&](const Triangle& u) {
    for (const index_t id : u) {
      const std::int32_t x = strip.points[id][0];
      if (x < -half + margin || x >= half - margin)
        return true;
    }
    return false;
  };
  std::vector<std::uint64_t> directed;
  std::vector<std::size_t> seam;
  for (std::size_t t = 0; t < kept.size(); ++t) {
    if (!near_seam(unwrapped[t]))
      continue;
    seam.push_back(t);
    for (int i = 0; i < 3; ++i)
      directed.push_back((std::uint64_t{static_cast<std::uint32_t>(kept[t][i])} << 32) |
                         static_cast<std::uint32_t>(kept[t][(i + 1) % 3]));
  }
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end())
    return false; // two triangles overlap
  for (const std::size_t t : seam) {
    const Triangle& corners = unwrapped[t];
    for (int i = 0; i < 3; ++i) {
      const index_t u = neighbours[t][i];
      if (u < 0)
        continue;
      const index_t a = kept[t][(i + 1) % 3], b = kept[t][(i + 2) % 3];
      int at_a = -1, opposite = -1;
      for (int k = 0; k < 3; ++k) {
        if (kept[u][k] == a)
          at_a = k;
        else if (kept[u][k] != b)
          opposite = k;
      }
      if (at_a < 0 || opposite < 0)
        return false;
      // The neighbour's corner where the two triangles meet: shifted by the period
      // when one of them holds a copy of the shared corner.
      const std::int32_t shift =
          strip.points[corners[(i + 1) % 3]][0] - strip.points[unwrapped[u][at_a]][0];
      QuantizedPoint far = strip.points[unwrapped[u][opposite]];
      far[0] += shift;
      if (inCircle(strip.points[corners[0]],
                   strip.points[corners[1]],
                   strip.points[corners[2]],
                   far) > 0)
        return false;
    }
  }
  return true;
}

} // namespace

bool
delaunay2dPeriodic(const std::vector<QuantizedPoint>& points,
                   std::int32_t period,
                   DelaunayBackend backend,
                   std::vector<Triangle>& triangles,
                   std::vector<Triangle>& neighbours,
                   bool& closed,
                   std::string* error,
                   unsigned int num_threads)
{
  triangles.clear();
  neighbours.clear();
  closed = false;
  if (period < 4 || period % 2 != 0 || period > kMaxDelaunayCoordinate) {
    setError(error,
             "delaunay2dPeriodic: the period " + std::to_string(period) +
                 " is not an even number in [4, " +
                 std::to_string(kMaxDelaunayCoordinate) + "]");
    return false;
  }
  if (backend == DelaunayBackend::Vtk) {
    setError(error,
             "delaunay2dPeriodic: needs an exact backend (sweep or boost), not vtk");
    return false;
  }
  const std::int32_t half = period / 2;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i][0] < -half || points[i][0] >= half) {
      setError(error,
               "delaunay2dPeriodic: point " + std::to_string(i) +
                   " has x = " + std::to_string(points[i][0]) + ", outside [" +
                   std::to_string(-half) + ", " + std::to_string(half) + ")");
      return false;
    }
  // Duplicates, named by their ids in the input (the strip's would mislead).
  // (Sorted already when they are the vertices of SphericalDelaunay.)
  std::vector<QuantizedPoint> sorted_copy;
  const bool in_order = std::is_sorted(points.begin(), points.end());
  if (!in_order) {
    sorted_copy = points;
    std::sort(sorted_copy.begin(), sorted_copy.end());
  }
  const std::vector<QuantizedPoint>& sorted_points = in_order ? points : sorted_copy;
  const auto duplicate = std::adjacent_find(sorted_points.begin(), sorted_points.end());
  if (duplicate != sorted_points.end()) {
    detail::reportDuplicate(points, *duplicate, error);
    return false;
  }
  // The widest gap between neighbouring x around the cylinder: a triangle across it is
  // at least that wide, and one as wide as half the period cannot be told from its
  // copy (withinStrip()), so the cylinder cannot close; the margin starts beyond it.
  std::int64_t widest_gap = period; // fewer than two points: nothing to close
  if (sorted_points.size() > 1) {
    widest_gap =
        std::int64_t{sorted_points.front()[0]} + period - sorted_points.back()[0];
    for (std::size_t k = 1; k < sorted_points.size(); ++k)
      widest_gap = std::max<std::int64_t>(
          widest_gap, std::int64_t{sorted_points[k][0]} - sorted_points[k - 1][0]);
  }
  // Two rows of sentinels, periodic, a sixty-fourth of the period below and above the
  // points: the strip's hull is theirs, so the points' own lower and upper hulls (rows
  // of nearly equal y, whose triangles have circles far wider than any margin) never
  // decide the triangulation near the seam. The sentinels' triangles are dropped.
  std::int32_t y_min = 0, y_max = 0;
  if (!points.empty()) {
    const auto [lo, hi] = std::minmax_element(
        points.begin(),
        points.end(),
        [](const QuantizedPoint& a, const QuantizedPoint& b) { return a[1] < b[1]; });
    y_min = (*lo)[1];
    y_max = (*hi)[1];
  }
  const std::int32_t gap = std::max(1, period / 64);
  if (std::int64_t{y_min} - gap < -kMaxDelaunayCoordinate ||
      std::int64_t{y_max} + gap > kMaxDelaunayCoordinate) {
    setError(error,
             "delaunay2dPeriodic: y must lie within +-(" +
                 std::to_string(kMaxDelaunayCoordinate) + " - period / 64)");
    return false;
  }
  std::vector<QuantizedPoint> sentinels; // in (x, y) order
  const std::int64_t per_row = std::min<std::int64_t>(64, period);
  for (std::int64_t j = 0; j < per_row; ++j) {
    const auto x = static_cast<std::int32_t>(-half + j * period / per_row);
    sentinels.push_back({x, y_min - gap});
    sentinels.push_back({x, y_max + gap});
  }
  Strip strip;
  std::vector<Triangle> strip_triangles, unwrapped, scratch;
  const std::int32_t first_margin = static_cast<std::int32_t>(std::min<std::int64_t>(
      half, std::max<std::int64_t>({1, period / 32, 2 * widest_gap})));
  for (std::int32_t margin = first_margin; widest_gap < half;
       margin = std::min(half, 2 * margin)) {
    makeStrip(points, sentinels, period, margin, strip);
    // With the adjacency, the sweep runs on num_threads threads (the adjacency itself
    // is not needed: the cylinder's is computed below).
    if (!delaunay2d(
            strip.points, backend, strip_triangles, scratch, error, num_threads))
      return false;
    keepOneCopy(strip, points.size(), strip_triangles, triangles, unwrapped);
    computeTriangleNeighbours(triangles, points.size(), neighbours, num_threads);
    if (!triangles.empty() && closesCylinder(strip,
                                             period,
                                             margin,
                                             y_min - gap,
                                             y_max + gap,
                                             triangles,
                                             unwrapped,
                                             neighbours)) {
      closed = true;
      detail::canonicalize(
          triangles, points.size(), &neighbours, static_cast<int>(num_threads));
      return true;
    }
    if (margin == half)
      break;
  }
  return delaunay2d(points, backend, triangles, neighbours, error, num_threads);
}

} // namespace selective_seg
} // namespace pcl
