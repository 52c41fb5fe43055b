/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/impl/parallel_exceptions.hpp>
#include <pcl_selective_seg/region_merging.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "incidence_build.h"
#include "mesh_checks.h"

namespace pcl {
namespace selective_seg {

Incidence
Incidence::build(const std::vector<pcl::index_t>& group_of, std::size_t num_groups)
{
  if (!detail::idsBelow(group_of, num_groups, true, "Incidence::build", "group_of"))
    return {std::vector<std::size_t>(num_groups + 1, 0), {}}; // every group empty
  return detail::buildIncidence(group_of.size(), num_groups, [&](std::size_t i, auto f) {
    if (group_of[i] >= 0)
      f(group_of[i]);
  });
}

void
clustersFromLabels(const std::vector<std::uint32_t>& labels,
                   std::size_t num_labels,
                   std::vector<pcl::PointIndices>& clusters,
                   int num_threads)
{
  clusters.resize(num_labels);
  std::vector<std::size_t> offsets;
  detail::placeInBuckets<pcl::index_t>(
      labels.size(),
      num_labels,
      [&](std::size_t i, auto f) {
        if (labels[i] > 0 && labels[i] <= num_labels)
          f(static_cast<pcl::index_t>(labels[i] - 1), static_cast<pcl::index_t>(i));
      },
      detail::threadCount(num_threads),
      offsets,
      [&](const std::vector<std::size_t>& bounds) {
        for (std::size_t l = 0; l < num_labels; ++l)
          clusters[l].indices.resize(bounds[l + 1] - bounds[l]);
      },
      [&](pcl::index_t l, std::size_t slot, pcl::index_t i) {
        clusters[l].indices[slot - offsets[l]] = i;
      });
}

Incidence
vertexTriangles(const std::vector<Triangle>& triangles,
                std::size_t num_vertices,
                int num_threads)
{
  if (!detail::idsBelow(triangles,
                        num_vertices,
                        false,
                        "vertexTriangles",
                        "the triangles",
                        num_threads))
    return {std::vector<std::size_t>(num_vertices + 1, 0), {}}; // every group empty
  return detail::buildIncidence(
      triangles.size(),
      num_vertices,
      [&](std::size_t t, auto f) {
        for (const auto v : triangles[t])
          f(v);
      },
      detail::threadCount(num_threads));
}

namespace {

/** The leaves' count, normals and areas, from whichever form the input gives. */
std::size_t
numLeaves(const MergeInput& in)
{
  return in.leaves ? in.leaves->size() : in.leaf_normals->size();
}

const Eigen::Vector3f&
leafNormal(const MergeInput& in, pcl::index_t l)
{
  return in.leaves ? (*in.leaves)[l].normal : (*in.leaf_normals)[l];
}

double
leafArea(const MergeInput& in, pcl::index_t l)
{
  return in.leaves ? (*in.leaves)[l].area : (*in.leaf_areas)[l];
}

/** A segment while it grows: eq. 7 as a running sum. */
struct GrowingSegment {
  explicit GrowingSegment(SegmentNormalWeight weight)
  : by_area(weight == SegmentNormalWeight::Area)
  {
  }

  bool by_area; ///< weight A_v instead of the paper's 1 / A_v
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();

  void add(const Eigen::Vector3f& leaf_normal, double leaf_area)
  {
    if (leaf_area > 0.0 && std::isfinite(leaf_area)) {
      if (by_area)
        sum += leaf_normal.cast<double>() * leaf_area;
      else
        sum += leaf_normal.cast<double>() / leaf_area;
    }
    renormalize();
  }

  /** Absorb another segment's eq. 7 sum (MergeWith::Segments). */
  void addSum(const Eigen::Vector3d& other)
  {
    sum += other;
    renormalize();
  }

private:
  void renormalize()
  {
    const double norm = sum.norm();
    if (norm > 0.0 && std::isfinite(norm))
      normal = sum / norm;
  }
};

/** The segments grown so far, for MergeWith::Segments: a growing segment may absorb
 * them. A union-find over segment ids: an absorbed segment's leaves keep its id, whose
 * root is the segment that absorbed it. */
struct GrownSegments {
  std::vector<pcl::index_t> parent;     ///< the root of each segment is its own parent
  std::vector<Eigen::Vector3d> sums;    ///< eq. 7 sum of each segment as it grew
  std::vector<Eigen::Vector3d> normals; ///< its normalized sum

