/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/impl/large_arrays.hpp>

#include <boost/polygon/voronoi.hpp>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <limits>
#include <numeric>
#include <utility>

#include "delaunay_2d_backends.h"
#include "incidence_build.h"
#include "mesh_checks.h"

namespace pcl {
namespace selective_seg {

namespace {

using detail::inCircle;
using detail::orientation;
using detail::setError;

using VoronoiDiagram = boost::polygon::voronoi_diagram<double>;

std::string
describe(const QuantizedPoint& p)
{
  return "(" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ")";
}

} // namespace

namespace detail {

void
setError(std::string* error, const std::string& message)
{
  if (error)
    *error = message;
}

void
reportDuplicate(const std::vector<QuantizedPoint>& points,
                const QuantizedPoint& position,
                std::string* error)
{
  std::vector<std::size_t> ids;
  for (std::size_t i = 0; i < points.size() && ids.size() < 2; ++i)
    if (points[i] == position)
      ids.push_back(i);
  setError(error,
           "delaunay2d: duplicate points " + std::to_string(ids[0]) + " and " +
               std::to_string(ids[1]) + " at " + describe(position) +
               " (the input must hold distinct points)");
}

bool
allCollinear(const QuantizedPoint* first, std::size_t count)
{
  for (std::size_t i = 2; i < count; ++i)
    if (orientation(first[0], first[1], first[i]) != 0)
      return false;
  return true;
}

void
canonicalize(std::vector<Triangle>& triangles,
             std::size_t num_points,
             std::vector<Triangle>* neighbours,
             int num_threads)
{
  const auto num_slots = static_cast<std::ptrdiff_t>(triangles.size());
  const int threads = std::max(1, num_threads);
  const bool parallel =
      threads > 1 && static_cast<std::size_t>(num_slots) >= kMinParallelItems;
  // Each triangle rotated so that its smallest id comes first; rotating the corners
  // rotates the neighbours opposite them the same way. Removed slots stay as they are.
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t t = 0; t < num_slots; ++t) {
    Triangle& tri = triangles[t];
    int first = 0;
    if (tri[1] < tri[0] && tri[1] < tri[2])
      first = 1;
    else if (tri[2] < tri[0] && tri[2] < tri[1])
      first = 2;
    if (first == 0 || tri[0] == kNone)
      continue;
    const auto rotate = [first](Triangle& row) {
      row = {row[first], row[(first + 1) % 3], row[(first + 2) % 3]};
    };
    rotate(tri);
    if (neighbours)
      rotate((*neighbours)[t]);
  }
  // order: the triangles bucketed by their first id (a counting sort), each bucket in
  // increasing slot order; then each bucket (the few triangles sharing their smallest
  // vertex) sorted on the other two ids.
  std::vector<std::size_t> offsets;
  std::vector<index_t> order;
  detail::buildBuckets<index_t>(
      triangles.size(),
      num_points,
      [&](std::size_t t, auto f) {
        if (triangles[t][0] != kNone)
          f(triangles[t][0], static_cast<index_t>(t));
      },
      parallel ? threads : 1,
      offsets,
      order);
  const auto earlier = [&](index_t a, index_t b) {
    const Triangle &s = triangles[a], &t = triangles[b];
    return s[1] < t[1] || (s[1] == t[1] && s[2] < t[2]);
  };
  const auto num_buckets = static_cast<std::ptrdiff_t>(num_points);
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t v = 0; v < num_buckets; ++v) {
    const auto first = order.begin() + static_cast<std::ptrdiff_t>(offsets[v]);
    const auto last = order.begin() + static_cast<std::ptrdiff_t>(offsets[v + 1]);
    if (last - first > 16) {
      std::sort(first, last, earlier);
    } else {
      for (auto i = first + 1; i < last; ++i)
        for (auto j = i; j > first && earlier(*j, *(j - 1)); --j)
          std::iter_swap(j, j - 1);
    }
  }
  offsets = std::vector<std::size_t>();
  const auto num_triangles = static_cast<std::ptrdiff_t>(order.size());
  std::vector<Triangle> sorted;
  detail::resizeLarge(sorted, order.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t k = 0; k < num_triangles; ++k)
    sorted[k] = triangles[order[k]];
  triangles.swap(sorted);
  if (!neighbours)
    return;
  // The neighbours' new numbers, then the rows in the new order.
  std::vector<index_t> position_of;
  detail::resizeLarge(position_of, static_cast<std::size_t>(num_slots));
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t k = 0; k < num_triangles; ++k)
    position_of[order[k]] = static_cast<index_t>(k);
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (parallel)
#endif
  for (std::ptrdiff_t k = 0; k < num_triangles; ++k) {
    const Triangle& old = (*neighbours)[order[k]];
    for (int i = 0; i < 3; ++i)
      sorted[k][i] = old[i] == kNone ? kNone : position_of[old[i]];
  }
  sorted.resize(order.size());
  neighbours->swap(sorted);
}

