/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

/* The Sweep backend of delaunay2d(): an advancing-front sweep over the points in
 * lexicographic order with exact integer predicates, one exact pass over all edges that
 * repairs and classifies them, then the canonical fans. See docs/delaunay.md. */

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/parallel_exceptions.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "delaunay_2d_backends.h"

namespace pcl {
namespace selective_seg {

namespace {

using detail::allCollinear;
using detail::findByKey;
using detail::inCircle;
using detail::Int128;
using detail::kNone;
using detail::orientation;
using detail::sortByKey;
using detail::undirectedEdgeKey;

// ------------------------------------------------------------------ the order

bool
isStrictlySorted(const std::vector<QuantizedPoint>& points)
{
  for (std::size_t i = 1; i < points.size(); ++i)
    if (!(points[i - 1] < points[i]))
      return false;
  return true;
}

/** Number of bits needed to write \a value. */
int
bitWidth(std::uint64_t value)
{
  int bits = 0;
  while (value >> bits)
    ++bits;
  return bits;
}

/** Keys ordered like the points (x, then y), packed relative to the smallest
 * coordinates; \a bits receives the number of bits the keys use. */
std::vector<std::uint64_t>
sortKeys(const std::vector<QuantizedPoint>& points, int& bits)
{
  std::int64_t min_x = points[0][0], max_x = min_x, min_y = points[0][1], max_y = min_y;
  for (const auto& p : points) {
    min_x = std::min<std::int64_t>(min_x, p[0]);
    max_x = std::max<std::int64_t>(max_x, p[0]);
    min_y = std::min<std::int64_t>(min_y, p[1]);
    max_y = std::max<std::int64_t>(max_y, p[1]);
  }
  const int y_bits = bitWidth(static_cast<std::uint64_t>(max_y - min_y));
  bits = y_bits + bitWidth(static_cast<std::uint64_t>(max_x - min_x));
  std::vector<std::uint64_t> keys;
  detail::resizeLarge(keys, points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    keys[i] = (static_cast<std::uint64_t>(points[i][0] - min_x) << y_bits) |
              static_cast<std::uint64_t>(points[i][1] - min_y);
  return keys;
}

/** The ids of \a points in lexicographic order (a stable least-significant-digit radix
 * sort of their keys); \a keys receives the sorted keys. */
std::vector<index_t>
sortedOrder(const std::vector<QuantizedPoint>& points, std::vector<std::uint64_t>& keys)
{
  int bits = 0;
  keys = sortKeys(points, bits);
  const std::size_t n = points.size();
  std::vector<index_t> order;
  detail::resizeLarge(order, n);
  for (std::size_t i = 0; i < n; ++i)
    order[i] = static_cast<index_t>(i);
  const int passes = std::max(1, (bits + 10) / 11);
  const int digit_bits = (bits + passes - 1) / passes;
  const std::uint64_t mask = (std::uint64_t{1} << digit_bits) - 1;
  std::vector<std::uint64_t> key_buffer;
  detail::resizeLarge(key_buffer, n);
  std::vector<index_t> order_buffer;
  detail::resizeLarge(order_buffer, n);
  std::vector<std::size_t> offsets(mask + 2);
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * digit_bits;
    std::fill(offsets.begin(), offsets.end(), 0);
    for (const std::uint64_t key : keys)
      ++offsets[((key >> shift) & mask) + 1];
    for (std::size_t d = 1; d < offsets.size(); ++d)
      offsets[d] += offsets[d - 1];
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t slot = offsets[(keys[i] >> shift) & mask]++;
      key_buffer[slot] = keys[i];
      order_buffer[slot] = order[i];
    }
    keys.swap(key_buffer);
    order.swap(order_buffer);
  }
  return order;
}

// -------------------------------------------------------------- the half-edges

/** Triangle of half-edge \a e: half-edges 4t, 4t + 1, 4t + 2 belong to triangle t (a
 * stride of four keeps these helpers to bit operations; ids 4t + 3 are unused). */
inline index_t
triangleOf(index_t e)
{
  return e >> 2;
}

/** Corner of half-edge \a e in its triangle: e runs from that corner to the next. */
inline int
cornerOf(index_t e)
{
  return e & 3;
}

/** Next half-edge counter-clockwise in the same triangle. */
inline index_t
nextEdge(index_t e)
{
  return cornerOf(e) == 2 ? e - 2 : e + 1;
}

/** Previous half-edge counter-clockwise in the same triangle. */
inline index_t
previousEdge(index_t e)
{
  return cornerOf(e) == 0 ? e + 2 : e - 1;
}

/** Whether the corner at b of the path a -> b -> c is a notch of an upward front worth
 * closing by the triangle (a, c, b) right away: a right turn with an angle below about
 * 100 degrees (its cosine above -1/5). Closing these keeps the front short and its
 * edges local; wider notches wait for the end. Exact: the products stay below 2^123. */
bool
isSharpNotch(const QuantizedPoint& a, const QuantizedPoint& b, const QuantizedPoint& c)
{
  if (orientation(a, b, c) >= 0)
    return false;
  const std::int64_t ax = std::int64_t{a[0]} - b[0], ay = std::int64_t{a[1]} - b[1];
  const std::int64_t cx = std::int64_t{c[0]} - b[0], cy = std::int64_t{c[1]} - b[1];
  const std::int64_t dot = ax * cx + ay * cy;
  if (dot >= 0)
    return true;
  const Int128 lengths = Int128{ax * ax + ay * ay} * (cx * cx + cy * cy);
  return 25 * (Int128{dot} * dot) < lengths;
}

/** A triangulation of distinct points sorted lexicographically, not all collinear,
 * built by an advancing-front sweep: Delaunay but for the few edges that the sweep's
 * local flips miss (repairAndClassify() flips those).
 *
 * Two artificial points, far below and far above the points and left of them, start
 * the front: the right boundary of the triangulated region, a chain of non-decreasing
 * y from the bottom point to the top one. Each new point, lexicographically larger than
 * all before it, lies strictly right of the front edge spanning its y and becomes the
 * apex of a new triangle on that edge; the sharp notches it leaves on either side are
 * closed, and Lawson's exact flips check every new edge. At the end, the pockets
 * between the front and its convex hull are filled and the artificial points are
 * flipped away.
 *
 * Storage: triangle t holds its corners counter-clockwise and owns half-edges 4t + i,
 * from corner i to corner i + 1; twin(e) is the opposite half-edge in the neighbouring
 * triangle, kNone on the boundary. Removed triangles hold kNone corners.
 */
class SweepTriangulation {
public:
  /** \a num_threads: threads of the final classification pass (the result does not
   * depend on it); the sweep itself is sequential. */
  SweepTriangulation(const std::vector<QuantizedPoint>& points, int num_threads = 1)
  : SweepTriangulation(points.data(), points.size(), num_threads)
  {}