  pcl::index_t find(pcl::index_t s)
  {
    while (parent[s] != s) {
      parent[s] = parent[parent[s]]; // path halving
      s = parent[s];
    }
    return s;
  }
};

/** A triangle listed under a leaf, with the leaves of its vertices (-1: none) kept
 * beside it: the growth reads them for every triangle it visits, and a copy next to
 * the triangle id saves it three scattered reads per visit. An edge-on triangle (never
 * a valid edge triangle) is stored as ~t, which saves the read of its flag too. */
struct LeafTriangle {
  std::array<pcl::index_t, 3> leaves;
  pcl::index_t triangle; ///< t, or ~t (negative) for an edge-on triangle
};

/** The triangles at each leaf that can matter to the growth: every triangle whose
 * vertices lie in at least two leaves, listed once under each distinct leaf of its
 * vertices, in increasing triangle order. A triangle within one leaf is never an edge
 * triangle of the segment holding that leaf, so leaving it out changes nothing. */
struct LeafTriangles {
  const MergeInput& in;
  std::vector<std::size_t> offsets; ///< #L + 1: leaf l's entries are [offsets[l], offsets[l + 1])
  detail::BlockArray<LeafTriangle> entries;

  LeafTriangles(const MergeInput& input) : in(input)
  {
    detail::buildBuckets<LeafTriangle>(
        in.triangles->size(),
        numLeaves(in),
        [&](std::size_t t, auto f) {
          const auto leaves = leavesOf(static_cast<pcl::index_t>(t));
          if (spansLeaves(leaves)) {
            const bool edge_on = in.triangle_edge_on && (*in.triangle_edge_on)[t];
            const auto id = static_cast<pcl::index_t>(t);
            const LeafTriangle entry{leaves, edge_on ? ~id : id};
            forEachDistinct(leaves, [&](pcl::index_t l) { f(l, entry); });
          }
        },
        detail::threadCount(in.num_threads),
        offsets,
        entries);
  }

  /** The leaves of a triangle's vertices (-1: none). */
  std::array<pcl::index_t, 3> leavesOf(pcl::index_t t) const
  {
    const Triangle& tri = (*in.triangles)[t];
    const auto& vertex_leaf = *in.vertex_leaf;
    return {vertex_leaf[tri[0]], vertex_leaf[tri[1]], vertex_leaf[tri[2]]};
  }

  /** Whether a triangle's vertices lie in at least two distinct leaves. */
  static bool spansLeaves(const std::array<pcl::index_t, 3>& l)
  {
    const pcl::index_t first = l[0] >= 0 ? l[0] : l[1] >= 0 ? l[1] : l[2];
    return first >= 0 && ((l[1] >= 0 && l[1] != first) || (l[2] >= 0 && l[2] != first));
  }

  /** Call f once for each distinct non-negative leaf of a triangle. */
  template <typename F>
  static void forEachDistinct(const std::array<pcl::index_t, 3>& l, F f)
  {
    if (l[0] >= 0)
      f(l[0]);
    if (l[1] >= 0 && l[1] != l[0])
      f(l[1]);
    if (l[2] >= 0 && l[2] != l[0] && l[2] != l[1])
      f(l[2]);
  }
};

/** Which segment holds each leaf, as the sequential growth sees it. */
struct SharedState {
  std::vector<pcl::index_t>& leaf_segment;
  pcl::index_t k;                 ///< the growing segment
  GrownSegments* grown = nullptr; ///< MergeWith::Segments: the segments grown before

  bool claimed(pcl::index_t l) const { return leaf_segment[l] >= 0; }
  bool own(pcl::index_t l) const
  {
    const pcl::index_t s = leaf_segment[l];
    return s == k || (grown && s >= 0 && grown->find(s) == k);
  }
  /** The grown segment (a root) holding \a l, when it may be absorbed; -1 otherwise. */
  pcl::index_t absorbable(pcl::index_t l) const
  {
    const pcl::index_t s = leaf_segment[l];
    if (!grown || s < 0 || s == k)
      return -1;
    const pcl::index_t root = grown->find(s);
    return root == k ? -1 : root;
  }
  /** A held leaf met (nothing to note here). */
  void metHeld(pcl::index_t) const {}
  /** Whether a leaf is held, as a segment taken over needs (SegmentReplay). */
  bool requireHeld(pcl::index_t l) const { return claimed(l); }
  void claim(pcl::index_t l) { leaf_segment[l] = k; }
};

/** A thread's view while it grows seeds ahead of their turn: the shared state as the
 * last window left it (read only), plus the segments this thread grew in this window
 * (an overlay of window-local ids + 1; 0: none). The leaves the growth finds held by
 * another segment of this window go, once each, to \a held: with the leaves it claimed,
 * all that its outcome depends on besides the input (see SeedMerger::run()). A segment
 * taken over (SegmentReplay) puts there the leaves it needs held that the shared state
 * does not hold. */
struct OverlayState {
  const std::vector<pcl::index_t>& leaf_segment;
  std::vector<std::uint16_t>& overlay;
  std::vector<std::uint8_t>& noted; ///< leaves already in held for this segment
  std::vector<pcl::index_t>& held;
  std::uint16_t k; ///< the growing segment's window-local id + 1