void
refanGroup(const std::vector<QuantizedPoint>& points,
           const std::vector<index_t>& group,
           Triangle* triangles,
           std::vector<index_t>& corners)
{
  corners.clear();
  for (const index_t t : group)
    corners.insert(corners.end(), triangles[t].begin(), triangles[t].end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const auto first =
      std::min_element(corners.begin(), corners.end(), [&](index_t a, index_t b) {
        return points[a] < points[b];
      });
  std::iter_swap(corners.begin(), first);
  const QuantizedPoint& apex = points[corners[0]];
  std::sort(corners.begin() + 1, corners.end(), [&](index_t a, index_t b) {
    return orientation(apex, points[a], points[b]) > 0;
  });
  for (std::size_t s = 0; s < group.size(); ++s)
    triangles[group[s]] = {corners[0], corners[s + 1], corners[s + 2]};
}

} // namespace detail

namespace {

// ----------------------------------------------------------------- preconditions

bool
checkRange(const std::vector<QuantizedPoint>& points, std::string* error)
{
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<index_t>::max())) {
    setError(error, "delaunay2d: too many points for pcl::index_t");
    return false;
  }
  const auto outside = [](std::int32_t c) {
    return c < -kMaxDelaunayCoordinate || c > kMaxDelaunayCoordinate;
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (outside(points[i][0]) || outside(points[i][1])) {
      setError(error,
               "delaunay2d: point " + std::to_string(i) + " " + describe(points[i]) +
                   " is outside the accepted range +-" +
                   std::to_string(kMaxDelaunayCoordinate));
      return false;
    }
  }
  return true;
}

/** Sortable 64-bit key of a point, ordered like the points (x, then y). */
std::uint64_t
pointKey(const QuantizedPoint& p)
{
  const auto biased = [](std::int32_t c) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(c) + (1LL << 31));
  };
  return (biased(p[0]) << 32) | biased(p[1]);
}

bool
checkDistinct(const std::vector<QuantizedPoint>& points, std::string* error)
{
  std::vector<std::uint64_t> keys(points.size());
  std::transform(points.begin(), points.end(), keys.begin(), pointKey);
  std::sort(keys.begin(), keys.end());
  const auto duplicate = std::adjacent_find(keys.begin(), keys.end());
  if (duplicate == keys.end())
    return true;
  const auto at = std::find_if(points.begin(), points.end(), [&](const auto& p) {
    return pointKey(p) == *duplicate;
  });
  detail::reportDuplicate(points, *at, error);
  return false;
}

// ------------------------------------------------------- polygon triangulation

/** Position in \a polygon of its lexicographically smallest point (x, then y). */
std::size_t
smallestCorner(const std::vector<QuantizedPoint>& points,
               const std::vector<index_t>& polygon)
{
  std::size_t best = 0;
  for (std::size_t j = 1; j < polygon.size(); ++j)
    if (points[polygon[j]] < points[polygon[best]])
      best = j;
  return best;
}

