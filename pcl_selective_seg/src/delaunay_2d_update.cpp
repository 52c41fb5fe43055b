/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Insertion of points into an exact Delaunay triangulation by local re-triangulation.
//
// Let P be the old points, Q the new ones, U = P + Q. An old triangle survives in DT(U)
// unless a new point lies in its closed circumdisk (then it is "replaced": a new point
// inside breaks the empty-circle property, one on the circle joins a co-circular
// group whose canonical fan may change). The replaced triangles C, plus the area the
// convex hull gains, form the region R; the kept triangles K tile the rest. Every
// triangle of DT(U) inside R has its vertices among Q, the vertices of C and the hull
// vertices that the new points see, and is empty in U, hence Delaunay (with the same
// canonical split) in any subset L of U that holds those points. So R is re-tiled by
// the triangles of DT(L) found by a flood from the new points' triangles that stops
// at the boundary of K. The result is checked (every boundary edge of K matched once,
// Euler's count over the whole mesh) before it replaces the input.

#include <pcl_selective_seg/delaunay_2d_update.h>
#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/radix_sort.hpp>

#include <algorithm>
#include <cstdint>
#include <unordered_map>

#include "delaunay_2d_backends.h"

namespace pcl {
namespace selective_seg {

namespace {

using detail::inCircle;
using detail::orientation;
using detail::undirectedEdgeKey;

/** A hull edge: triangle and the local index of the vertex opposite the edge. The edge
 * runs from triangle[(i + 1) % 3] to triangle[(i + 2) % 3], the interior on its left.
 */
struct HullEdge {
  pcl::index_t triangle = -1;
  int opposite = 0;
};

/** Bits 0..26 of \a x spread to the even bits. */
std::uint64_t
spreadBits(std::uint64_t x)
{
  x &= (std::uint64_t{1} << 27) - 1;
  x = (x | (x << 16)) & 0x0000FFFF0000FFFFull;
  x = (x | (x << 8)) & 0x00FF00FF00FF00FFull;
  x = (x | (x << 4)) & 0x0F0F0F0F0F0F0F0Full;
  x = (x | (x << 2)) & 0x3333333333333333ull;
  x = (x | (x << 1)) & 0x5555555555555555ull;
  return x;
}

/** The order in which to locate the points \a q: along a Z-order curve over their
 * coordinates, so that each walk starts from a nearby point's triangle. (In the
 * lexicographic order, consecutive points of a jittered scan lie far apart in phi, and
 * every walk crosses the window.) The conflicts found do not depend on the order. */
std::vector<std::pair<std::uint64_t, pcl::index_t>>
locationOrder(const std::vector<QuantizedPoint>& q)
{
  std::vector<std::pair<std::uint64_t, pcl::index_t>> order(q.size());
  if (q.empty())
    return order;
  std::int64_t lo0 = q[0][0], lo1 = q[0][1];
  for (const auto& p : q) {
    lo0 = std::min<std::int64_t>(lo0, p[0]);
    lo1 = std::min<std::int64_t>(lo1, p[1]);
  }
  std::uint64_t highest = 0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    // |coordinate| <= 2^26, so each offset fits in 27 bits.
    const std::uint64_t code =
        spreadBits(static_cast<std::uint64_t>(q[k][0] - lo0)) |
        (spreadBits(static_cast<std::uint64_t>(q[k][1] - lo1)) << 1);
    order[k] = {code, static_cast<pcl::index_t>(k)};
    highest = std::max(highest, code);
  }
  detail::radixSortByKey(order, detail::bitWidth(highest));
  return order;
}

/** Merges two sorted sequences of distinct items into new ids, in chunks of the first
 * one on \a threads threads: item i of A (0 <= i < n) gets id i - skipped_before(i) + (the
 * number of B items before it), unless skip(i); item j of B (0 <= j < m) gets id j +
 * (the number of kept A items before it). \a b_before(i) is the number of B items
 * before A item i (skipped or not); the ids are those of the serial merge. */
template <typename Skip, typename SkippedBefore, typename BBefore, typename ALess,
          typename EmitA, typename EmitB>
void
mergeInChunks(std::size_t n,
              std::size_t m,
              const Skip& skip,
              const SkippedBefore& skipped_before,
              const BBefore& b_before,
              const ALess& a_less, // (i, j): A item i before B item j
              const EmitA& emit_a,
              const EmitB& emit_b,
              unsigned int threads)
{
  const std::size_t chunks =
      threads > 1 && n >= detail::kMinParallelItems ? 4 * std::size_t{threads} : 1;
  const std::size_t chunk_size = (n + chunks - 1) / chunks;
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(threads)) schedule(dynamic, 1) \
    if (chunks > 1)
#endif
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(chunks); ++c) {
    const std::size_t i0 = std::min(n, static_cast<std::size_t>(c) * chunk_size);
    const std::size_t i1 = std::min(n, i0 + chunk_size);
    std::size_t j = c == 0 ? 0 : b_before(i0);
    const std::size_t j1 = i1 == n ? m : b_before(i1);
    auto id = static_cast<pcl::index_t>(i0 - skipped_before(i0) + j);
    for (std::size_t i = i0; i < i1; ++i) {
      if (skip(i))
        continue;
      while (j < j1 && !a_less(i, j))
        emit_b(j++, id++);
      emit_a(i, id++);
    }
    while (j < j1)
      emit_b(j++, id++);
  }
}