  bool claimed(pcl::index_t l) const { return leaf_segment[l] >= 0 || overlay[l] != 0; }
  bool own(pcl::index_t l) const { return overlay[l] == k; }
  /** Growth ahead of its turn never absorbs (MergeWith::Segments runs in turn). */
  pcl::index_t absorbable(pcl::index_t) const { return -1; }
  /** A held leaf met: noted when another segment of this window holds it (a leaf held
   * in the shared state stays held: nothing to check). */
  void metHeld(pcl::index_t l)
  {
    if (leaf_segment[l] >= 0 || overlay[l] == k || noted[l])
      return;
    noted[l] = 1;
    held.push_back(l);
  }
  /** A leaf a segment taken over needs held (SegmentReplay), before it claims any:
   * noted like a held leaf met, to be checked when the segment is committed. */
  bool requireHeld(pcl::index_t l)
  {
    metHeld(l);
    return true;
  }
  void claim(pcl::index_t l) { overlay[l] = k; }
};

/** The growth of one segment from its seed (eq. 7-10) over a state that says which
 * leaves are claimed and which are this segment's, and hears of the held leaves met. */
class SegmentGrowth {
public:
  SegmentGrowth(const MergeInput& in, const LeafTriangles& adjacency)
      : in_(in)
      , adjacency_(adjacency)
      , cos_merge_(std::cos(in.max_merge_angle))
      , cos_edge_(std::cos(in.max_edge_triangle_angle))
  {
  }

  template <typename State>
  Eigen::Vector3d
  grow(pcl::index_t seed, State& state)
  {
    GrowingSegment segment(in_.segment_normal_weight);
    segment.add(leafNormal(in_, seed), leafArea(in_, seed));
    state.claim(seed);
    queue_.assign(1, seed);
    for (std::size_t head = 0; head < queue_.size(); ++head) {
      const auto leaf = queue_[head];
      const auto end = adjacency_.offsets[leaf + 1];
      for (auto i = adjacency_.offsets[leaf]; i < end; ++i) {
        // The triangles' normals are scattered: ask for one a few entries ahead (a
        // hint; no effect on the values).
        if (i + 8 < end && adjacency_.entries[i + 8].triangle >= 0) {
          const pcl::index_t ahead = adjacency_.entries[i + 8].triangle;
          __builtin_prefetch(&(*in_.triangle_normals)[ahead]);
        }
        visitTriangle(adjacency_.entries[i], segment, state);
      }
    }
    sum_ = segment.sum;
    return segment.normal;
  }

  /** The leaves the last grow() claimed, in the order it claimed them. */
  const std::vector<pcl::index_t>& queue() const { return queue_; }
  /** The eq. 7 sum of the segment the last grow() made. */
  const Eigen::Vector3d& sum() const { return sum_; }

private:
  template <typename State>
  void visitTriangle(const LeafTriangle& entry, GrowingSegment& segment, State& state)
  {
    const auto& leaves = entry.leaves;
    const pcl::index_t t = entry.triangle;
    const bool edge = std::any_of(leaves.begin(), leaves.end(), [&](pcl::index_t l) {
      return l >= 0 && !state.own(l);
    });
    if (!edge || t < 0 || !isValidFor(t, segment.normal))
      return; // interior, or an invalid edge triangle (eq. 8; t < 0: edge-on)
    for (const auto other : leaves) {
      if (other < 0)
        continue;
      if (state.claimed(other)) {
        const pcl::index_t j = state.absorbable(other);
        if (j >= 0)
          absorb(j, segment, state);
        else
          state.metHeld(other);
        continue;
      }
      const Eigen::Vector3f& n_other = leafNormal(in_, other);
      if (n_other.cast<double>().dot(segment.normal) < cos_merge_)
        continue;         // eq. 9
      state.claim(other); // eq. 10
      segment.add(n_other, leafArea(in_, other));
      queue_.push_back(other);
    }
  }