/** Appends the fan from the smallest corner of a counter-clockwise polygon if the
 * polygon is strictly convex and exactly co-circular; returns false (appending nothing)
 * otherwise. Three points in counter-clockwise order always qualify. */
bool
appendCoCircularFan(const std::vector<QuantizedPoint>& points,
                    const std::vector<index_t>& polygon,
                    std::vector<Triangle>& triangles)
{
  const std::size_t k = polygon.size();
  const std::size_t first = smallestCorner(points, polygon);
  const auto id = [&](std::size_t j) { return polygon[(first + j) % k]; };
  const auto at = [&](std::size_t j) -> const QuantizedPoint& { return points[id(j)]; };
  for (std::size_t j = 1; j + 1 < k; ++j)
    if (orientation(at(0), at(j), at(j + 1)) <= 0)
      return false;
  for (std::size_t j = 3; j < k; ++j)
    if (inCircle(at(0), at(1), at(2), at(j)) != 0)
      return false;
  for (std::size_t j = 1; j + 1 < k; ++j)
    triangles.push_back({id(0), id(j), id(j + 1)});
  return true;
}

/** Whether corner i of the counter-clockwise ring is an ear: convex, and no other
 * corner lies in the closed triangle it forms with its two neighbours. */
bool
isEar(const std::vector<QuantizedPoint>& points,
      const std::vector<index_t>& ring,
      std::size_t i)
{
  const std::size_t k = ring.size();
  const index_t a = ring[(i + k - 1) % k], b = ring[i], c = ring[(i + 1) % k];
  if (orientation(points[a], points[b], points[c]) <= 0)
    return false;
  for (const index_t v : ring) {
    if (v == a || v == b || v == c)
      continue;
    const QuantizedPoint& p = points[v];
    if (orientation(points[a], points[b], p) >= 0 &&
        orientation(points[b], points[c], p) >= 0 &&
        orientation(points[c], points[a], p) >= 0)
      return false;
  }
  return true;
}

/** Triangulates a simple counter-clockwise polygon by ear clipping (exact predicates);
 * false if the polygon is not simple. */
bool
appendEarClipping(const std::vector<QuantizedPoint>& points,
                  std::vector<index_t> ring,
                  std::vector<Triangle>& triangles)
{
  std::size_t i = 0;
  while (ring.size() > 3) {
    std::size_t tried = 0;
    while (tried < ring.size() && !isEar(points, ring, i)) {
      i = (i + 1) % ring.size();
      ++tried;
    }
    if (tried == ring.size())
      return false;
    const std::size_t k = ring.size();
    triangles.push_back({ring[(i + k - 1) % k], ring[i], ring[(i + 1) % k]});
    ring.erase(ring.begin() + i);
    i = (i + ring.size() - 1) % ring.size();
  }
  if (orientation(points[ring[0]], points[ring[1]], points[ring[2]]) <= 0)
    return false;
  triangles.push_back({ring[0], ring[1], ring[2]});
  return true;
}

// ------------------------------------------------------------ Delaunay repair

/** Position (0..2) of \a value in \a t, or 3 if absent. */
int
cornerOf(const Triangle& t, index_t value)
{
  int i = 0;
  while (i < 3 && t[i] != value)
    ++i;
  return i;
}

void
replaceNeighbour(std::vector<Triangle>& neighbours, index_t t, index_t from, index_t to)
{
  if (t < 0)
    return;
  const int i = cornerOf(neighbours[t], from);
  if (i < 3)
    neighbours[t][i] = to;
}

/** Flips the edge shared by triangle t (opposite its corner i) and triangle u
 * (opposite its corner j), keeping both triangles counter-clockwise and the adjacency
 * up to date. With t = (a, b, c) and u = (d, c, b), the new triangles are t = (a, b, d)
 * and u = (a, d, c). */