  /** The same over the \a count points from \a first. With \a storage, the triangles
   * are written there (room for maxTriangles(count) of them) instead of in storage of
   * its own. */
  SweepTriangulation(const QuantizedPoint* first,
                     std::size_t count,
                     int num_threads,
                     Triangle* storage = nullptr);

  /** The most triangle slots the sweep of \a count points uses: it creates
   * 2 (count + 2) - 5 triangles at most. */
  static std::size_t maxTriangles(std::size_t count) { return 2 * count + 4; }

  /** Sweeps, completes the convex hull, removes the artificial points, then repairs and
   * classifies every edge (repairAndClassify()). Returns false, unfinished, if that
   * takes more than about 16 flips per point: insertion in sweep order can flip much
   * of the triangulation at each point on inputs such as points along concave curves,
   * while area-sampled clouds need fewer than one flip per point. */
  bool build();

  /** Triangles, removed ones included (kNone corners), in storage of its own (not
   * with external storage). */
  std::vector<Triangle>& triangles()
  {
    own_triangles_.resize(static_cast<std::size_t>(num_triangles_));
    return own_triangles_;
  }

  /** Number of triangle slots used, removed ones included. */
  index_t numTriangles() const { return num_triangles_; }

  const Triangle& triangle(index_t t) const { return triangles_[t]; }

  /** The input points (then the two artificial ones). */
  const std::vector<QuantizedPoint>& points() const { return points_; }

  index_t numHalfEdges() const { return 4 * num_triangles_; }

  index_t origin(index_t e) const { return triangles_[triangleOf(e)][cornerOf(e)]; }

  index_t twin(index_t e) const { return twins_[e]; }

  /** Whether the triangles on both sides of interior half-edge \a e share their
   * circumcircle (valid after repairAndClassify()). */
  bool isOnCircle(index_t e) const { return circle_[e] == kOnCircle; }

  /** Splits one co-circular group (its triangles' slots) by the canonical fan
   * (detail::refanGroup()) and relinks the twins of its half-edges and of the
   * half-edges across its boundary, so that the half-edge structure stays valid.
   * False if the fan's polygon edges are not the group's (an internal error). */
  bool refan(const std::vector<QuantizedPoint>& points, const std::vector<index_t>& group);

  /** The adjacency of the live triangles in computeTriangleNeighbours()'s layout
   * (neighbour i across the edge opposite corner i, -1 on the boundary), one row per
   * slot; rows of removed triangles are left -1. */
  void neighbours(std::vector<Triangle>& out) const;

  /** The same, written to out[0], ..., out[numTriangles() - 1]. */
  void neighbours(Triangle* out) const;

private:
  /** What the last in-circle test of an edge found, while its two triangles remain. */
  enum CircleState : char { kUntested = 0, kOffCircle, kOnCircle };

  /** In-circle determinant of the vertex across interior half-edge \a e against the
   * circumcircle of e's triangle: positive if the edge is not locally Delaunay. */
  Int128 inCircleAcross(index_t e) const
  {
    return inCircle(points_[origin(e)],
                    points_[origin(nextEdge(e))],
                    points_[origin(previousEdge(e))],
                    points_[origin(previousEdge(twins_[e]))]);
  }

  Int128 classify(index_t e);
  void forget(index_t e);
  bool repairAndClassify();
  bool overBudget() const { return flips_ > flip_budget_; }
  void flip(index_t e);
  void start();
  void insert(index_t p);
  index_t locate(index_t p);
  void closeNotchesAbove(index_t p);
  bool closeNotchBelow(index_t p, bool sharp_only);
  void closeNotch(index_t left, index_t middle, index_t right);
  void convexifyFront();
  void removeVertex(index_t v);
  void flipSpokesAway(index_t v, index_t boundary_spoke);
  bool canFlipSpoke(index_t v, index_t s) const;
  double earPower(index_t v, index_t s) const;
  void deleteStar(index_t boundary_spoke);
  index_t addTriangle(index_t a, index_t b, index_t c);
  void setCorner(index_t e, index_t v);
  void link(index_t e, index_t other);
  void joinFront(index_t lower, index_t upper);
  void legalize();
  bool flipIfIllegal(index_t e);