  /** Eq. 9-10 between the growing segment and the grown segment \a j
   * (MergeWith::Segments): when their normals are close enough, \a j's leaves become
   * the growing segment's and its sum joins eq. 7's. They are not searched again: \a j
   * searched them when it grew, and each leaf's triangles are then visited once per
   * growth (linear, however often a segment is absorbed). */
  void absorb(pcl::index_t j, GrowingSegment& segment, SharedState& state)
  {
    GrownSegments& grown = *state.grown;
    if (grown.normals[j].dot(segment.normal) < cos_merge_)
      return;
    grown.parent[j] = state.k;
    segment.addSum(grown.sums[j]);
  }
  template <typename State> void absorb(pcl::index_t, GrowingSegment&, State&) {}

  /** Eq. 8 for a triangle that is not edge-on. */
  bool isValidFor(pcl::index_t t, const Eigen::Vector3d& segment_normal) const
  {
    const Eigen::Vector3f& n_t = (*in_.triangle_normals)[t];
    if (!n_t.allFinite())
      return false;
    return n_t.cast<double>().dot(segment_normal) >= cos_edge_;
  }

  const MergeInput& in_;
  const LeafTriangles& adjacency_;
  std::vector<pcl::index_t> queue_;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  double cos_merge_;
  double cos_edge_;
};

/** Previous segments taken over instead of grown (MergeReplay). */
class SegmentReplay {
public:
  SegmentReplay(const MergeInput& in, const LeafTriangles& adjacency)
      : in_(in)
      , adjacency_(adjacency)
  {
    if (!in.replay || !in.replay->leaf_segment || !in.replay->segment_seed ||
        !in.replay->segment_normals)
      return;
    const MergeReplay& r = *in.replay;
    const std::size_t num_leaves = numLeaves(in);
    const std::size_t num_segments = r.segment_seed->size();
    if (r.leaf_segment->size() != num_leaves ||
        r.segment_normals->size() != num_segments ||
        std::any_of(
            r.leaf_segment->begin(), r.leaf_segment->end(), [&](pcl::index_t s) {
              return s >= 0 && static_cast<std::size_t>(s) >= num_segments;
            }))
      return; // inconsistent: nothing is taken over
    const auto replayable = [&](pcl::index_t s) {
      return s >= 0 && (*r.segment_seed)[s] >= 0;
    };
    // The leaves of each previous segment that may be taken over, in leaf order.
    offsets_.assign(num_segments + 1, 0);
    for (const auto s : *r.leaf_segment)
      if (replayable(s))
        ++offsets_[s + 1];
    for (std::size_t k = 1; k <= num_segments; ++k)
      offsets_[k] += offsets_[k - 1];
    leaves_.resize(offsets_[num_segments]);
    std::vector<std::size_t> next(offsets_.begin(), offsets_.end() - 1);
    for (std::size_t l = 0; l < num_leaves; ++l) {
      const auto s = (*r.leaf_segment)[l];
      if (replayable(s))
        leaves_[next[s]++] = static_cast<pcl::index_t>(l);
    }
    active_ = true;
  }

  bool active() const { return active_; }

  /** Takes over the previous segment grown from \a seed when the state allows it
   * (MergeReplay): claims its leaves, notes the held leaves it depends on, and returns
   * true with its normal and leaves. False, with the state as it was but for held
   * leaves noted, otherwise. */
  template <typename State>
  bool take(pcl::index_t seed,
            State& state,
            Eigen::Vector3d& normal,
            const pcl::index_t*& first,
            const pcl::index_t*& last) const
  {
    const MergeReplay& r = *in_.replay;
    const auto& leaf_segment = *r.leaf_segment;
    const pcl::index_t s = leaf_segment[seed];
    if (s < 0 || (*r.segment_seed)[s] != seed)
      return false;
    first = leaves_.data() + offsets_[s];
    last = leaves_.data() + offsets_[s + 1];
    for (const pcl::index_t* l = first; l != last; ++l)
      if (state.claimed(*l))
        return false;
    for (const pcl::index_t* l = first; l != last; ++l) {
      const auto end = adjacency_.offsets[*l + 1];
      for (auto i = adjacency_.offsets[*l]; i < end; ++i)
        for (const auto other : adjacency_.entries[i].leaves) {
          if (other < 0)
            continue;
          const pcl::index_t o = leaf_segment[other];
          if (o == s || o > s)
            continue; // S's own, or free when S grew: either way not taken
          if (!state.requireHeld(other))
            return false; // held when S grew (or changed): must be held now
        }
    }
    for (const pcl::index_t* l = first; l != last; ++l)
      state.claim(*l);
    normal = (*r.segment_normals)[s].cast<double>();
    return true;
  }

private:
  const MergeInput& in_;
  const LeafTriangles& adjacency_;
  bool active_ = false;
  std::vector<std::size_t> offsets_; ///< #S + 1 into leaves_
  std::vector<pcl::index_t> leaves_;
};

/** One thread's segments grown ahead of their turn in a window of the seed order, from
 * the seeds of its part of the leaves. */
struct Speculation {
  struct Segment {
    pcl::index_t seed;
    std::uint32_t claimed_end; ///< its leaves: claimed[previous end, claimed_end)
    std::uint32_t held_end;    ///< held[previous end, held_end)
    Eigen::Vector3d normal;
    bool replayed; ///< taken over from the previous merge (SegmentReplay)
  };
  std::vector<Segment> segments;
  std::vector<pcl::index_t> claimed;
  std::vector<pcl::index_t> held;
  std::vector<std::uint16_t> overlay; ///< #L, OverlayState::overlay
  std::vector<std::uint8_t> noted;    ///< #L, OverlayState::noted
};

class SeedMerger {
public:
  explicit SeedMerger(const MergeInput& in)
      : in_(in)
      , adjacency_(in)
      , replay_(in, adjacency_)
  {
  }