int
localIndex(const Triangle& t, pcl::index_t v)
{
  return t[0] == v ? 0 : (t[1] == v ? 1 : 2);
}

class Inserter {
public:
  Inserter(const std::vector<QuantizedPoint>& points,
           const std::vector<Triangle>& triangles,
           const std::vector<Triangle>& neighbours,
           unsigned int threads)
  : p_(points), t_(triangles), n_(neighbours), threads_(std::max(1u, threads))
  {}

  bool run(const std::vector<QuantizedPoint>& q,
           std::vector<QuantizedPoint>& out_points,
           std::vector<Triangle>& out_triangles,
           std::vector<Triangle>& out_neighbours,
           DelaunayInsertion& info,
           std::string* error);

private:
  /** Walk from \a start to the triangle holding \a q; false: q is outside the hull
   * and \a exit is the hull edge the walk left through. */
  bool locate(const QuantizedPoint& q, pcl::index_t& start, HullEdge& exit) const;

  /** The next hull edge counter-clockwise (forward) or clockwise. */
  HullEdge nextHullEdge(HullEdge h, bool forward) const;

  bool visible(const HullEdge& h, const QuantizedPoint& q) const
  {
    const Triangle& tri = t_[h.triangle];
    return orientation(p_[tri[(h.opposite + 1) % 3]], p_[tri[(h.opposite + 2) % 3]], q) <
           0;
  }

  bool inConflict(pcl::index_t t, const QuantizedPoint& q) const
  {
    const Triangle& tri = t_[t];
    return inCircle(p_[tri[0]], p_[tri[1]], p_[tri[2]], q) >= 0;
  }

  /** Add every triangle whose closed circumdisk holds q, connected to \a seed. */
  void collectConflicts(pcl::index_t seed, const QuantizedPoint& q, std::uint32_t stamp);

  const std::vector<QuantizedPoint>& p_;
  const std::vector<Triangle>& t_;
  const std::vector<Triangle>& n_;
  const unsigned int threads_;
  std::vector<std::uint8_t> replaced_;  // per old triangle
  std::vector<std::uint32_t> visited_;  // per old triangle: stamp of the last new point
  std::vector<pcl::index_t> conflicts_; // replaced triangles
  std::vector<HullEdge> seen_hull_;     // old hull edges visible from a new point
  std::vector<pcl::index_t> stack_;
};

bool
Inserter::locate(const QuantizedPoint& q, pcl::index_t& start, HullEdge& exit) const
{
  pcl::index_t t = start;
  const std::size_t limit = 4 * t_.size() + 16;
  for (std::size_t step = 0; step < limit; ++step) {
    const Triangle& tri = t_[t];
    int out = -1;
    for (int k = 0; k < 3 && out < 0; ++k) {
      const int i = static_cast<int>((k + step) % 3); // vary the first edge tried
      if (orientation(p_[tri[(i + 1) % 3]], p_[tri[(i + 2) % 3]], q) < 0)
        out = i;
    }
    if (out < 0) {
      start = t;
      return true;
    }
    if (n_[t][out] < 0) {
      start = t;
      exit = {t, out};
      return false;
    }
    t = n_[t][out];
  }
  exit = {-1, 0};
  return false;
}