  /** The input points, then the bottom and the top artificial point. */
  std::vector<QuantizedPoint> points_;
  index_t bottom_ = 0, top_ = 0;
  std::vector<Triangle> own_triangles_;
  Triangle* triangles_ = nullptr; // own_triangles_ or external storage
  index_t num_triangles_ = 0;
  /** Per half-edge (four per triangle), allocated for the most triangles the sweep
   * can make: the twin, and the CircleState of the edge. */
  std::unique_ptr<index_t[]> twins_;
  std::unique_ptr<CircleState[]> circle_;
  /** Front links, kNone off the front. Once the front is done, flipSpokesAway() uses
   * them as scratch (a spoke and an ear stamp per vertex). */
  std::vector<index_t> front_next_, front_previous_;
  /** Per vertex, a boundary half-edge leaving it: on the front, the one to its
   * successor. */
  std::vector<index_t> boundary_edge_;
  /** Front vertices by y bucket (a hint: entries may have left the front). */
  std::vector<index_t> buckets_;
  std::int64_t bucket_base_ = 0;
  int bucket_shift_ = 0;
  std::vector<index_t> stack_;
  std::int64_t flips_ = 0, flip_budget_ = 0;
  int num_threads_ = 1;
  /** refan() scratch: the polygon's corners, and its boundary half-edges as
   * (origin, destination, twin across, circle state). */
  struct BoundaryEdge {
    index_t from, to, twin;
    CircleState circle;
  };
  std::vector<index_t> corners_;
  std::vector<BoundaryEdge> boundary_;
};

SweepTriangulation::SweepTriangulation(const QuantizedPoint* first,
                                       std::size_t count,
                                       int num_threads,
                                       Triangle* storage)
    : num_threads_(std::max(1, num_threads))
{
  const auto n = static_cast<index_t>(count);
  detail::reserveLarge(points_, count + 2);
  points_.assign(first, first + count);
  if (storage == nullptr) {
    detail::resizeLarge(own_triangles_, maxTriangles(count));
    storage = own_triangles_.data();
  }
  triangles_ = storage;
  const std::size_t half_edges = 8 * static_cast<std::size_t>(n) + 16;
  twins_.reset(new index_t[half_edges]);
  detail::adviseHugePages(twins_.get(), half_edges * sizeof(index_t));
  circle_.reset(new CircleState[half_edges]);
  detail::adviseHugePages(circle_.get(), half_edges * sizeof(CircleState));
  detail::assignLarge(front_next_, n + 2, kNone);
  detail::assignLarge(front_previous_, n + 2, kNone);
  detail::assignLarge(boundary_edge_, n + 2, kNone);
  stack_.reserve(64);
  flip_budget_ = 16 * std::int64_t{n} + 65536;
}

bool
SweepTriangulation::build()
{
  const auto n = static_cast<index_t>(points_.size());
  start();
  for (index_t p = 1; p < n; ++p) {
    insert(p);
    if (overBudget())
      return false;
  }
  convexifyFront();
  if (overBudget())
    return false;
  removeVertex(bottom_);
  removeVertex(top_);
  return repairAndClassify();
}

/** Places the artificial points and the first triangle (bottom, point 0, top). They
 * lie up to 2^27 beyond the points, so coordinate differences stay below 2^29, where
 * the predicates are still exact (int64 / int128, see the bounds in
 * delaunay_2d_backends.h). */
void
SweepTriangulation::start()
{
  std::int32_t min_y = points_[0][1], max_y = min_y;
  for (const auto& p : points_) {
    min_y = std::min(min_y, p[1]);
    max_y = std::max(max_y, p[1]);
  }
  const std::int32_t far =
      std::min(std::max(max_y - min_y, points_.back()[0] - points_[0][0]) + 16,
               2 * kMaxDelaunayCoordinate);
  bottom_ = static_cast<index_t>(points_.size());
  top_ = bottom_ + 1;
  points_.push_back({points_[0][0] - far, min_y - far});
  points_.push_back({points_[0][0] - far, max_y + far});
  const index_t e = addTriangle(bottom_, 0, top_);
  twins_[e] = twins_[e + 1] = twins_[e + 2] = kNone;
  boundary_edge_[bottom_] = e;
  boundary_edge_[0] = e + 1;
  boundary_edge_[top_] = e + 2;
  joinFront(bottom_, 0);
  joinFront(0, top_);
  // About two buckets per front vertex of a square cloud.
  int shift = 0;
  const std::int64_t range = std::int64_t{max_y} - min_y;
  const auto wanted = static_cast<std::int64_t>(2 * std::sqrt(points_.size()) + 16);
  while ((range >> shift) >= wanted)
    ++shift;
  bucket_base_ = min_y;
  bucket_shift_ = shift;
  buckets_.assign(static_cast<std::size_t>(range >> shift) + 1, kNone);
  buckets_[(std::int64_t{points_[0][1]} - min_y) >> shift] = 0;
}

/** Inserts \a p on the front edge spanning its y, closes the sharp notches beside it
 * and restores the Delaunay property around the new triangles. */
void
SweepTriangulation::insert(index_t p)
{
  const index_t a = locate(p);
  const index_t b = front_next_[a];
  const index_t e = addTriangle(a, p, b);
  twins_[e] = twins_[e + 1] = kNone;
  link(e + 2, boundary_edge_[a]);
  boundary_edge_[a] = e;
  boundary_edge_[p] = e + 1;
  joinFront(a, p);
  joinFront(p, b);
  stack_.push_back(e + 2);
  legalize();
  closeNotchesAbove(p);
  while (closeNotchBelow(p, true)) {
  }
  buckets_[(std::int64_t{points_[p][1]} - bucket_base_) >> bucket_shift_] = p;
}

/** The front vertex a with y(a) <= y(p) < y(front_next_[a]), found from the nearest
 * bucket at or below p's. */
index_t
SweepTriangulation::locate(index_t p)
{
  const std::int32_t y = points_[p][1];
  auto bucket = (std::int64_t{y} - bucket_base_) >> bucket_shift_;
  index_t a = bottom_;
  for (; bucket >= 0; --bucket) {
    const index_t v = buckets_[bucket];
    if (v != kNone && front_next_[v] != kNone) {
      a = v;
      break;
    }
  }
  while (points_[front_next_[a]][1] <= y)
    a = front_next_[a];
  while (points_[a][1] > y)
    a = front_previous_[a];
  return a;
}

/** Closes the sharp notches above \a p: while p -> b -> c is one, adds (p, c, b). */
void
SweepTriangulation::closeNotchesAbove(index_t p)
{
  while (true) {
    const index_t b = front_next_[p];
    const index_t c = front_next_[b];
    if (c == kNone || !isSharpNotch(points_[p], points_[b], points_[c]))
      return;
    closeNotch(p, b, c);
  }
}

/** Closes the front notch left -> middle -> right by the triangle (left, right,
 * middle): \a middle leaves the front, and the new edges are legalized. */
void
SweepTriangulation::closeNotch(index_t left, index_t middle, index_t right)
{
  const index_t e = addTriangle(left, right, middle);
  twins_[e] = kNone;
  link(e + 1, boundary_edge_[middle]);
  link(e + 2, boundary_edge_[left]);
  boundary_edge_[left] = e;
  front_next_[middle] = front_previous_[middle] = kNone;
  joinFront(left, right);
  stack_.push_back(e + 1);
  stack_.push_back(e + 2);
  legalize();
}

/** Closes the notch below \a p, z -> a -> p (a right turn; if \a sharp_only, a sharp
 * one), by the triangle (z, p, a); returns whether there was one. */
bool
SweepTriangulation::closeNotchBelow(index_t p, bool sharp_only)
{
  const index_t a = front_previous_[p];
  const index_t z = a == kNone ? kNone : front_previous_[a];
  if (z == kNone)
    return false;
  const bool notch = sharp_only ? isSharpNotch(points_[z], points_[a], points_[p])
                                : orientation(points_[z], points_[a], points_[p]) < 0;
  if (!notch)
    return false;
  closeNotch(z, a, p);
  return true;
}

/** Closes every notch of the front, bottom to top (a Graham scan), each new triangle
 * checked by Lawson's flips: the region becomes the convex hull of all points, the
 * artificial ones included. */
void
SweepTriangulation::convexifyFront()
{
  for (index_t v = front_next_[bottom_]; v != kNone && !overBudget();
       v = front_next_[v]) {
    while (closeNotchBelow(v, false)) {
    }
  }
}

/** Removes artificial hull vertex \a v: flips its spokes away while one can be
 * flipped, which leaves a convex chain of its neighbours, then deletes its remaining
 * triangles. */
void
SweepTriangulation::removeVertex(index_t v)
{
  const index_t spoke = boundary_edge_[v];
  if (spoke == kNone || origin(spoke) != v)
    return;
  flipSpokesAway(v, spoke);
  deleteStar(boundary_edge_[v]);
  boundary_edge_[v] = kNone;
}

/** Flips the interior spokes of hull vertex \a v away while one can be flipped: spoke
 * v -> u, between the triangles (v, u, after) and (v, before, u), becomes the edge
 * before - after when both new triangles are counter-clockwise. Ears (before, u, after)
 * go first by the power of v with respect to their circumcircle, smallest first, which
 * makes the new triangles Delaunay where the triangulation was; the order only saves
 * flips in repairAndClassify(), any order gives a valid triangulation. */
void
SweepTriangulation::flipSpokesAway(index_t v, index_t boundary_spoke)
{
  struct Ear {
    double power;
    index_t vertex, stamp;
    bool operator>(const Ear& other) const { return power > other.power; }
  };
  std::vector<index_t>& spoke_of = front_next_;
  std::vector<index_t>& stamp = front_previous_;
  std::vector<Ear> heap;
  const auto push = [&](index_t s) {
    const index_t u = origin(nextEdge(s));
    spoke_of[u] = s;
    heap.push_back({earPower(v, s), u, ++stamp[u]});
    std::push_heap(heap.begin(), heap.end(), std::greater<>());
  };
  for (index_t s = twins_[previousEdge(boundary_spoke)]; s != kNone;
       s = twins_[previousEdge(s)])
    push(s);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), std::greater<>());
    const Ear ear = heap.back();
    heap.pop_back();
    const index_t s = spoke_of[ear.vertex];
    if (ear.stamp != stamp[ear.vertex] || !canFlipSpoke(v, s))
      continue;
    flip(s);
    ++stamp[ear.vertex];
    if (twins_[s] != kNone)
      push(s);
    const index_t next_spoke = twins_[previousEdge(s)];
    if (next_spoke != kNone)
      push(next_spoke);
  }
}