  /** The seeds in order, each unassigned one growing a segment.
   *
   * On several threads (enough leaves), the order is taken in windows of at most
   * kWindow seeds. In a window, each thread first grows the window's seeds of its part
   * of the leaves (a range of octree order, a region of space), over the state the
   * previous windows left plus its own segments of this window, as if the other parts'
   * seeds of the window did not exist; it notes the leaves each segment claimed and
   * those it found held by its own earlier segments of the window. Then, in seed order,
   * a grown segment is taken as is when its growth met the state the sequential run
   * meets: each leaf it claimed is still free, and each leaf it found held is held. The
   * growth reads nothing else that can differ (which segment holds a leaf never
   * matters, only whether it is this one, and a free leaf that a test turned down is
   * left alone whether free or held), so it makes the same decisions in the same order
   * and ends with the same normal. Otherwise the segment grows again there, over the
   * true state. The result is the sequential run's, bit for bit, for any thread count;
   * the windows bound the memory the threads' notes take.
   *
   * With MergeInput::replay, a previous segment is taken over at its seed's turn, in
   * place of its growth, when the state allows (SegmentReplay); ahead of its turn, the
   * leaves it needs held are checked when it is committed, like a grown segment's. */
  void run(std::vector<pcl::index_t>& leaf_segment, Vector3fVector& segment_normals)
  {
    const std::size_t num_leaves = numLeaves(in_);
    leaf_segment.assign(num_leaves, -1);
    segment_normals.clear();
    num_replayed_ = 0;
    const std::vector<pcl::index_t> order = seedOrder(*in_.vertex_leaf, num_leaves);
    const int threads = detail::threadCount(in_.num_threads);
    const std::size_t parts =
        std::min<std::size_t>(kMaxParts, static_cast<std::size_t>(threads));
    SegmentGrowth growth(in_, adjacency_);
    const auto growHere = [&](pcl::index_t seed) {
      const auto k = static_cast<pcl::index_t>(segment_normals.size());
      SharedState state{leaf_segment, k};
      Eigen::Vector3d normal;
      const pcl::index_t *first = nullptr, *last = nullptr;
      if (replay_.active() && replay_.take(seed, state, normal, first, last))
        ++num_replayed_;
      else
        normal = growth.grow(seed, state);
      segment_normals.push_back(normal.cast<float>());
    };
    if (in_.merge_with == MergeWith::Segments) {
      growAbsorbing(order, growth, leaf_segment, segment_normals);
      return;
    }
    if (parts < 2 || num_leaves < kMinParallelLeaves) {
      for (const auto seed : order)
        if (leaf_segment[seed] < 0)
          growHere(seed);
      return;
    }
    // Part p is the leaves [bounds[p], bounds[p + 1]).
    std::vector<std::size_t> bounds(parts + 1);
    for (std::size_t p = 0; p <= parts; ++p)
      bounds[p] = num_leaves * p / parts;
    std::vector<Speculation> ahead(parts);
    for (auto& a : ahead) {
      a.overlay.assign(num_leaves, 0);
      a.noted.assign(num_leaves, 0);
    }
    std::size_t window = kFirstWindow;
    for (std::size_t w = 0; w < order.size();) {
      const std::size_t w_end = std::min(order.size(), w + window);
      detail::ParallelExceptions errors;
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(parts)) schedule(static, 1)
#endif
      for (std::ptrdiff_t p = 0; p < static_cast<std::ptrdiff_t>(parts); ++p)
        errors.run([&] {
          speculate(order, w, w_end, bounds[p], bounds[p + 1], leaf_segment, ahead[p]);
        });
      errors.rethrow();
      std::vector<std::size_t> next(parts, 0); // each part's next grown segment
      for (std::size_t i = w; i < w_end; ++i) {
        const pcl::index_t seed = order[i];
        const auto above = std::upper_bound(
            bounds.begin(), bounds.end(), static_cast<std::size_t>(seed));
        const auto part = static_cast<std::size_t>(above - bounds.begin() - 1);
        const Speculation& mine = ahead[part];
        const Speculation::Segment* grown = nullptr;
        std::size_t claimed_begin = 0, held_begin = 0;
        if (next[part] < mine.segments.size() &&
            mine.segments[next[part]].seed == seed) {
          if (next[part] > 0) {
            claimed_begin = mine.segments[next[part] - 1].claimed_end;
            held_begin = mine.segments[next[part] - 1].held_end;
          }
          grown = &mine.segments[next[part]++];
        }
        if (leaf_segment[seed] >= 0)
          continue;
        if (grown &&
            stillValid(*grown, claimed_begin, held_begin, mine, leaf_segment)) {
          const auto k = static_cast<pcl::index_t>(segment_normals.size());
          for (std::size_t c = claimed_begin; c < grown->claimed_end; ++c)
            leaf_segment[mine.claimed[c]] = k;
          segment_normals.push_back(grown->normal.cast<float>());
          num_replayed_ += grown->replayed;
          continue;
        }
        growHere(seed);
      }
      for (auto& a : ahead)
        for (const auto l : a.claimed)
          a.overlay[l] = 0;
      w = w_end;
      window = std::min(2 * window, kWindow);
    }
  }

