/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/region_merging.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include "incidence_build.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace pcl {
namespace selective_seg {

Incidence
Incidence::build(const std::vector<pcl::index_t>& group_of, std::size_t num_groups)
{
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
      num_threads > 0 ? num_threads : static_cast<int>(defaultThreads()),
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
  return detail::buildIncidence(
      triangles.size(),
      num_vertices,
      [&](std::size_t t, auto f) {
        for (const auto v : triangles[t])
          f(v);
      },
      num_threads > 0 ? num_threads : static_cast<int>(defaultThreads()));
}

namespace {

/** A segment while it grows: eq. 7 as a running sum. */
struct GrowingSegment {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();

  void add(const Eigen::Vector3f& leaf_normal, double leaf_area)
  {
    if (leaf_area > 0.0 && std::isfinite(leaf_area))
      sum += leaf_normal.cast<double>() / leaf_area;
    const double norm = sum.norm();
    if (norm > 0.0 && std::isfinite(norm))
      normal = sum / norm;
  }
};

/** Seeds, largest first (number of vertices); ties by leaf index. */
std::vector<pcl::index_t>
seedOrder(const std::vector<pcl::index_t>& vertex_leaf, std::size_t num_leaves)
{
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
        in.leaf_normals->size(),
        [&](std::size_t t, auto f) {
          const auto leaves = leavesOf(static_cast<pcl::index_t>(t));
          if (spansLeaves(leaves)) {
            const bool edge_on = in.triangle_edge_on && (*in.triangle_edge_on)[t];
            const auto id = static_cast<pcl::index_t>(t);
            const LeafTriangle entry{leaves, edge_on ? ~id : id};
            forEachDistinct(leaves, [&](pcl::index_t l) { f(l, entry); });
          }
        },
        in.num_threads > 0 ? in.num_threads : static_cast<int>(defaultThreads()),
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

class SeedMerger {
public:
  explicit SeedMerger(const MergeInput& in)
      : in_(in)
      , adjacency_(in)
      , cos_merge_(std::cos(in.max_merge_angle))
      , cos_edge_(std::cos(in.max_edge_triangle_angle))
  {
  }

  void run(std::vector<pcl::index_t>& leaf_segment, Vector3fVector& segment_normals)
  {
    leaf_segment.assign(in_.leaf_normals->size(), -1);
    segment_normals.clear();
    for (const auto seed : seedOrder(*in_.vertex_leaf, in_.leaf_normals->size())) {
      if (leaf_segment[seed] >= 0)
        continue;
      const auto k = static_cast<pcl::index_t>(segment_normals.size());
      segment_normals.push_back(grow(seed, k, leaf_segment).cast<float>());
    }
  }

private:
  /** Breadth first from the seed; queue_ is reused across segments. */
  Eigen::Vector3d
  grow(pcl::index_t seed, pcl::index_t k, std::vector<pcl::index_t>& leaf_segment)
  {
    GrowingSegment segment;
    segment.add((*in_.leaf_normals)[seed], (*in_.leaf_areas)[seed]);
    leaf_segment[seed] = k;
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
        visitTriangle(adjacency_.entries[i], k, segment, leaf_segment);
      }
    }
    return segment.normal;
  }

  void visitTriangle(const LeafTriangle& entry,
                     pcl::index_t k,
                     GrowingSegment& segment,
                     std::vector<pcl::index_t>& leaf_segment)
  {
    const auto& leaves = entry.leaves;
    const pcl::index_t t = entry.triangle;
    const bool edge = std::any_of(leaves.begin(), leaves.end(), [&](pcl::index_t l) {
      return l >= 0 && leaf_segment[l] != k;
    });
    if (!edge || t < 0 || !isValidFor(t, segment.normal))
      return; // interior, or an invalid edge triangle (eq. 8; t < 0: edge-on)
    for (const auto other : leaves) {
      if (other < 0 || leaf_segment[other] >= 0)
        continue;
      const Eigen::Vector3f& n_other = (*in_.leaf_normals)[other];
      if (n_other.cast<double>().dot(segment.normal) < cos_merge_)
        continue;              // eq. 9
      leaf_segment[other] = k; // eq. 10
      segment.add(n_other, (*in_.leaf_areas)[other]);
      queue_.push_back(other);
    }
  }

  /** Eq. 8 for a triangle that is not edge-on. */
  bool isValidFor(pcl::index_t t, const Eigen::Vector3d& segment_normal) const
  {
    const Eigen::Vector3f& n_t = (*in_.triangle_normals)[t];
    if (!n_t.allFinite())
      return false;
    return n_t.cast<double>().dot(segment_normal) >= cos_edge_;
  }

  const MergeInput& in_;
  LeafTriangles adjacency_;
  std::vector<pcl::index_t> queue_;
  double cos_merge_;
  double cos_edge_;
};

} // namespace

void
mergeSeedSegments(const MergeInput& input,
                  std::vector<pcl::index_t>& leaf_segment,
                  Vector3fVector& segment_normals)
{
  SeedMerger(input).run(leaf_segment, segment_normals);
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
  const double cos_edge = std::cos(max_edge_triangle_angle);
  labels.assign(triangles.size(), 0);
  classes.assign(triangles.size(), TriangleClass::InvalidEdge);
  const int threads = num_threads > 0 ? num_threads : static_cast<int>(defaultThreads());
  const auto num_triangles = static_cast<std::ptrdiff_t>(triangles.size());
  // Each triangle's label and class are its own: the same for any thread count.
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static)
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