/** Whether interior spoke \a s of vertex \a v can be flipped: both triangles it would
 * leave are strictly counter-clockwise. */
bool
SweepTriangulation::canFlipSpoke(index_t v, index_t s) const
{
  const QuantizedPoint& u = points_[origin(nextEdge(s))];
  const QuantizedPoint& after = points_[origin(previousEdge(s))];
  const QuantizedPoint& before = points_[origin(previousEdge(twins_[s]))];
  return orientation(points_[v], before, after) > 0 &&
         orientation(u, after, before) > 0;
}

/** Power of vertex \a v with respect to the circumcircle of the ear of spoke \a s
 * (floating point: it only orders the flips). */
double
SweepTriangulation::earPower(index_t v, index_t s) const
{
  const QuantizedPoint& u = points_[origin(nextEdge(s))];
  const auto offset = [&](index_t w) {
    return std::array<double, 2>{static_cast<double>(points_[w][0]) - u[0],
                                 static_cast<double>(points_[w][1]) - u[1]};
  };
  const auto a = offset(origin(previousEdge(twins_[s])));
  const auto b = offset(origin(previousEdge(s)));
  const auto w = offset(v);
  const double twice_area = 2 * (a[0] * b[1] - a[1] * b[0]);
  if (twice_area == 0)
    return std::numeric_limits<double>::infinity();
  const double a2 = a[0] * a[0] + a[1] * a[1], b2 = b[0] * b[0] + b[1] * b[1];
  const double centre_x = (a2 * b[1] - b2 * a[1]) / twice_area;
  const double centre_y = (b2 * a[0] - a2 * b[0]) / twice_area;
  return w[0] * w[0] + w[1] * w[1] - 2 * (w[0] * centre_x + w[1] * centre_y);
}

/** Deletes the triangles around a hull vertex, from its boundary spoke on; the edges
 * they shared with other triangles become boundary edges. */
void
SweepTriangulation::deleteStar(index_t boundary_spoke)
{
  index_t s = boundary_spoke;
  while (s != kNone) {
    const index_t outer = twins_[nextEdge(s)];
    if (outer != kNone) {
      twins_[outer] = kNone;
      circle_[outer] = kUntested;
      boundary_edge_[origin(outer)] = outer;
    }
    const index_t next_spoke = twins_[previousEdge(s)];
    triangles_[triangleOf(s)] = {kNone, kNone, kNone};
    s = next_spoke;
  }
}

/** Appends the counter-clockwise triangle (a, b, c); returns its first half-edge,
 * a -> b. The twins are left to the caller. */
index_t
SweepTriangulation::addTriangle(index_t a, index_t b, index_t c)
{
  const index_t e = numHalfEdges();
  triangles_[num_triangles_++] = {a, b, c};
  circle_[e] = circle_[e + 1] = circle_[e + 2] = kUntested;
  return e;
}

void
SweepTriangulation::setCorner(index_t e, index_t v)
{
  triangles_[triangleOf(e)][cornerOf(e)] = v;
}

void
SweepTriangulation::link(index_t e, index_t other)
{
  twins_[e] = other;
  twins_[other] = e;
}

void
SweepTriangulation::joinFront(index_t lower, index_t upper)
{
  front_next_[lower] = upper;
  front_previous_[upper] = lower;
}

/** Tests interior half-edge \a e (see inCircleAcross()) and, unless it is illegal,
 * records whether it is on the circle. */
inline Int128
SweepTriangulation::classify(index_t e)
{
  const Int128 inside = inCircleAcross(e);
  if (inside <= 0)
    circle_[e] = circle_[twins_[e]] = inside == 0 ? kOnCircle : kOffCircle;
  return inside;
}

/** Checks the edges on the stack, flipping the illegal ones; a flip puts the two edges
 * it exposes to the same apex on the stack. */
void
SweepTriangulation::legalize()
{
  while (!stack_.empty()) {
    const index_t e = stack_.back();
    stack_.pop_back();
    while (flipIfIllegal(e)) {
    }
  }
}

/** Flips interior half-edge \a e, a -> b of triangle (a, b, p), if the vertex d across
 * lies strictly inside the circumcircle; then e is a -> d of (a, d, p), and the edge
 * d -> b of (b, p, d) goes on the stack. */
bool
SweepTriangulation::flipIfIllegal(index_t e)
{
  const index_t o = twins_[e];
  if (o == kNone || classify(e) <= 0)
    return false;
  flip(e);
  stack_.push_back(previousEdge(o));
  return true;
}

/** Marks the edge of half-edge \a e untested (its triangles changed). */
void
SweepTriangulation::forget(index_t e)
{
  circle_[e] = kUntested;
  if (twins_[e] != kNone)
    circle_[twins_[e]] = kUntested;
}

/** Flips interior half-edge \a e, a -> b, between the triangles (a, b, p) and
 * (b, a, d): they become (a, d, p), with e now a -> d, and (b, p, d) in the other
 * triangle, with twin(e) now b -> p. */