  /** Segments the last run() took over from MergeInput::replay. */
  std::size_t numReplayed() const
  {
    return num_replayed_;
  }

private:
  /** Below this many leaves the growth runs on one thread. */
  static constexpr std::size_t kMinParallelLeaves = 1024;
  /** At most this many parts (threads) grow ahead: each holds 3 bytes per leaf, and
   * more parts meet more often at their borders. */
  static constexpr std::size_t kMaxParts = 8;
  /** Seeds per window (window-local ids fit the overlay's 16 bits). */
  static constexpr std::size_t kWindow = 4096;
  /** The first window; each next one twice as long, up to kWindow. The largest seeds
   * come first and often grow the largest segments: in short windows, these are
   * committed before the threads grow the seeds around them. */
  static constexpr std::size_t kFirstWindow = 8;

  /** MergeWith::Segments: the seeds in order on one thread, each growing segment
   * absorbing the grown ones it meets (SegmentGrowth::absorb()); then the segments
   * left are numbered in the order they were created. */
  static void growAbsorbing(const std::vector<pcl::index_t>& order,
                            SegmentGrowth& growth,
                            std::vector<pcl::index_t>& leaf_segment,
                            Vector3fVector& segment_normals)
  {
    GrownSegments grown;
    for (const auto seed : order) {
      if (leaf_segment[seed] >= 0)
        continue;
      const auto k = static_cast<pcl::index_t>(grown.parent.size());
      grown.parent.push_back(k);
      SharedState state{leaf_segment, k, &grown};
      const Eigen::Vector3d normal = growth.grow(seed, state);
      grown.sums.push_back(growth.sum());
      grown.normals.push_back(normal);
    }
    std::vector<pcl::index_t> number(grown.parent.size(), -1);
    for (std::size_t k = 0; k < grown.parent.size(); ++k)
      if (grown.find(static_cast<pcl::index_t>(k)) == static_cast<pcl::index_t>(k)) {
        number[k] = static_cast<pcl::index_t>(segment_normals.size());
        segment_normals.push_back(grown.normals[k].cast<float>());
      }
    for (auto& s : leaf_segment)
      if (s >= 0)
        s = number[static_cast<std::size_t>(grown.find(s))];
  }