HullEdge
Inserter::nextHullEdge(HullEdge h, bool forward) const
{
  // Rotate through the interior around the edge's end vertex (forward) or start vertex
  // (backward) to the hull edge that leaves it (arrives at it).
  const int corner = (h.opposite + (forward ? 2 : 1)) % 3;
  const int step = forward ? 2 : 1; // from the pivot to the vertex opposite the edge
  const pcl::index_t pivot = t_[h.triangle][corner];
  pcl::index_t cur = h.triangle;
  int j = corner;
  for (std::size_t guard = 0; guard <= t_.size(); ++guard) {
    const int opp = (j + step) % 3; // the other edge at the pivot in cur
    const pcl::index_t next = n_[cur][opp];
    if (next < 0)
      return {cur, opp};
    cur = next;
    j = localIndex(t_[cur], pivot);
  }
  return {-1, 0};
}

void
Inserter::collectConflicts(pcl::index_t seed, const QuantizedPoint& q, std::uint32_t stamp)
{
  if (visited_[seed] == stamp)
    return;
  visited_[seed] = stamp;
  stack_.assign(1, seed);
  while (!stack_.empty()) {
    const pcl::index_t t = stack_.back();
    stack_.pop_back();
    if (!replaced_[t]) {
      replaced_[t] = 1;
      conflicts_.push_back(t);
    }
    for (const pcl::index_t u : n_[t])
      if (u >= 0 && visited_[u] != stamp) {
        visited_[u] = stamp;
        if (inConflict(u, q))
          stack_.push_back(u);
      }
  }
}