void
flipEdge(std::vector<Triangle>& triangles,
         std::vector<Triangle>& neighbours,
         index_t t,
         int i,
         index_t u,
         int j)
{
  const index_t a = triangles[t][i];
  const index_t b = triangles[t][(i + 1) % 3];
  const index_t c = triangles[t][(i + 2) % 3];
  const index_t d = triangles[u][j];
  const index_t across_ca = neighbours[t][(i + 1) % 3];
  const index_t across_ab = neighbours[t][(i + 2) % 3];
  const index_t across_bd = neighbours[u][(j + 1) % 3];
  const index_t across_dc = neighbours[u][(j + 2) % 3];
  triangles[t] = {a, b, d};
  neighbours[t] = {across_bd, u, across_ab};
  triangles[u] = {a, d, c};
  neighbours[u] = {across_dc, across_ca, t};
  replaceNeighbour(neighbours, across_bd, u, t);
  replaceNeighbour(neighbours, across_ca, t, u);
}

/** In-circle test of the vertex of neighbour u opposite the edge it shares with t
 * against the circumcircle of t; sets j to that vertex's corner in u. */
detail::Int128
inCircleAcross(const std::vector<QuantizedPoint>& points,
               const std::vector<Triangle>& triangles,
               const std::vector<Triangle>& neighbours,
               index_t t,
               index_t u,
               int& j)
{
  j = cornerOf(neighbours[u], t);
  const Triangle& tri = triangles[t];
  return inCircle(
      points[tri[0]], points[tri[1]], points[tri[2]], points[triangles[u][j]]);
}

/** Lawson's edge flips until every interior edge is locally Delaunay (exact
 * predicates, strict criterion, so the loop terminates). */
void
flipToDelaunay(const std::vector<QuantizedPoint>& points,
               std::vector<Triangle>& triangles,
               std::vector<Triangle>& neighbours)
{
  std::vector<index_t> stack(triangles.size());
  std::iota(stack.begin(), stack.end(), 0);
  std::vector<char> queued(triangles.size(), 1);
  const auto push = [&](index_t t) {
    if (!queued[t]) {
      queued[t] = 1;
      stack.push_back(t);
    }
  };
  while (!stack.empty()) {
    const index_t t = stack.back();
    stack.pop_back();
    queued[t] = 0;
    for (int i = 0; i < 3; ++i) {
      const index_t u = neighbours[t][i];
      int j = 0;
      if (u >= 0 && inCircleAcross(points, triangles, neighbours, t, u, j) > 0) {
        flipEdge(triangles, neighbours, t, i, u, j);
        push(t);
        push(u);
        break;
      }
    }
  }
}

index_t
findRoot(std::vector<index_t>& parent, index_t t)
{
  while (parent[t] != t) {
    parent[t] = parent[parent[t]];
    t = parent[t];
  }
  return t;
}

/** Splits every group of co-circular triangles (joined across interior edges whose
 * in-circle determinant is zero) by the canonical fan. Expects a Delaunay
 * triangulation. */
void
canonicalizeCoCircular(const std::vector<QuantizedPoint>& points,
                       std::vector<Triangle>& triangles)
{
  std::vector<Triangle> neighbours;
  computeTriangleNeighbours(triangles, points.size(), neighbours);
  const auto num_triangles = static_cast<index_t>(triangles.size());
  std::vector<index_t> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (index_t t = 0; t < num_triangles; ++t) {
    for (const index_t u : neighbours[t]) {
      int j = 0;
      if (u > t && inCircleAcross(points, triangles, neighbours, t, u, j) == 0)
        parent[findRoot(parent, u)] = findRoot(parent, t);
    }
  }
  std::vector<std::pair<index_t, index_t>> members; // (root, triangle)
  for (index_t t = 0; t < num_triangles; ++t)
    members.emplace_back(findRoot(parent, t), t);
  std::sort(members.begin(), members.end());
  std::vector<index_t> group, corners;
  for (std::size_t s = 0; s < members.size(); ++s) {
    group.push_back(members[s].second);
    if (s + 1 == members.size() || members[s + 1].first != members[s].first) {
      if (group.size() > 1)
        detail::refanGroup(points, group, triangles.data(), corners);
      group.clear();
    }
  }
}