void
SweepTriangulation::flip(index_t e)
{
  ++flips_;
  const index_t o = twins_[e];
  const index_t e_next = nextEdge(e), o_next = nextEdge(o);
  const index_t a = origin(e), b = origin(e_next);
  const index_t outer_ad = twins_[o_next], outer_bp = twins_[e_next];
  setCorner(e_next, origin(previousEdge(o)));
  setCorner(o_next, origin(previousEdge(e)));
  if (outer_ad == kNone) {
    twins_[e] = kNone;
    boundary_edge_[a] = e;
  } else {
    link(e, outer_ad);
  }
  if (outer_bp == kNone) {
    twins_[o] = kNone;
    boundary_edge_[b] = o;
  } else {
    link(o, outer_bp);
  }
  link(e_next, o_next);
  for (const index_t changed : {e, previousEdge(e), e_next, o, previousEdge(o)})
    forget(changed);
}

// --------------------------------------------------- repair and co-circular groups

/** Flips the edges the sweep left illegal (Lawson's flips, exact, strict) and tests
 * the edges no test has classified yet, so that every interior edge is locally
 * Delaunay and known to be on or off the circumcircle across it. False if over
 * budget. */
bool
SweepTriangulation::repairAndClassify()
{
  std::vector<index_t>& illegal = stack_;
  // Every interior edge not yet classified, tested once from its lower half-edge (which
  // alone reads and writes the pair's states, so the triangles can be split among
  // threads); the illegal ones listed in increasing order, whatever the thread count.
  const index_t num_triangles = num_triangles_;
  const bool parallel =
      static_cast<std::size_t>(num_triangles) >= detail::kMinParallelItems;
  const int threads = parallel ? num_threads_ : 1;
  std::vector<std::vector<index_t>> found(static_cast<std::size_t>(threads));
  detail::ParallelExceptions errors;
#ifdef _OPENMP
#pragma omp parallel num_threads(threads)
#endif
  {
#ifdef _OPENMP
    std::vector<index_t>& mine = found[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
#else
    std::vector<index_t>& mine = found[0];
#endif
    for (index_t t = 0; t < num_triangles; ++t) {
      if (triangles_[t][0] == kNone)
        continue;
      for (index_t e = 4 * t; e < 4 * t + 3; ++e)
        if (twins_[e] > e && circle_[e] == kUntested && classify(e) > 0)
          errors.run([&] { mine.push_back(e); });
    }
  }
  errors.rethrow();
  for (const auto& part : found)
    illegal.insert(illegal.end(), part.begin(), part.end());
  while (!illegal.empty() && !overBudget()) {
    const index_t e = illegal.back();
    illegal.pop_back();
    const index_t o = twins_[e];
    if (o == kNone || classify(e) <= 0)
      continue;
    flip(e);
    for (const index_t exposed : {e, previousEdge(e), nextEdge(e), o, previousEdge(o)})
      illegal.push_back(exposed);
  }
  return !overBudget();
}

bool
SweepTriangulation::refan(const std::vector<QuantizedPoint>& points,
                          const std::vector<index_t>& group)
{
  // The group's boundary half-edges: the polygon's edges, counter-clockwise, which the
  // fan keeps (an edge between two triangles of the group is on their common circle).
  boundary_.clear();
  for (const index_t g : group)
    for (index_t e = 4 * g; e < 4 * g + 3; ++e)
      if (!isOnCircle(e))
        boundary_.push_back({origin(e), origin(nextEdge(e)), twins_[e], circle_[e]});
  const auto by_ends = [](const BoundaryEdge& a, const BoundaryEdge& b) {
    return a.from < b.from || (a.from == b.from && a.to < b.to);
  };
  std::sort(boundary_.begin(), boundary_.end(), by_ends);
  detail::refanGroup(points, group, triangles_, corners_);
  // Fan triangle s is (c0, c[s + 1], c[s + 2]) in slot group[s]: its edge c[s + 2] -> c0
  // (corner 2) is the twin of the next one's c0 -> c[s + 2] (corner 0); the others lie
  // on the polygon.
  for (std::size_t s = 0; s < group.size(); ++s) {
    const index_t first = 4 * group[s];
    for (index_t e = first; e < first + 3; ++e) {
      if ((e == first && s > 0) || (e == first + 2 && s + 1 < group.size())) {
        const index_t partner = e == first ? 4 * group[s - 1] + 2 : 4 * group[s + 1];
        twins_[e] = partner;
        circle_[e] = kOnCircle;
        continue;
      }
      const BoundaryEdge key{origin(e), origin(nextEdge(e)), kNone, kUntested};
      const auto found =
          std::lower_bound(boundary_.begin(), boundary_.end(), key, by_ends);
      if (found == boundary_.end() || found->from != key.from || found->to != key.to)
        return false;
      twins_[e] = found->twin;
      circle_[e] = found->circle;
      if (found->twin != kNone)
        twins_[found->twin] = e;
    }
  }
  return true;
}

void
SweepTriangulation::neighbours(std::vector<Triangle>& out) const
{
  detail::resizeLarge(out, static_cast<std::size_t>(num_triangles_));
  neighbours(out.data());
}

void
SweepTriangulation::neighbours(Triangle* out) const
{
  const index_t num_triangles = num_triangles_;
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_threads_) schedule(static) \
    if (static_cast<std::size_t>(num_triangles) >= detail::kMinParallelItems)
#endif
  for (index_t t = 0; t < num_triangles; ++t) {
    out[t] = Triangle{kNone, kNone, kNone};
    if (triangles_[t][0] == kNone)
      continue;
    // The edge opposite corner i is half-edge i + 1 (from corner i + 1 to i + 2).
    for (int i = 0; i < 3; ++i) {
      const index_t twin = twins_[4 * t + (i + 1) % 3];
      out[t][i] = twin == kNone ? kNone : triangleOf(twin);
    }
  }
}

/** Splits every group of co-circular triangles (joined across marked edges: the
 * triangulation of one empty circle's polygon) by the canonical fan, in place. False
 * on an internal error (SweepTriangulation::refan()). \a visited: scratch space. */
bool
refanCoCircular(const std::vector<QuantizedPoint>& points,
                SweepTriangulation& mesh,
                std::vector<char>& visited)
{
  visited.assign(static_cast<std::size_t>(mesh.numTriangles()), 0);
  std::vector<index_t> group, pending;
  const auto on_circle = [&](index_t t) {
    return mesh.isOnCircle(4 * t) || mesh.isOnCircle(4 * t + 1) ||
           mesh.isOnCircle(4 * t + 2);
  };
  for (index_t t = 0; t < mesh.numTriangles(); ++t) {
    if (visited[t] || mesh.triangle(t)[0] == kNone || !on_circle(t))
      continue;
    group.clear();
    pending.assign(1, t);
    visited[t] = 1;
    while (!pending.empty()) {
      const index_t u = pending.back();
      pending.pop_back();
      group.push_back(u);
      for (index_t e = 4 * u; e < 4 * u + 3; ++e) {
        const index_t w = mesh.isOnCircle(e) ? triangleOf(mesh.twin(e)) : kNone;
        if (w != kNone && !visited[w]) {
          visited[w] = 1;
          pending.push_back(w);
        }
      }
    }
    if (!mesh.refan(points, group))
      return false;
  }
  return true;
}