bool
Inserter::run(const std::vector<QuantizedPoint>& q,
              std::vector<QuantizedPoint>& out_points,
              std::vector<Triangle>& out_triangles,
              std::vector<Triangle>& out_neighbours,
              DelaunayInsertion& info,
              std::string* error)
{
  const std::size_t num_old = t_.size();
  replaced_.assign(num_old, 0);
  visited_.assign(num_old, 0);
  std::vector<pcl::index_t> chain; // old hull vertices seen from new points

  // 1. Locate the new points (along a Z-order curve: consecutive walks are short) and
  // collect the replaced triangles and the hull edges the new points see.
  pcl::index_t hint = 0;
  const auto order = locationOrder(q);
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const auto k = static_cast<std::size_t>(order[rank].second);
    const auto stamp = static_cast<std::uint32_t>(rank + 1);
    HullEdge exit;
    if (locate(q[k], hint, exit)) {
      collectConflicts(hint, q[k], stamp);
      continue;
    }
    if (exit.triangle < 0) {
      detail::setError(error, "insertDelaunayPoints: point location did not terminate");
      return false;
    }
    // Outside the hull: the chain of hull edges visible from q, both ways from exit.
    const auto visit = [&](const HullEdge& h) {
      seen_hull_.push_back(h);
      const Triangle& tri = t_[h.triangle];
      chain.push_back(tri[(h.opposite + 1) % 3]);
      chain.push_back(tri[(h.opposite + 2) % 3]);
      if (visited_[h.triangle] != stamp && inConflict(h.triangle, q[k]))
        collectConflicts(h.triangle, q[k], stamp);
    };
    visit(exit);
    std::size_t guard = 0;
    for (const bool forward : {true, false})
      for (HullEdge h = nextHullEdge(exit, forward);
           h.triangle >= 0 && visible(h, q[k]) && guard <= 2 * num_old + 1;
           h = nextHullEdge(h, forward), ++guard)
        visit(h);
  }

  // 2. The new numbering: the union in lexicographic order.
  detail::resizeLarge(info.old_to_new_point, p_.size());
  info.inserted_points.resize(q.size());
  detail::resizeLarge(out_points, p_.size() + q.size());
  mergeInChunks(
      p_.size(),
      q.size(),
      [](std::size_t) { return false; },
      [](std::size_t) { return std::size_t{0}; },
      [&](std::size_t i) {
        return static_cast<std::size_t>(std::lower_bound(q.begin(), q.end(), p_[i]) -
                                        q.begin());
      },
      [&](std::size_t i, std::size_t j) { return p_[i] < q[j]; },
      [&](std::size_t i, pcl::index_t id) {
        info.old_to_new_point[i] = id;
        out_points[id] = p_[i];
      },
      [&](std::size_t j, pcl::index_t id) {
        info.inserted_points[j] = id;
        out_points[id] = q[j];
      },
      threads_);
  const auto& remap = info.old_to_new_point;

  // 3. The boundary of the kept triangles around the region: edges between a kept and
  // a replaced triangle, and old hull edges of kept triangles that new points see.
  struct Boundary {
    std::uint64_t key;
    pcl::index_t kept; // old id of the kept triangle
  };
  std::vector<Boundary> boundary;
  std::vector<pcl::index_t> local; // new ids of the local points
  for (const pcl::index_t t : conflicts_) {
    for (int i = 0; i < 3; ++i) {
      local.push_back(remap[t_[t][i]]);
      const pcl::index_t u = n_[t][i];
      if (u < 0 || replaced_[u])
        continue;
      for (const pcl::index_t v : t_[u]) // one ring more around the region
        local.push_back(remap[v]);
      boundary.push_back(
          {undirectedEdgeKey(remap[t_[t][(i + 1) % 3]], remap[t_[t][(i + 2) % 3]]), u});
    }
  }
  for (const HullEdge& h : seen_hull_)
    if (!replaced_[h.triangle]) {
      const Triangle& tri = t_[h.triangle];
      boundary.push_back({undirectedEdgeKey(remap[tri[(h.opposite + 1) % 3]],
                                  remap[tri[(h.opposite + 2) % 3]]),
                          h.triangle});
    }
  for (const pcl::index_t v : chain)
    local.push_back(remap[v]);
  local.insert(local.end(), info.inserted_points.begin(), info.inserted_points.end());
  std::sort(local.begin(), local.end());
  local.erase(std::unique(local.begin(), local.end()), local.end());
  detail::sortByKey(boundary);
  boundary.erase(std::unique(boundary.begin(),
                             boundary.end(),
                             [](const Boundary& a, const Boundary& b) {
                               return a.key == b.key;
                             }),
                 boundary.end());
  const auto findBoundary = [&](std::uint64_t key) -> const Boundary* {
    return detail::findByKey(boundary, key);
  };

  // 4. The local triangulation (its points are sorted: the sweep's fast path), and the
  // flood from the triangles at new points, stopped by the boundary.
  std::vector<QuantizedPoint> local_points(local.size());
  for (std::size_t i = 0; i < local.size(); ++i)
    local_points[i] = out_points[local[i]];
  std::vector<Triangle> local_tris, local_nbrs;
  if (!detail::delaunaySweep(local_points, local_tris, &local_nbrs, error))
    return false;
  std::vector<std::uint8_t> is_new_point(local.size(), 0);
  for (std::size_t i = 0, j = 0; i < local.size(); ++i) {
    while (j < info.inserted_points.size() && info.inserted_points[j] < local[i])
      ++j;
    is_new_point[i] =
        j < info.inserted_points.size() && info.inserted_points[j] == local[i];
  }
  std::vector<std::uint8_t> in_region(local_tris.size(), 0);
  stack_.clear();
  for (std::size_t t = 0; t < local_tris.size(); ++t)
    if (is_new_point[local_tris[t][0]] || is_new_point[local_tris[t][1]] ||
        is_new_point[local_tris[t][2]]) {
      in_region[t] = 1;
      stack_.push_back(static_cast<pcl::index_t>(t));
    }
  std::vector<std::uint8_t> matched(boundary.size(), 0);
  while (!stack_.empty()) {
    const pcl::index_t t = stack_.back();
    stack_.pop_back();
    for (int i = 0; i < 3; ++i) {
      const pcl::index_t u = local_nbrs[t][i];
      if (u < 0 || in_region[u])
        continue;
      if (findBoundary(undirectedEdgeKey(local[local_tris[t][(i + 1) % 3]],
                               local[local_tris[t][(i + 2) % 3]])))
        continue;
      in_region[u] = 1;
      stack_.push_back(u);
    }
  }

  // 5. Assemble: kept triangles renumbered (still in canonical order, since the
  // renumbering keeps the order of the points) merged with the region's triangles
  // (canonical in local ids, and local ids increase with new ids).
  std::vector<Triangle> fresh;
  std::vector<pcl::index_t> fresh_local;
  for (std::size_t t = 0; t < local_tris.size(); ++t)
    if (in_region[t]) {
      const Triangle& lt = local_tris[t];
      fresh.push_back({local[lt[0]], local[lt[1]], local[lt[2]]});
      fresh_local.push_back(static_cast<pcl::index_t>(t));
    }
  const std::size_t num_kept = num_old - conflicts_.size();
  const std::size_t total = num_kept + fresh.size();
  detail::resizeLarge(out_triangles, total);
  detail::resizeLarge(info.old_to_new_triangle, num_old);
  info.new_triangles.resize(fresh.size());
  std::vector<pcl::index_t> local_to_new(local_tris.size(), -1);
  std::sort(conflicts_.begin(), conflicts_.end());
  const auto keptAt = [&](std::size_t k) {
    const Triangle& o = t_[k];
    return Triangle{remap[o[0]], remap[o[1]], remap[o[2]]};
  };
  mergeInChunks(
      num_old,
      fresh.size(),
      [&](std::size_t k) { return replaced_[k] != 0; },
      [&](std::size_t k) {
        return static_cast<std::size_t>(
            std::lower_bound(conflicts_.begin(), conflicts_.end(),
                             static_cast<pcl::index_t>(k)) -
            conflicts_.begin());
      },
      // The renumbering keeps the order of the points, so the old triangles, replaced
      // or not, stay in canonical order.
      [&](std::size_t k) {
        return static_cast<std::size_t>(
            std::lower_bound(fresh.begin(), fresh.end(), keptAt(k)) - fresh.begin());
      },
      [&](std::size_t k, std::size_t j) { return keptAt(k) < fresh[j]; },
      [&](std::size_t k, pcl::index_t id) {
        info.old_to_new_triangle[k] = id;
        out_triangles[id] = keptAt(k);
      },
      [&](std::size_t j, pcl::index_t id) {
        local_to_new[fresh_local[j]] = id;
        info.new_triangles[j] = id;
        out_triangles[id] = fresh[j];
      },
      threads_);
  for (const pcl::index_t t : conflicts_)
    info.old_to_new_triangle[t] = -1;

  // 6. Adjacency: kept pairs renumbered; across the boundary through the edge keys.
  std::unordered_map<std::uint64_t, pcl::index_t> fresh_edges; // region side
  for (std::size_t j = 0; j < fresh.size(); ++j) {
    const pcl::index_t lt = fresh_local[j];
    for (int i = 0; i < 3; ++i) {
      const pcl::index_t u = local_nbrs[lt][i];
      if (u >= 0 && in_region[u])
        continue;
      const std::uint64_t key =
          undirectedEdgeKey(fresh[j][(i + 1) % 3], fresh[j][(i + 2) % 3]);
      if (const Boundary* b = findBoundary(key)) {
        const auto index = static_cast<std::size_t>(b - boundary.data());
        if (matched[index]++) {
          detail::setError(error, "insertDelaunayPoints: a boundary edge is matched "
                                  "twice");
          return false;
        }
        fresh_edges.emplace(key, local_to_new[lt]);
      }
    }
  }
  if (std::find(matched.begin(), matched.end(), 0) != matched.end()) {
    detail::setError(error, "insertDelaunayPoints: the re-triangulated region does not "
                            "meet the kept triangles");
    return false;
  }
  detail::assignLarge(out_neighbours, total, Triangle{-1, -1, -1});
  std::size_t hull_edges = 0;
  const auto n_old = static_cast<std::ptrdiff_t>(num_old);
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(threads_)) schedule(static) \
    if (num_old >= detail::kMinParallelItems) reduction(+ : hull_edges)