// ------------------------------------------------------------ Boost backend

/** The Delaunay polygon dual to \a vertex as Voronoi cell indices (positions in
 * diagram.cells()), counter-clockwise: Boost.Polygon orders the edges around a vertex
 * counter-clockwise and rot_next() walks them in that order. Incident edge e_k, dual to
 * the polygon edge (p_{k-1}, p_k), has cell p_k on its left. \a earlier[k] is the index
 * of the other end of e_k if that vertex is stored before \a vertex, otherwise -1, so
 * that each Voronoi edge is seen once. */
void
collectPolygon(const VoronoiDiagram& diagram,
               const VoronoiDiagram::vertex_type& vertex,
               std::vector<index_t>& polygon,
               std::vector<index_t>& earlier)
{
  polygon.clear();
  earlier.clear();
  const VoronoiDiagram::edge_type* edge = vertex.incident_edge();
  do {
    polygon.push_back(static_cast<index_t>(edge->cell() - diagram.cells().data()));
    const VoronoiDiagram::vertex_type* end = edge->vertex1();
    earlier.push_back(end && end < &vertex
                          ? static_cast<index_t>(end - diagram.vertices().data())
                          : -1);
    edge = edge->rot_next();
  } while (edge != vertex.incident_edge());
}

/** Whether the co-circular \a polygon lies on a different empty circle than each
 * polygon across its edges to \a earlier vertices (see collectPolygon()), whose circles
 * are given by three counter-clockwise corners in \a circles: the corner after the
 * shared edge, standing for the whole polygon, must be strictly outside. */
bool
isStrictlyDelaunayAcross(const std::vector<QuantizedPoint>& points,
                         const std::vector<index_t>& polygon,
                         const std::vector<index_t>& earlier,
                         const std::vector<Triangle>& circles)
{
  const std::size_t k = polygon.size();
  for (std::size_t j = 0; j < k; ++j) {
    if (earlier[j] < 0)
      continue;
    const Triangle& circle = circles[earlier[j]];
    if (inCircle(points[circle[0]],
                 points[circle[1]],
                 points[circle[2]],
                 points[polygon[(j + 1) % k]]) >= 0)
      return false;
  }
  return true;
}

/** Triangulates the Delaunay polygon of every Voronoi vertex, in cell indices, with
 * \a cell_points the points of the cells. Co-circular polygons get the canonical fan.
 * \a exact is cleared if a polygon is not exactly co-circular (Boost.Polygon merges
 * vertices closer than 128 ULPs; the polygon is then ear clipped) or if two adjacent
 * polygons share their circle (co-circular points left split over two vertices): the
 * caller then repairs the result. */
bool
triangulateVoronoiVertices(const std::vector<QuantizedPoint>& cell_points,
                           const VoronoiDiagram& diagram,
                           std::vector<Triangle>& triangles,
                           bool& exact,
                           std::string* error)
{
  triangles.reserve(2 * cell_points.size());
  std::vector<Triangle> circles(diagram.num_vertices());
  std::vector<index_t> polygon, earlier;
  for (std::size_t v = 0; v < diagram.num_vertices(); ++v) {
    collectPolygon(diagram, diagram.vertices()[v], polygon, earlier);
    circles[v] = {polygon[0], polygon[1], polygon[2]};
    if (appendCoCircularFan(cell_points, polygon, triangles)) {
      exact = exact && isStrictlyDelaunayAcross(cell_points, polygon, earlier, circles);
      continue;
    }
    exact = false;
    if (!appendEarClipping(cell_points, polygon, triangles)) {
      setError(error,
               "delaunay2d (boost): the Delaunay polygon of a Voronoi vertex with " +
                   std::to_string(polygon.size()) + " sites is not simple");
      return false;
    }
  }
  return true;
}