/** The Delaunay triangulation of distinct points sorted lexicographically, not all
 * collinear, with the canonical fans, in the points' ids, by slot: removed slots hold
 * kNone corners (detail::canonicalize() drops them). Optionally its adjacency
 * (computeTriangleNeighbours()'s layout, by slot), read off the sweep's half-edges.
 * False if the sweep ran out of budget (SweepTriangulation::build()). */
bool
triangulateSorted(const std::vector<QuantizedPoint>& points,
                  std::vector<Triangle>& triangles,
                  std::vector<Triangle>* neighbours,
                  int num_threads)
{
  SweepTriangulation mesh(points, num_threads);
  if (!mesh.build())
    return false;
  std::vector<char> visited;
  if (!refanCoCircular(points, mesh, visited))
    return false;
  if (neighbours)
    mesh.neighbours(*neighbours);
  triangles.swap(mesh.triangles());
  return true;
}

// ------------------------------------------------------------ slabs in parallel

/** Whether the closed circumdisk of the counter-clockwise triangle (a, b, c) lies
 * strictly right of x = \a left (if \a has_left) and strictly left of x = \a right (if
 * \a has_right), with a < right and a > left. Conservative: false when the rounding
 * leaves it open.
 *
 * With b, c relative to a, the circumcentre is u = (nx, ny) / d with d = 2 orient(a, b,
 * c) > 0, nx = cy |b|^2 - by |c|^2, ny = bx |c|^2 - cx |b|^2 (exact in int64 / int128).
 * The disk stays left of a.x + s (s > 0) iff ux + |u| < s, iff uy^2 + 2 s ux < s^2,
 * iff s^2 d^2 - ny^2 - 2 s nx d > 0;
 * right of a.x - s iff s^2 d^2 - ny^2 + 2 s nx d > 0.
 * These are evaluated in double from correctly rounded nx, ny, d: each of the three
 * terms carries a relative error below 2^-50, so a value above 10^-12 times the sum of
 * their magnitudes has the right sign. */
bool
circumdiskWithin(const QuantizedPoint& a,
                 const QuantizedPoint& b,
                 const QuantizedPoint& c,
                 bool has_left,
                 std::int32_t left,
                 bool has_right,
                 std::int32_t right)
{
  const std::int64_t bx = std::int64_t{b[0]} - a[0], by = std::int64_t{b[1]} - a[1];
  const std::int64_t cx = std::int64_t{c[0]} - a[0], cy = std::int64_t{c[1]} - a[1];
  const std::int64_t b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double d = static_cast<double>(2 * (bx * cy - by * cx));
  const double nx = static_cast<double>(Int128{cy} * b2 - Int128{by} * c2);
  const double ny = static_cast<double>(Int128{bx} * c2 - Int128{cx} * b2);
  const double ny2 = ny * ny;
  const auto clear = [&](double s, double sign) {
    const double outer = s * s * d * d;
    const double cross = 2 * s * nx * d * sign;
    return outer - ny2 - cross > 1e-12 * (outer + ny2 + std::abs(cross));
  };
  return (!has_right || clear(static_cast<double>(std::int64_t{right} - a[0]), 1.0)) &&
         (!has_left || clear(static_cast<double>(std::int64_t{a[0]} - left), -1.0));
}

/** An edge of a kept triangle whose other side is re-triangulated, or on a slab's
 * hull. */
struct SeamEdge {
  std::uint64_t key;
  index_t from;  // the kept triangle runs from -> to (global ids)
  index_t kept;  // slot of the kept triangle
  index_t fresh; // slot of the new triangle across, or kNone
  int corner;    // the edge is opposite this corner of the kept triangle
  bool on_hull;  // no triangle across in the slab
};

/** One slab of the points: its slots in the shared arrays, and what the stitching
 * needs of it. */
struct Slab {
  index_t first = 0, count = 0;    // its points: global ids [first, first + count)
  index_t base = 0, capacity = 0;  // its slots [base, base + capacity)
  std::vector<index_t> local;      // global ids of the points to re-triangulate
  std::vector<SeamEdge> seam;      // edges of kept triangles towards the rest
  std::vector<index_t> free_slots; // slots of the triangles not kept
  std::vector<char> visited;       // scratch of refanCoCircular()
  bool ok = false;
};

/** Triangulates a slab (sweep, canonical fans, adjacency) into its slots of \a
 * triangles and \a neighbours, in global ids. Keeps the triangles whose closed
 * circumdisk stays inside the slab's x range (Delaunay in the union too) and removes
 * the others (kNone corners), listing their points, the slab's hull points and the
 * edges of the kept triangles towards them or the hull. */
void
triangulateSlab(const std::vector<QuantizedPoint>& points,
                Slab& slab,
                std::unique_ptr<SweepTriangulation> mesh,
                bool has_left,
                bool has_right,
                std::vector<Triangle>& triangles,
                std::vector<Triangle>& neighbours)
{
  if (!mesh->build() || !refanCoCircular(mesh->points(), *mesh, slab.visited))
    return;
  const index_t num_slots = mesh->numTriangles();
  mesh->neighbours(neighbours.data() + slab.base);
  mesh.reset();
  const index_t base = slab.base, end = slab.base + slab.capacity;
  const QuantizedPoint* p = points.data() + slab.first;
  const std::int32_t left = has_left ? points[slab.first - 1][0] : 0;
  const std::int32_t right = has_right ? points[slab.first + slab.count][0] : 0;
  // A triangle not kept is marked by its third corner v stored as -2 - v (neither a
  // vertex nor kNone) until the second pass.
  const auto isKept = [&triangles](index_t t) { return triangles[t][2] >= 0; };
  for (index_t t = base; t < base + num_slots; ++t) {
    Triangle& tri = triangles[t];
    if (tri[0] != kNone &&
        !circumdiskWithin(
            p[tri[0]], p[tri[1]], p[tri[2]], has_left, left, has_right, right))
      tri[2] = -2 - tri[2];
  }
  for (index_t t = base; t < end; ++t) {
    Triangle& tri = triangles[t];
    if (t >= base + num_slots || tri[0] == kNone) {
      tri = {kNone, kNone, kNone};
      slab.free_slots.push_back(t);
      continue;
    }
    if (!isKept(t)) {
      for (const index_t v : {tri[0], tri[1], -2 - tri[2]})
        slab.local.push_back(slab.first + v);
      slab.free_slots.push_back(t);
      continue;
    }
    Triangle& row = neighbours[t];
    for (int i = 0; i < 3; ++i) {
      index_t& u = row[i];
      if (u != kNone) {
        u += base;
        if (isKept(u))
          continue;
      }
      const index_t from = slab.first + tri[(i + 1) % 3];
      const index_t to = slab.first + tri[(i + 2) % 3];
      slab.seam.push_back({undirectedEdgeKey(from, to), from, t, kNone, i, u == kNone});
      if (u == kNone) {
        slab.local.push_back(from);
        slab.local.push_back(to);
      }
      u = kNone;
    }
  }
  // Global ids, and the removed triangles' slots free.
  for (index_t t = base; t < end; ++t) {
    Triangle& tri = triangles[t];
    if (tri[0] != kNone && tri[2] >= 0)
      for (auto& v : tri)
        v += slab.first;
    else
      tri = {kNone, kNone, kNone};
  }
  slab.ok = true;
}