#endif
  for (std::ptrdiff_t k = 0; k < n_old; ++k) {
    const pcl::index_t id = info.old_to_new_triangle[k];
    if (id < 0)
      continue;
    for (int i = 0; i < 3; ++i) {
      const pcl::index_t u = n_[k][i];
      if (u >= 0 && !replaced_[u]) {
        out_neighbours[id][i] = info.old_to_new_triangle[u];
        continue;
      }
      const Triangle& tri = out_triangles[id];
      const auto it =
          fresh_edges.find(undirectedEdgeKey(tri[(i + 1) % 3], tri[(i + 2) % 3]));
      if (it != fresh_edges.end())
        out_neighbours[id][i] = it->second;
      else
        ++hull_edges;
    }
  }
  for (std::size_t j = 0; j < fresh.size(); ++j) {
    const pcl::index_t lt = fresh_local[j];
    const pcl::index_t id = local_to_new[lt];
    for (int i = 0; i < 3; ++i) {
      const pcl::index_t u = local_nbrs[lt][i];
      if (u >= 0 && in_region[u]) {
        out_neighbours[id][i] = local_to_new[u];
        continue;
      }
      const Boundary* b =
          findBoundary(undirectedEdgeKey(fresh[j][(i + 1) % 3], fresh[j][(i + 2) % 3]));
      if (b)
        out_neighbours[id][i] = info.old_to_new_triangle[b->kept];
      else
        ++hull_edges;
    }
  }
  // Euler: a triangulation of V points with h of them on its boundary has 2V - h - 2
  // triangles (every point a vertex, as in any Delaunay triangulation).
  if (2 * out_points.size() < hull_edges + 2 ||
      total != 2 * out_points.size() - hull_edges - 2) {
    detail::setError(error, "insertDelaunayPoints: the stitched mesh fails Euler's "
                            "count");
    return false;
  }
  info.replaced_triangles = conflicts_.size();
  info.local_points = local.size();
  return true;
}

} // namespace