/** Triangles dual to Boost.Polygon's Voronoi diagram; \a exact is cleared if they may
 * not be the canonical Delaunay triangulation and need the repair. The geometry is
 * looked up by cell index: the cells are stored in sweep order (by x, then y), like the
 * vertices, so that the lookups stay local in memory while the input ids may be in any
 * order. */
bool
triangulateVoronoiDual(const std::vector<QuantizedPoint>& points,
                       std::vector<Triangle>& triangles,
                       bool& exact,
                       std::string* error)
{
  std::vector<boost::polygon::point_data<std::int32_t>> sites;
  sites.reserve(points.size());
  for (const auto& p : points)
    sites.emplace_back(p[0], p[1]);
  VoronoiDiagram diagram;
  boost::polygon::construct_voronoi(sites.begin(), sites.end(), &diagram);
  std::vector<index_t> cell_ids(diagram.num_cells());
  std::vector<QuantizedPoint> cell_points(diagram.num_cells());
  for (std::size_t c = 0; c < cell_ids.size(); ++c) {
    cell_ids[c] = static_cast<index_t>(diagram.cells()[c].source_index());
    cell_points[c] = points[cell_ids[c]];
  }
  if (!triangulateVoronoiVertices(cell_points, diagram, triangles, exact, error))
    return false;
  for (auto& t : triangles)
    for (auto& v : t)
      v = cell_ids[v];
  return true;
}

} // namespace

namespace detail {

bool
delaunayBoostVoronoi(const std::vector<QuantizedPoint>& points,
                     std::vector<Triangle>& triangles,
                     std::string* error)
{
  triangles.clear();
  bool exact = true;
  if (!triangulateVoronoiDual(points, triangles, exact, error)) {
    triangles.clear();
    return false;
  }
  if (exact)
    return true;
  // Boost.Polygon merges Voronoi vertices by a 128-ULP tolerance while each computed
  // vertex carries an error of up to about 64 ULPs, so near-co-circular points may be
  // merged and, in principle, co-circular ones left split over two vertices. The
  // triangulation is still valid; flips and the canonical fans make it exact again.
  std::vector<Triangle> neighbours;
  computeTriangleNeighbours(triangles, points.size(), neighbours);
  flipToDelaunay(points, triangles, neighbours);
  canonicalizeCoCircular(points, triangles);
  return true;
}

} // namespace detail

namespace {

bool
runBackend(const std::vector<QuantizedPoint>& points,
           DelaunayBackend backend,
           std::vector<Triangle>& triangles,
           std::string* error)
{
  switch (backend) {
  case DelaunayBackend::BoostVoronoi:
    return detail::delaunayBoostVoronoi(points, triangles, error);
  case DelaunayBackend::Sweep:
    return detail::delaunaySweep(points, triangles, nullptr, error);
  case DelaunayBackend::Vtk:
#ifdef PCL_SELSEG_HAVE_VTK
    return detail::delaunayVtk(points, triangles, error);
#else
    break;
#endif
  }
  setError(error,
           std::string("delaunay2d: backend '") + toString(backend) +
               "' is not available in this build");
  return false;
}

} // namespace

const char*
toString(DelaunayBackend backend)
{
  switch (backend) {
  case DelaunayBackend::BoostVoronoi:
    return "boost";
  case DelaunayBackend::Vtk:
    return "vtk";
  case DelaunayBackend::Sweep:
    return "sweep";
  }
  return "unknown";
}

bool
isDelaunayBackendAvailable(DelaunayBackend backend)
{
  switch (backend) {
  case DelaunayBackend::BoostVoronoi:
  case DelaunayBackend::Sweep:
    return true;
  case DelaunayBackend::Vtk:
#ifdef PCL_SELSEG_HAVE_VTK
    return true;
#else
    return false;
#endif
  }
  return false;
}