/** triangulateSorted()'s triangulation and adjacency (by slot, removed slots kNone),
 * computed on \a num_slabs slabs of the points at once (one per thread) and stitched.
 *
 * The slabs split the points between distinct x. A triangle of a slab's triangulation
 * whose closed circumdisk holds no point of the neighbouring slabs (it stays strictly
 * inside the slab's x range, circumdiskWithin()) has an empty open circumdisk in the
 * union, and its co-circular group, all in the slab, is split the same way there: it
 * is a triangle of the union's triangulation ("kept"). The rest of the union's hull,
 * the region R (the other triangles and the gaps between the slabs' hulls), is tiled by
 * union triangles whose corners lie in the closure of R: corners of the other triangles
 * and the slabs' hull points. With those points L, every union triangle in R is a
 * triangle of DT(L), with the same canonical split, and the edges between R and the
 * kept triangles are edges of DT(L): the triangles of DT(L) found by a flood from those
 * edges, stopped by them, re-tile R (as in insertDelaunayPoints()). They go into free
 * slots (there are always enough: the slots of a slab hold maxTriangles() triangles).
 * Checked: every edge between a kept triangle and R is met by exactly one new
 * triangle, and Euler's count holds for the whole mesh. False (the output is then
 * unusable) if a slab is collinear, over the sweep's budget, or a check fails: the
 * caller triangulates in one piece. */
bool
triangulateSortedInSlabs(const std::vector<QuantizedPoint>& points,
                         int num_slabs,
                         std::vector<Triangle>& triangles,
                         std::vector<Triangle>& neighbours)
{
  const auto n = static_cast<index_t>(points.size());
  std::vector<Slab> slabs(static_cast<std::size_t>(num_slabs));
  index_t begin = 0, slots = 0;
  for (int s = 0; s < num_slabs; ++s) {
    index_t end = s + 1 == num_slabs
                      ? n
                      : static_cast<index_t>(std::int64_t{n} * (s + 1) / num_slabs);
    while (end < n && end > begin && points[end - 1][0] == points[end][0])
      ++end;
    if (end - begin < 3)
      return false;
    if (allCollinear(points.data() + begin, static_cast<std::size_t>(end - begin)))
      return false;
    slabs[s].first = begin;
    slabs[s].count = end - begin;
    slabs[s].base = slots;
    slabs[s].capacity = static_cast<index_t>(
        SweepTriangulation::maxTriangles(static_cast<std::size_t>(end - begin)));
    slots += slabs[s].capacity;
    begin = end;
  }
  if (begin != n)
    return false;

  // The shared arrays and the sweeps' own are allocated here, on the calling thread:
  // memory a worker thread allocates comes from its own malloc arena, which the later
  // stages of a segmentation would not reuse.
  detail::resizeLarge(triangles, static_cast<std::size_t>(slots));
  detail::resizeLarge(neighbours, static_cast<std::size_t>(slots));
  std::vector<std::unique_ptr<SweepTriangulation>> meshes(slabs.size());
  for (std::size_t s = 0; s < slabs.size(); ++s) {
    slabs[s].visited.reserve(static_cast<std::size_t>(slabs[s].capacity));
    meshes[s].reset(new SweepTriangulation(points.data() + slabs[s].first,
                                           static_cast<std::size_t>(slabs[s].count),
                                           1,
                                           triangles.data() + slabs[s].base));
  }
  detail::ParallelExceptions errors;
#ifdef _OPENMP
#pragma omp parallel for num_threads(num_slabs) schedule(static, 1)
#endif
  for (int s = 0; s < num_slabs; ++s)
    errors.run([&] {
      triangulateSlab(points,
                      slabs[s],
                      std::move(meshes[s]),
                      s > 0,
                      s + 1 < num_slabs,
                      triangles,
                      neighbours);
    });
  errors.rethrow();
  std::vector<index_t> local;
  std::vector<SeamEdge> seam;
  for (Slab& slab : slabs) {
    if (!slab.ok)
      return false;
    slab.visited = std::vector<char>();
    local.insert(local.end(), slab.local.begin(), slab.local.end());
    seam.insert(seam.end(), slab.seam.begin(), slab.seam.end());
  }
  std::sort(local.begin(), local.end());
  local.erase(std::unique(local.begin(), local.end()), local.end());
  sortByKey(seam);
  const auto findSeam = [&seam](std::uint64_t key) { return findByKey(seam, key); };

  // DT(L), and the flood from the seam into R.
  std::vector<QuantizedPoint> local_points(local.size());
  for (std::size_t i = 0; i < local.size(); ++i)
    local_points[i] = points[local[i]];
  std::vector<Triangle> local_tris, local_nbrs;
  if (!detail::delaunaySweep(local_points, local_tris, &local_nbrs, nullptr) ||
      local_tris.empty())
    return false;
  const auto edgeFrom = [&](index_t t, int i) {
    return local[local_tris[t][(i + 1) % 3]];
  };
  const auto edgeTo = [&](index_t t, int i) {
    return local[local_tris[t][(i + 2) % 3]];
  };
  std::size_t num_kept = 0;
  for (const Slab& slab : slabs)
    num_kept += static_cast<std::size_t>(slab.capacity) - slab.free_slots.size();
  // With no kept triangle, R is the whole hull; otherwise each part of R borders a kept
  // triangle (a part bounded by the hull alone would be the whole hull).
  std::vector<index_t> slot_of(local_tris.size(), num_kept == 0 ? 0 : kNone);
  std::vector<index_t> stack;
  for (index_t t = 0; t < static_cast<index_t>(local_tris.size()); ++t)
    for (int i = 0; i < 3 && slot_of[t] == kNone; ++i) {
      const SeamEdge* e = findSeam(undirectedEdgeKey(edgeFrom(t, i), edgeTo(t, i)));
      // R lies left of to -> from, the kept triangle's edge reversed.
      if (e && e->from == edgeTo(t, i)) {
        slot_of[t] = 0;
        stack.push_back(t);
      }
    }
  while (!stack.empty()) {
    const index_t t = stack.back();
    stack.pop_back();
    for (int i = 0; i < 3; ++i) {
      const index_t u = local_nbrs[t][i];
      if (u == kNone || slot_of[u] != kNone ||
          findSeam(undirectedEdgeKey(edgeFrom(t, i), edgeTo(t, i))))
        continue;
      slot_of[u] = 0;
      stack.push_back(u);
    }
  }
  // The new triangles' slots: the free ones, slab by slab.
  std::size_t next_slab = 0, next_free = 0;
  for (index_t& slot : slot_of) {
    if (slot == kNone)
      continue;
    while (next_slab < slabs.size() &&
           next_free == slabs[next_slab].free_slots.size()) {
      ++next_slab;
      next_free = 0;
    }
    if (next_slab == slabs.size())
      return false;
    slot = slabs[next_slab].free_slots[next_free++];
  }

  // The new triangles and their adjacency, and across the seam.
  std::size_t hull_edges = 0, total = num_kept;
  for (index_t t = 0; t < static_cast<index_t>(local_tris.size()); ++t) {
    const index_t id = slot_of[t];
    if (id == kNone)
      continue;
    ++total;
    for (int i = 0; i < 3; ++i) {
      triangles[id][i] = local[local_tris[t][i]];
      const index_t u = local_nbrs[t][i];
      if (u != kNone && slot_of[u] != kNone) {
        neighbours[id][i] = slot_of[u];
        continue;
      }
      SeamEdge* e = findSeam(undirectedEdgeKey(edgeFrom(t, i), edgeTo(t, i)));
      if (e == nullptr) {
        if (u != kNone) // the flood crossed every other edge
          return false;
        neighbours[id][i] = kNone;
        ++hull_edges;
        continue;
      }
      if (e->fresh != kNone || e->from != edgeTo(t, i))
        return false;
      e->fresh = id;
      neighbours[id][i] = e->kept;
      neighbours[e->kept][e->corner] = id;
    }
  }
  for (const SeamEdge& e : seam) {
    if (e.fresh == kNone && !e.on_hull)
      return false;
    hull_edges += e.fresh == kNone;
  }
  // Euler: a triangulation of n points, h of them on its boundary, has 2n - h - 2
  // triangles (every point is a vertex of a Delaunay triangulation).
  return 2 * points.size() >= hull_edges + 2 &&
         total == 2 * points.size() - hull_edges - 2;
}