bool
insertDelaunayPoints(std::vector<QuantizedPoint>& points,
                     std::vector<Triangle>& triangles,
                     std::vector<Triangle>& neighbours,
                     std::vector<QuantizedPoint> new_points,
                     DelaunayInsertion& info,
                     std::string* error,
                     unsigned int num_threads)
{
  info = DelaunayInsertion();
  // Compared without std::abs, whose value at INT_MIN is undefined.
  const auto inRange = [](const QuantizedPoint& p) {
    return p[0] >= -kMaxDelaunayCoordinate && p[0] <= kMaxDelaunayCoordinate &&
           p[1] >= -kMaxDelaunayCoordinate && p[1] <= kMaxDelaunayCoordinate;
  };
  if (triangles.empty() || neighbours.size() != triangles.size()) {
    detail::setError(error,
                     "insertDelaunayPoints: the old triangulation has no triangles");
    return false;
  }
  for (std::size_t i = 1; i < points.size(); ++i)
    if (!(points[i - 1] < points[i])) {
      detail::setError(error,
                       "insertDelaunayPoints: the old points are not sorted and distinct");
      return false;
    }
  if (!std::all_of(points.begin(), points.end(), inRange)) {
    detail::setError(error, "insertDelaunayPoints: an old point is out of range");
    return false;
  }
  std::sort(new_points.begin(), new_points.end());
  for (std::size_t i = 0; i < new_points.size(); ++i) {
    if (!inRange(new_points[i]) || (i > 0 && new_points[i - 1] == new_points[i]) ||
        std::binary_search(points.begin(), points.end(), new_points[i])) {
      detail::setError(error,
                       "insertDelaunayPoints: a new point is out of range, repeated or "
                       "already in the triangulation");
      return false;
    }
  }
  if (new_points.empty()) {
    detail::resizeLarge(info.old_to_new_point, points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      info.old_to_new_point[i] = static_cast<pcl::index_t>(i);
    detail::resizeLarge(info.old_to_new_triangle, triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i)
      info.old_to_new_triangle[i] = static_cast<pcl::index_t>(i);
    return true;
  }
  std::vector<QuantizedPoint> out_points;
  std::vector<Triangle> out_triangles, out_neighbours;
  Inserter inserter(points, triangles, neighbours, num_threads);
  if (!inserter.run(new_points, out_points, out_triangles, out_neighbours, info, error)) {
    info = DelaunayInsertion();
    return false;
  }
  points.swap(out_points);
  triangles.swap(out_triangles);
  neighbours.swap(out_neighbours);
  return true;
}

} // namespace selective_seg
} // namespace pcl