  /** Grow the seeds order[w, w_end) that lie in [first, last), in order. */
  void speculate(const std::vector<pcl::index_t>& order,
                 std::size_t w,
                 std::size_t w_end,
                 std::size_t first,
                 std::size_t last,
                 const std::vector<pcl::index_t>& leaf_segment,
                 Speculation& out) const
  {
    out.segments.clear();
    out.claimed.clear();
    out.held.clear();
    SegmentGrowth growth(in_, adjacency_);
    for (std::size_t i = w; i < w_end; ++i) {
      const pcl::index_t seed = order[i];
      if (static_cast<std::size_t>(seed) < first ||
          static_cast<std::size_t>(seed) >= last || leaf_segment[seed] >= 0 ||
          out.overlay[seed] != 0)
        continue;
      const auto k = static_cast<std::uint16_t>(out.segments.size() + 1);
      OverlayState state{leaf_segment, out.overlay, out.noted, out.held, k};
      const std::size_t held_begin = out.held.size();
      Speculation::Segment s;
      s.seed = seed;
      const pcl::index_t *taken = nullptr, *taken_end = nullptr;
      s.replayed =
          replay_.active() && replay_.take(seed, state, s.normal, taken, taken_end);
      if (!s.replayed) {
        for (std::size_t h = held_begin; h < out.held.size(); ++h)
          out.noted[out.held[h]] = 0;
        out.held.resize(held_begin);
        s.normal = growth.grow(seed, state);
        taken = growth.queue().data();
        taken_end = taken + growth.queue().size();
      }
      for (std::size_t h = held_begin; h < out.held.size(); ++h)
        out.noted[out.held[h]] = 0;
      out.claimed.insert(out.claimed.end(), taken, taken_end);
      s.claimed_end = static_cast<std::uint32_t>(out.claimed.size());
      s.held_end = static_cast<std::uint32_t>(out.held.size());
      out.segments.push_back(s);
    }
  }

  static bool stillValid(const Speculation::Segment& s,
                         std::size_t claimed_begin,
                         std::size_t held_begin,
                         const Speculation& from,
                         const std::vector<pcl::index_t>& leaf_segment)
  {
    for (std::size_t i = claimed_begin; i < s.claimed_end; ++i)
      if (leaf_segment[from.claimed[i]] >= 0)
        return false;
    for (std::size_t i = held_begin; i < s.held_end; ++i)
      if (leaf_segment[from.held[i]] < 0)
        return false;
    return true;
  }