/** Fewest points per slab worth a thread of their own. */
constexpr std::size_t kMinSlabPoints = 2048;

/** triangulateSorted(), on up to \a num_threads slabs at once when the points are many
 * enough (triangulateSortedInSlabs(); by slot, not in canonical order either way). The
 * result does not depend on the number of slabs. */
bool
triangulateSortedOnThreads(const std::vector<QuantizedPoint>& points,
                           std::vector<Triangle>& triangles,
                           std::vector<Triangle>* neighbours,
                           int num_threads)
{
  const auto slabs = static_cast<int>(std::min<std::size_t>(
      static_cast<std::size_t>(std::max(1, std::min(num_threads, 8))),
      points.size() / kMinSlabPoints));
  if (slabs >= 2) {
    std::vector<Triangle> own_neighbours;
    std::vector<Triangle>& adjacency = neighbours ? *neighbours : own_neighbours;
    if (triangulateSortedInSlabs(points, slabs, triangles, adjacency))
      return true;
    triangles.clear();
    adjacency.clear();
  }
  return triangulateSorted(points, triangles, neighbours, num_threads);
}

/** BoostVoronoi's triangles in canonical order, for the inputs the sweep gives up on:
 * the same triangles, in about Boost's time. */
bool
triangulateByBoost(const std::vector<QuantizedPoint>& points,
                   std::vector<Triangle>& triangles,
                   std::vector<Triangle>* neighbours,
                   std::string* error)
{
  if (!detail::delaunayBoostVoronoi(points, triangles, error))
    return false;
  detail::canonicalize(triangles, points.size());
  if (neighbours)
    computeTriangleNeighbours(triangles, points.size(), *neighbours);
  return true;
}

} // namespace

namespace detail {

bool
delaunaySweep(const std::vector<QuantizedPoint>& points,
              std::vector<Triangle>& triangles,
              std::vector<Triangle>* neighbours,
              std::string* error,
              int num_threads)
{
  triangles.clear();
  if (neighbours)
    neighbours->clear();
  if (isStrictlySorted(points)) {
    if (points.size() < 3 || allCollinear(points))
      return true;
    if (!triangulateSortedOnThreads(points, triangles, neighbours, num_threads))
      return triangulateByBoost(points, triangles, neighbours, error);
    canonicalize(triangles, points.size(), neighbours, num_threads);
    return true;
  }
  std::vector<std::uint64_t> keys;
  const std::vector<index_t> order = sortedOrder(points, keys);
  const auto duplicate = std::adjacent_find(keys.begin(), keys.end());
  if (duplicate != keys.end()) {
    reportDuplicate(points, points[order[duplicate - keys.begin()]], error);
    return false;
  }
  std::vector<QuantizedPoint> sorted;
  detail::resizeLarge(sorted, points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    sorted[i] = points[order[i]];
  if (points.size() < 3 || allCollinear(sorted))
    return true;
  if (!triangulateSortedOnThreads(sorted, triangles, neighbours, num_threads))
    return triangulateByBoost(points, triangles, neighbours, error);
  for (auto& t : triangles)
    if (t[0] != kNone)
      for (auto& v : t)
        v = order[v];
  canonicalize(triangles, points.size(), neighbours, num_threads);
  return true;
}

bool
delaunaySweepInSlabs(const std::vector<QuantizedPoint>& points,
                     int num_slabs,
                     std::vector<Triangle>& triangles,
                     std::vector<Triangle>& neighbours)
{
  triangles.clear();
  neighbours.clear();
  if (num_slabs < 1 || !isStrictlySorted(points) ||
      !triangulateSortedInSlabs(points, num_slabs, triangles, neighbours)) {
    triangles.clear();
    neighbours.clear();
    return false;
  }
  canonicalize(triangles, points.size(), &neighbours);
  return true;
}

} // namespace detail

} // namespace selective_seg
} // namespace pcl