namespace {

bool
triangulate2d(const std::vector<QuantizedPoint>& points,
              DelaunayBackend backend,
              std::vector<Triangle>& triangles,
              std::vector<Triangle>* neighbours,
              std::string* error,
              unsigned int num_threads)
{
  triangles.clear();
  if (neighbours)
    neighbours->clear();
  if (!isDelaunayBackendAvailable(backend)) {
    setError(error,
             std::string("delaunay2d: backend '") + toString(backend) +
                 "' is not available in this build" +
                 (backend == DelaunayBackend::Vtk ? " (compiled without VTK)" : ""));
    return false;
  }
  if (!checkRange(points, error))
    return false;
  // The sweep sorts the points anyway, which finds duplicates at no extra cost; it
  // also returns its triangles in canonical order, and its adjacency.
  if (backend == DelaunayBackend::Sweep)
    return detail::delaunaySweep(
        points, triangles, neighbours, error, static_cast<int>(num_threads));
  if (!checkDistinct(points, error))
    return false;
  if (points.size() < 3 || detail::allCollinear(points))
    return true;
  if (!runBackend(points, backend, triangles, error)) {
    triangles.clear();
    return false;
  }
  detail::canonicalize(triangles, points.size());
  if (neighbours)
    computeTriangleNeighbours(triangles, points.size(), *neighbours, num_threads);
  return true;
}

} // namespace

bool
delaunay2d(const std::vector<QuantizedPoint>& points,
           DelaunayBackend backend,
           std::vector<Triangle>& triangles,
           std::string* error)
{
  return triangulate2d(points, backend, triangles, nullptr, error, 1);
}

bool
delaunay2d(const std::vector<QuantizedPoint>& points,
           DelaunayBackend backend,
           std::vector<Triangle>& triangles,
           std::vector<Triangle>& neighbours,
           std::string* error,
           unsigned int num_threads)
{
  return triangulate2d(points, backend, triangles, &neighbours, error, num_threads);
}

void
computeTriangleNeighbours(const std::vector<Triangle>& triangles,
                          std::size_t num_vertices,
                          std::vector<Triangle>& neighbours,
                          unsigned int num_threads)
{
  if (!detail::idsBelow(triangles,
                        num_vertices,
                        false,
                        "computeTriangleNeighbours",
                        "the triangles",
                        static_cast<int>(num_threads))) {
    neighbours.clear();
    return;
  }
  // Bucket the half-edges by their origin vertex (compressed rows), each stored as
  // (end vertex, triangle). The half-edge opposite corner i of triangle t runs from
  // t[(i + 1) % 3] to t[(i + 2) % 3]; its twin is the half-edge leaving t[(i + 2) % 3]
  // towards t[(i + 1) % 3].
  std::vector<std::size_t> offsets;
  std::vector<std::pair<index_t, index_t>> half_edges;
  detail::buildBuckets<std::pair<index_t, index_t>>(
      triangles.size(),
      num_vertices,
      [&](std::size_t t, auto f) {
        for (std::size_t i = 0; i < 3; ++i)
          f(triangles[t][i],
            std::pair<index_t, index_t>(triangles[t][(i + 1) % 3],
                                        static_cast<index_t>(t)));
      },
      static_cast<int>(std::max(1u, num_threads)),
      offsets,
      half_edges);
  neighbours.resize(triangles.size());
  // Each triangle's entries are its own: the same result for any thread count.
#ifdef _OPENMP
#pragma omp parallel for num_threads(std::max(1u, num_threads)) schedule(static)
#endif
  for (std::ptrdiff_t t = 0; t < static_cast<std::ptrdiff_t>(triangles.size()); ++t) {
    neighbours[t] = Triangle{-1, -1, -1};
    for (std::size_t i = 0; i < 3; ++i) {
      const index_t origin = triangles[t][(i + 1) % 3];
      const index_t end = triangles[t][(i + 2) % 3];
      for (std::size_t s = offsets[end]; s < offsets[end + 1]; ++s) {
        if (half_edges[s].first == origin) {
          neighbours[t][i] = half_edges[s].second;
          break;
        }
      }
    }
  }
}

} // namespace selective_seg
} // namespace pcl