  const MergeInput& in_;
  LeafTriangles adjacency_;
  SegmentReplay replay_;
  std::size_t num_replayed_ = 0;
};

} // namespace

namespace {

/** Whether \a angle lies in [0, pi] (not NaN), the range validate() gives eq. 8-9. */
bool
angleUsable(double angle)
{
  return angle >= 0.0 && angle <= M_PI;
}

/** What mergeSeedSegments() and classifyTriangles() both need of the mesh's
 * per-triangle inputs and eq. 8's angle: nullptr, or what is wrong. */
const char*
triangleInputsBroken(std::size_t num_triangles,
                     std::size_t num_normals,
                     const std::vector<std::uint8_t>* edge_on,
                     double max_edge_triangle_angle)
{
  if (num_normals != num_triangles || (edge_on && edge_on->size() != num_triangles))
    return "triangle_normals (and triangle_edge_on) need one entry per triangle";
  if (!angleUsable(max_edge_triangle_angle))
    return "max_edge_triangle_angle must lie in [0, pi] rad";
  return nullptr;
}

} // namespace

std::vector<pcl::index_t>
seedOrder(const std::vector<pcl::index_t>& vertex_leaf, std::size_t num_leaves)
{
  if (!detail::idsBelow(vertex_leaf, num_leaves, true, "seedOrder", "vertex_leaf"))
    return {};
  std::vector<std::uint32_t> size(num_leaves, 0);
  std::uint32_t largest = 0;
  for (const auto l : vertex_leaf)
    if (l >= 0)
      largest = std::max(largest, ++size[l]);
  // A counting sort by size, largest first; leaves of one size in increasing order (the
  // order of a stable sort of 0, 1, ... by decreasing size).
  std::vector<std::size_t> first(static_cast<std::size_t>(largest) + 2, 0);
  for (const auto n : size)
    ++first[largest - n + 1];
  for (std::size_t k = 1; k < first.size(); ++k)
    first[k] += first[k - 1];
  std::vector<pcl::index_t> order(num_leaves);
  for (std::size_t l = 0; l < num_leaves; ++l)
    order[first[largest - size[l]]++] = static_cast<pcl::index_t>(l);
  return order;
}

void
mergeSeedSegments(const MergeInput& input,
                  std::vector<pcl::index_t>& leaf_segment,
                  Vector3fVector& segment_normals)
{
  const char* missing = [&]() -> const char* {
    if (!input.vertex_leaf || !input.triangles || !input.triangle_normals)
      return "vertex_leaf, triangles and triangle_normals are required";
    if (!input.leaves && (!input.leaf_normals || !input.leaf_areas))
      return "leaves, or leaf_normals and leaf_areas, are required";
    if (!input.leaves && input.leaf_normals->size() != input.leaf_areas->size())
      return "leaf_normals and leaf_areas differ in size";
    if (const char* broken = triangleInputsBroken(input.triangles->size(),
                                                  input.triangle_normals->size(),
                                                  input.triangle_edge_on,
                                                  input.max_edge_triangle_angle))
      return broken;
    if (!angleUsable(input.max_merge_angle))
      return "max_merge_angle must lie in [0, pi] rad";
    if (!detail::idsBelow(*input.triangles,
                          input.vertex_leaf->size(),
                          false,
                          "mergeSeedSegments",
                          "the triangles",
                          input.num_threads) ||
        !detail::idsBelow(*input.vertex_leaf,
                          numLeaves(input),
                          true,
                          "mergeSeedSegments",
                          "vertex_leaf",
                          input.num_threads))
      return "the mesh's ids do not fit its arrays (above)";
    return nullptr;
  }();
  if (missing) {
    PCL_ERROR("[pcl::selective_seg::mergeSeedSegments] %s\n", missing);
    leaf_segment.clear();
    segment_normals.clear();
    return;
  }
  SeedMerger merger(input);
  merger.run(leaf_segment, segment_normals);
  if (input.replay)
    input.replay->num_replayed = merger.numReplayed();
}

void
classifyTriangles(const std::vector<Triangle>& triangles,
                  const Vector3fVector& triangle_normals,
                  const std::vector<std::uint8_t>* triangle_edge_on,
                  const std::vector<std::uint32_t>& vertex_labels,
                  const Vector3fVector& label_normals,
                  double max_edge_triangle_angle,
                  std::vector<std::uint32_t>& labels,
                  std::vector<TriangleClass>& classes,
                  int num_threads)
{
  const char* broken = [&]() -> const char* {
    if (const char* wrong = triangleInputsBroken(triangles.size(),
                                                 triangle_normals.size(),
                                                 triangle_edge_on,
                                                 max_edge_triangle_angle))
      return wrong;
    if (!detail::idsBelow(triangles,
                          vertex_labels.size(),
                          false,
                          "classifyTriangles",
                          "the triangles",
                          num_threads))
      return "the triangles' vertex ids do not fit vertex_labels (above)";
    if (!detail::meshTrusted() && !vertex_labels.empty() &&
        *std::max_element(vertex_labels.begin(), vertex_labels.end()) >
            label_normals.size())
      return "a vertex label has no normal in label_normals (label l at [l - 1])";
    return nullptr;
  }();
  if (broken) {
    PCL_ERROR("[pcl::selective_seg::classifyTriangles] %s\n", broken);
    labels.clear();
    classes.clear();
    return;
  }
  const double cos_edge = std::cos(max_edge_triangle_angle);
  detail::assignLarge(labels, triangles.size(), 0);
  detail::assignLarge(classes, triangles.size(), TriangleClass::InvalidEdge);
  const int threads = detail::threadCount(num_threads);
  const auto num_triangles = static_cast<std::ptrdiff_t>(triangles.size());
  // Each triangle's label and class are its own: the same for any thread count.
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1024)
#endif
  for (std::ptrdiff_t t = 0; t < num_triangles; ++t) {
    const auto& tri = triangles[t];
    const std::uint32_t l0 = vertex_labels[tri[0]];
    if (l0 != 0 && l0 == vertex_labels[tri[1]] && l0 == vertex_labels[tri[2]]) {
      labels[t] = l0;
      classes[t] = TriangleClass::Interior;
      continue;
    }
    const Eigen::Vector3f& n = triangle_normals[t];
    double best = -2.0;
    for (const auto v : tri) {
      const std::uint32_t l = vertex_labels[v];
      if (l == 0)
        continue;
      const double c = n.allFinite() ? n.dot(label_normals[l - 1]) : -1.5;
      if (c > best || (c == best && l < labels[t])) {
        best = c;
        labels[t] = l;
      }
    }
    const bool edge_on = triangle_edge_on && (*triangle_edge_on)[t];
    if (labels[t] != 0 && best >= cos_edge && !edge_on)
      classes[t] = TriangleClass::ValidEdge;
  }
}

} // namespace selective_seg
} // namespace pcl
