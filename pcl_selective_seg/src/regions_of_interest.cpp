/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/impl/parallel_exceptions.hpp>
#include <pcl_selective_seg/regions_of_interest.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <new>
#include <numeric>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "int64_triple_hash.h"
#include "parameter_checks.h"

namespace pcl {
namespace selective_seg {

namespace {

constexpr double kHalfPi = 0.5 * M_PI;
/** Windows stay this far inside (-pi/2, pi/2), where eq. 1 has an image. */
constexpr double kEdgeGuard = 1e-6;
/** Margins that overlap a window by less than this merely touch it [rad]. */
constexpr double kTouch = 1e-9;
/** Passes over fewer items than this run on the calling thread (a team costs more). */
constexpr std::ptrdiff_t kParallelFrom = 16384;

/** The smallest i in [0, n) with bad(i), or n: on \a threads threads, the same
 * answer as a sequential search. bad(i) is called for every i when none is bad. */
template <typename Bad>
std::size_t
firstWhere(std::size_t n, int threads, Bad bad)
{
  std::size_t first = n;
  const auto count = static_cast<std::ptrdiff_t>(n);
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static)                         \
    reduction(min                                                                      \
              : first) if (count >= kParallelFrom)
#endif
  for (std::ptrdiff_t i = 0; i < count; ++i)
    if (static_cast<std::size_t>(i) < first && bad(static_cast<std::size_t>(i)))
      first = static_cast<std::size_t>(i);
  (void)threads;
  return first;
}

/** The vertices' angles of eq. 1 [rad]: the quantized angles times the quantum, made
 * when read. The same doubles as an array of them held (16 bytes a vertex, 16 MB at 1M
 * points) from the triangulation's 8 bytes a vertex. */
class VertexAngles {
public:
  VertexAngles(const SphericalTriangulation& tri, double quantum)
      : quantized_(tri.vertex_angles)
      , quantum_(quantum)
  {
  }
  Eigen::Vector2d operator[](std::size_t v) const
  {
    return Eigen::Vector2d(quantized_[v][0], quantized_[v][1]) * quantum_;
  }
  std::size_t size() const { return quantized_.size(); }

private:
  const std::vector<QuantizedPoint>& quantized_;
  double quantum_;
};

/** The step from b to a in (theta, phi) [rad]; with the panoramic projection theta's
 * difference is taken the short way round the seam, into (-pi, pi]. */
Eigen::Vector2d
angleStep(const Eigen::Vector2d& a,
          const Eigen::Vector2d& b,
          const SphericalTriangulation& tri)
{
  Eigen::Vector2d d = a - b;
  if (tri.projection == ViewProjection::Panoramic) {
    if (d.x() > M_PI)
      d.x() -= 2.0 * M_PI;
    else if (d.x() <= -M_PI)
      d.x() += 2.0 * M_PI;
  }
  return d;
}
/** Smallest max_window_size: a nanoradian, far below any scan's angular resolution
 * (the finest angle quantization is 2.5e-8 rad). */
constexpr double kMinWindowSize = 1e-9;
/** 2^63: point counts from here up are given as the largest size_t. */
constexpr double kMaxCount = 9223372036854775808.0;

bool
reject(std::string* why, const char* name, double value, const char* range)
{
  return detail::rejectParameter(why, name, value, range);
}

bool
finiteAtLeast(double value, double lo)
{
  return std::isfinite(value) && value >= lo;
}

/** Union-find over at most 2^32 - 1 items (vertices), with path halving; the root is
 * the smallest member. */
class DisjointSets {
public:
  explicit DisjointSets(std::size_t n)
      : parent_(n)
  {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }
  std::uint32_t find(std::uint32_t x)
  {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b)
  {
    a = find(a);
    b = find(b);
    if (a != b)
      parent_[std::max(a, b)] = std::min(a, b);
  }

private:
  std::vector<std::uint32_t> parent_;
};

/** A window under construction. */
struct Window {
  double theta_min, theta_max, phi_min, phi_max;
  std::uint8_t reasons = 0;
  std::vector<pcl::index_t> evidence; ///< vertex ids
  /** Evidence outside the window whose margin reaches into it (a part cut beside a
   * window taken before it): it sizes the window, but is not its evidence. */
  std::vector<pcl::index_t> reach;
  double width() const { return theta_max - theta_min; }
  double height() const { return phi_max - phi_min; }
  double area() const { return width() * height(); }
  /** A window holding nothing yet: the first include() sets its bounds. */
  static Window none()
  {
    Window w;
    w.theta_min = w.phi_min = std::numeric_limits<double>::infinity();
    w.theta_max = w.phi_max = -std::numeric_limits<double>::infinity();
    return w;
  }
  /** Grows the bounds to hold the angles \a a. */
  void include(const Eigen::Vector2d& a)
  {
    theta_min = std::min(theta_min, a.x());
    theta_max = std::max(theta_max, a.x());
    phi_min = std::min(phi_min, a.y());
    phi_max = std::max(phi_max, a.y());
  }
};

double
overlapArea(const Window& a, const Window& b)
{
  const double w =
      std::min(a.theta_max, b.theta_max) - std::max(a.theta_min, b.theta_min);
  const double h = std::min(a.phi_max, b.phi_max) - std::max(a.phi_min, b.phi_min);
  return w > 0.0 && h > 0.0 ? w * h : 0.0;
}

/** Whether two windows overlap or share a stretch of their borders. */
bool
meet(const Window& a, const Window& b)
{
  const double w =
      std::min(a.theta_max, b.theta_max) - std::max(a.theta_min, b.theta_min);
  const double h = std::min(a.phi_max, b.phi_max) - std::max(a.phi_min, b.phi_min);
  return w >= 0.0 && h >= 0.0 && (w > 0.0 || h > 0.0);
}

Window
boundingWindow(const Window& a, const Window& b)
{
  Window u;
  u.theta_min = std::min(a.theta_min, b.theta_min);
  u.theta_max = std::max(a.theta_max, b.theta_max);
  u.phi_min = std::min(a.phi_min, b.phi_min);
  u.phi_max = std::max(a.phi_max, b.phi_max);
  return u;
}

double
median(std::vector<double> v)
{
  if (v.empty())
    return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/** The spacing that half the view's area is sampled at or below: the median of the
 * spacings, each weighted by the area its vertex stands for (spacing^2). */
double
areaMedian(std::vector<double> v)
{
  if (v.empty())
    return 0.0;
  std::sort(v.begin(), v.end());
  double total = 0.0;
  for (const double s : v)
    total += s * s;
  double sum = 0.0;
  for (const double s : v) {
    sum += s * s;
    if (sum >= 0.5 * total)
      return s;
  }
  return v.back();
}

/** Median angular length of the mesh edges at each vertex [rad] (0 when isolated). */
std::vector<double>
vertexSpacing(const SphericalTriangulation& tri,
              const VertexAngles& angles,
              int threads)
{
  const std::size_t nv = angles.size();
  // The triangles at each vertex (4-byte ids: a list of every edge length at every
  // vertex took three times the memory, and most of the time went into faulting it in).
  std::vector<std::uint32_t> start(nv + 1, 0);
  for (const auto& t : tri.triangles)
    for (const auto v : t)
      ++start[static_cast<std::size_t>(v) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> at(start.back());
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t t = 0; t < tri.triangles.size(); ++t)
      for (const auto v : tri.triangles[t])
        at[fill[static_cast<std::size_t>(v)]++] = static_cast<std::uint32_t>(t);
  }
  // The median of the lengths of the two edges at the vertex of each of its triangles
  // (at each corner that is the vertex: a triangle listed twice in a row has it twice).
  std::vector<double> spacing(nv, 0.0);
  const auto length = [&](pcl::index_t a, pcl::index_t b) {
    return angleStep(angles[static_cast<std::size_t>(a)],
                     angles[static_cast<std::size_t>(b)],
                     tri)
        .norm();
  };
  const auto count = static_cast<std::ptrdiff_t>(nv);
  std::vector<double> lengths; // empty: each thread's copy allocates nothing
  detail::ParallelExceptions errors;
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static)                         \
    firstprivate(lengths) if (count >= kParallelFrom)
#endif
  for (std::ptrdiff_t iv = 0; iv < count; ++iv)
    errors.run([&] {
      const auto v = static_cast<std::size_t>(iv);
      lengths.clear();
      for (std::uint32_t i = start[v]; i < start[v + 1]; ++i) {
        if (i > start[v] && at[i] == at[i - 1])
          continue;
        const auto& t = tri.triangles[at[i]];
        for (int k = 0; k < 3; ++k)
          if (static_cast<std::size_t>(t[k]) == v) {
            lengths.push_back(length(t[k], t[(k + 1) % 3]));
            lengths.push_back(length(t[(k + 2) % 3], t[k]));
          }
      }
      if (lengths.empty())
        return;
      const auto mid =
          lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
      std::nth_element(lengths.begin(), mid, lengths.end());
      spacing[v] = *mid;
    });
  errors.rethrow();
  return spacing;
}

/** Integer key of the finest-size octree cell holding a sensor-frame position. */
using CellKey = std::array<std::int64_t, 3>;

CellKey
cellKey(const Eigen::Vector3d& position, const Eigen::Vector3d& origin, double size)
{
  // Saturated beyond +-2^63 cells (an extent past float's range over a fine voxel),
  // where converting to an integer would be undefined: such cells share a key.
  const auto cell = [](double c) {
    constexpr double kLimit = 9.2e18; // below 2^63
    const double r = std::floor(c + 0.5);
    if (!(r > -kLimit))
      return std::numeric_limits<std::int64_t>::min();
    if (!(r < kLimit))
      return std::numeric_limits<std::int64_t>::max();
    return static_cast<std::int64_t>(r);
  };
  const Eigen::Vector3d c = (position - origin) / size;
  return {cell(c.x()), cell(c.y()), cell(c.z())};
}

/** Vertices inside finest-size leaves whose normals spread above the threshold. */
void
markLeafEvidence(const SegmentationResult& result,
                 const SphericalTriangulation& tri,
                 const Eigen::Affine3d& cloud_to_sensor,
                 double sigma_threshold,
                 int threads,
                 std::vector<std::uint8_t>& kinds)
{
  if (!(sigma_threshold > 0.0) || result.leaves.empty())
    return;
  float finest = std::numeric_limits<float>::infinity();
  // Leaves with a non-finite centre or size (not the segmenter's) are passed over.
  const auto usable = [](const OctreeLeaf& leaf) {
    return leaf.size > 0.0f && std::isfinite(leaf.size) && leaf.centre.allFinite();
  };
  for (const auto& leaf : result.leaves)
    if (usable(leaf))
      finest = std::min(finest, leaf.size);
  if (!std::isfinite(finest))
    return;
  const double size = finest;
  bool have_origin = false;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<CellKey> cells;
  for (const auto& leaf : result.leaves) {
    if (!usable(leaf) || !(leaf.size <= finest * (1.0f + 1e-4f)) ||
        !(std::max(leaf.sigma_theta, leaf.sigma_phi) > sigma_threshold))
      continue;
    const Eigen::Vector3d centre = cloud_to_sensor * leaf.centre.cast<double>();
    if (!have_origin) {
      origin = centre;
      have_origin = true;
    }
    cells.push_back(cellKey(centre, origin, size));
  }
  if (cells.empty())
    return;
  std::sort(cells.begin(), cells.end());
  const auto count = static_cast<std::ptrdiff_t>(tri.vertex_positions.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads)                                          \
    schedule(static) if (count >= kParallelFrom)
#endif
  for (std::ptrdiff_t iv = 0; iv < count; ++iv) {
    const auto v = static_cast<std::size_t>(iv);
    if (tri.vertex_positions[v].allFinite() &&
        std::binary_search(
            cells.begin(),
            cells.end(),
            cellKey(tri.vertex_positions[v].cast<double>(), origin, size)))
      kinds[v] |= kTransition;
  }
  (void)threads;
}

/** Corners of triangle \a t in the sensor frame. */
std::array<Eigen::Vector3d, 3>
sensorCorners(const SphericalTriangulation& tri, std::size_t t)
{
  const auto& corners = tri.triangles[t];
  return {tri.vertex_positions[corners[0]].cast<double>(),
          tri.vertex_positions[corners[1]].cast<double>(),
          tri.vertex_positions[corners[2]].cast<double>()};
}

/** Unnormalized normal of triangle \a t (counter-clockwise in (theta, phi)) from its
 * sensor-frame corners \a x. */
Eigen::Vector3d
crossNormal(const std::array<Eigen::Vector3d, 3>& x)
{
  return (x[1] - x[0]).cross(x[2] - x[0]);
}

/** Whether triangle \a t is seen edge-on: more than edge_on_angle between its normal
 * and the line of sight to its centroid (the sensor is at the origin of the sensor
 * frame); a degenerate triangle counts as edge-on when \a degenerate is true. */
bool
edgeOn(const SphericalTriangulation& tri,
       std::size_t t,
       const RegionOfInterestParameters& p,
       bool degenerate = true)
{
  const auto x = sensorCorners(tri, t);
  const Eigen::Vector3d normal = crossNormal(x);
  const Eigen::Vector3d ray = x[0] + x[1] + x[2];
  const double n = normal.norm() * ray.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    return degenerate;
  return std::abs(normal.dot(ray)) < std::cos(p.edge_on_angle) * n;
}

/** Per segment, the cone of confidence of its mean normal at side_confidence
 * (fisherConfidenceAngle()) over the unit normals of its interior triangles (all
 * three corners in it), from the triangulation's sensor-frame positions, each turned
 * toward the sensor; empty when side_confidence is off. */
std::vector<double>
sideCones(const SegmentationResult& result,
          const SphericalTriangulation& tri,
          const RegionOfInterestParameters& p)
{
  if (!(p.min_side_angle > 0.0 && p.side_confidence > 0.0))
    return {};
  const std::size_t ns = result.segments.size();
  std::vector<Eigen::Vector3d> sum(ns, Eigen::Vector3d::Zero());
  std::vector<std::size_t> count(ns, 0);
  for (std::size_t t = 0; t < tri.triangles.size(); ++t) {
    const auto& corners = tri.triangles[t];
    const std::uint32_t label = result.labels[tri.vertex_point[corners[0]]];
    if (label == 0 || label > ns ||
        result.labels[tri.vertex_point[corners[1]]] != label ||
        result.labels[tri.vertex_point[corners[2]]] != label)
      continue;
    const auto x = sensorCorners(tri, t);
    Eigen::Vector3d n = crossNormal(x);
    const double length = n.norm();
    if (!(length > 0.0) || !std::isfinite(length))
      continue;
    n /= length;
    sum[label - 1] += n.dot(x[0]) > 0.0 ? -n : n; // toward the sensor at the origin
    ++count[label - 1];
  }
  std::vector<double> cones(ns);
  for (std::size_t i = 0; i < ns; ++i)
    cones[i] = fisherConfidenceAngle(count[i], sum[i].norm(), p.side_confidence);
  return cones;
}

/** Whether edge triangle \a t separates two surfaces (min_side_angle): seen edge-on,
 * a corner without a segment, or segments of at least min_side_points points whose
 * normals differ by more than min_side_angle (plus their cones of confidence, \a
 * cones, when side_confidence is on). */
bool
twoSurfaces(const SegmentationResult& result,
            const SphericalTriangulation& tri,
            std::size_t t,
            const RegionOfInterestParameters& p,
            const std::vector<double>& cones)
{
  if (!(p.min_side_angle > 0.0) || edgeOn(tri, t, p))
    return true;
  const auto& corners = tri.triangles[t];
  const double cos_side = std::cos(p.min_side_angle);
  std::uint32_t labels[3];
  for (int k = 0; k < 3; ++k) {
    labels[k] = result.labels[tri.vertex_point[corners[k]]];
    if (labels[k] == 0 || labels[k] > result.segments.size())
      return true;
  }
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      if (labels[i] == labels[j])
        continue;
      const Segment& si = result.segments[labels[i] - 1];
      const Segment& sj = result.segments[labels[j] - 1];
      if (si.num_points < p.min_side_points || sj.num_points < p.min_side_points)
        continue;
      const double cos_ij = static_cast<double>(si.normal.dot(sj.normal));
      if (cones.empty()) {
        if (cos_ij < cos_side)
          return true;
        continue;
      }
      const double ci = cones[labels[i] - 1], cj = cones[labels[j] - 1];
      if (std::acos(std::clamp(cos_ij, -1.0, 1.0)) - std::sqrt(ci * ci + cj * cj) >
          p.min_side_angle)
        return true;
    }
  return false;
}

/** Evidence bits of every vertex. */
std::vector<std::uint8_t>
findEvidence(const SegmentationResult& result,
             const SphericalTriangulation& tri,
             const Eigen::Affine3d& cloud_to_sensor,
             const VertexAngles& angles,
             const std::vector<double>& spacing,
             const RegionOfInterestParameters& p,
             int threads,
             std::vector<double>& transition_strength)
{
  const std::size_t nv = tri.vertex_point.size();
  std::vector<std::uint8_t> kinds(nv, 0);
  // The strength of transition evidence: invalid edges, then leaves, then valid edges.
  transition_strength.assign(nv, 0.0);
  const auto mark = [&](std::size_t v, double weight) {
    kinds[v] |= kTransition;
    transition_strength[v] = std::max(transition_strength[v], weight);
  };
  const std::vector<double> cones = sideCones(result, tri, p);
  // What each triangle is evidence of (on the threads), then the marks (a maximum and
  // bits: in any order the same).
  enum : std::uint8_t { kNone, kTransitionTriangle, kValidEdgeTriangle };
  std::vector<std::uint8_t> evidence(tri.triangles.size(), kNone);
  const auto nt = static_cast<std::ptrdiff_t>(tri.triangles.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads)                                          \
    schedule(dynamic, 4096) if (nt >= kParallelFrom)
#endif
  for (std::ptrdiff_t it = 0; it < nt; ++it) {
    const auto t = static_cast<std::size_t>(it);
    const auto c = result.mesh.classes[t];
    if ((c == TriangleClass::InvalidEdge || c == TriangleClass::ValidEdge) &&
        !twoSurfaces(result, tri, t, p, cones))
      continue;
    if ((p.use_invalid_edges && c == TriangleClass::InvalidEdge) ||
        (p.use_edge_on && edgeOn(tri, t, p, false)))
      evidence[t] = kTransitionTriangle;
    else if (p.use_valid_edges && c == TriangleClass::ValidEdge)
      evidence[t] = kValidEdgeTriangle;
  }
  for (std::size_t t = 0; t < tri.triangles.size(); ++t)
    if (evidence[t] != kNone)
      for (const auto v : tri.triangles[t])
        mark(static_cast<std::size_t>(v),
             evidence[t] == kTransitionTriangle ? p.transition_weight
                                                : p.valid_edge_weight);
  std::vector<std::uint8_t> leaf(nv, 0);
  markLeafEvidence(result, tri, cloud_to_sensor, p.leaf_sigma_threshold, threads, leaf);
  for (std::size_t v = 0; v < nv; ++v)
    if (leaf[v])
      mark(v, p.leaf_weight);
  if (p.small_segment_points > 0)
    for (std::size_t v = 0; v < nv; ++v) {
      const std::uint32_t label = result.labels[tri.vertex_point[v]];
      if (label > 0 && label <= result.segments.size() &&
          result.segments[label - 1].num_points < p.small_segment_points)
        kinds[v] |= kSmallSegment;
    }
  if (p.sparse_factor > 0.0) {
    std::vector<double> positive;
    for (const double s : spacing)
      if (s > 0.0)
        positive.push_back(s);
    const double typical = p.sparse_by_area ? areaMedian(positive) : median(positive);
    // An invalid edge triangle among sparse samples says "too coarse" rather than
    // "an edge" (holes are spanned by such triangles): such vertices are sparse only.
    for (std::size_t v = 0; v < nv; ++v)
      if (typical > 0.0 && spacing[v] > p.sparse_factor * typical)
        kinds[v] = kSparse;
  }
  // The mesh's outer boundary is the edge of the view, not a transition: its long,
  // thin hull triangles look like invalid edges and sparse samples. The end points of
  // a boundary edge longer than twice their own spacing are no evidence.
  for (std::size_t t = 0; t < tri.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      if (result.mesh.neighbours[t][k] >= 0)
        continue;
      const auto a = tri.triangles[t][(k + 1) % 3];
      const auto b = tri.triangles[t][(k + 2) % 3];
      if (angleStep(angles[a], angles[b], tri).norm() >
          2.0 * std::max(spacing[a], spacing[b]))
        kinds[a] = kinds[b] = 0;
    }
  // With a fixed target step, evidence already sampled about that finely is spent:
  // windows grow around coarse evidence only.
  if (p.target_step > 0.0)
    for (std::size_t v = 0; v < nv; ++v)
      if (kinds[v] && spacing[v] < p.min_refinement * p.target_step)
        kinds[v] = 0;
  return kinds;
}

/** The angles windows may span: a panorama's azimuth ends at +-pi (the seam), eq. 1's
 * short of +-pi/2. */
Window
viewLimits(const SphericalTriangulation& tri)
{
  const double theta_limit =
      tri.projection == ViewProjection::Panoramic ? M_PI : kHalfPi - kEdgeGuard;
  Window limits;
  limits.theta_min = -theta_limit;
  limits.theta_max = theta_limit;
  limits.phi_min = -kHalfPi + kEdgeGuard;
  limits.phi_max = kHalfPi - kEdgeGuard;
  return limits;
}

/** Grows window \a w (its evidence's extent) by \a margin on every side, and to
 * min_window_size about its centre, within \a limits. */
void
growWithin(Window& w,
           double margin,
           const RegionOfInterestParameters& p,
           const Window& limits)
{
  // One axis: the margin, clipped to the limits; then, if that is narrower than
  // min_window_size, widened about its centre and moved inside the limits where they
  // leave room.
  const auto grow = [&](double& lo, double& hi, double limit_lo, double limit_hi) {
    lo = std::max(lo - margin, limit_lo);
    hi = std::min(hi + margin, limit_hi);
    const double missing = p.min_window_size - (hi - lo);
    if (!(missing > 0.0))
      return;
    lo -= 0.5 * missing;
    hi += 0.5 * missing;
    if (lo < limit_lo) {
      hi = std::min(hi + (limit_lo - lo), limit_hi);
      lo = limit_lo;
    }
    if (hi > limit_hi) {
      lo = std::max(lo - (hi - limit_hi), limit_lo);
      hi = limit_hi;
    }
  };
  grow(w.theta_min, w.theta_max, limits.theta_min, limits.theta_max);
  grow(w.phi_min, w.phi_max, limits.phi_min, limits.phi_max);
}

/** One window per (kind, mesh-connected component, tile of max_window_size).
 * \a kept receives, per vertex, the kinds of its evidence that are in a component of
 * at least min_component_vertices (the rest is ignored as noise). */
std::vector<Window>
makeTileWindows(const SphericalTriangulation& tri,
                const VertexAngles& angles,
                const std::vector<std::uint8_t>& kinds,
                const std::vector<double>& spacing,
                const RegionOfInterestParameters& p,
                std::vector<std::uint8_t>& kept)
{
  const std::size_t nv = angles.size();
  kept.assign(nv, 0);
  // Windows by kind, then by (component, tile theta, tile phi): each group of
  // evidence vertices is a window, its vertices in increasing order.
  struct Group {
    std::array<std::int64_t, 3> key; ///< component root, tile theta, tile phi
    Window window;
    std::vector<double> spacing;
  };
  std::vector<Window> windows;
  std::vector<Group> groups;
  const detail::Int64TripleHash hash;
  std::unordered_map<std::array<std::int64_t, 3>, std::size_t, detail::Int64TripleHash>
      group_of;
  constexpr std::uint32_t kNoGroup = std::numeric_limits<std::uint32_t>::max();
  struct CachedGroup {
    std::array<std::int64_t, 3> key{};
    std::uint32_t group = kNoGroup;
  };
  std::vector<CachedGroup> cache(std::size_t{1} << 12); // a power of two
  // Each kind's evidence vertices, numbered compactly in increasing vertex order (so a
  // set's root, its smallest member, is its smallest vertex).
  std::vector<std::int32_t> slot(nv, -1);
  std::vector<pcl::index_t> members;
  const Window view = viewLimits(tri);
  for (const std::uint8_t kind : {kTransition, kSmallSegment, kSparse}) {
    members.clear();
    for (std::size_t v = 0; v < nv; ++v)
      if (kinds[v] & kind) {
        slot[v] = static_cast<std::int32_t>(members.size());
        members.push_back(static_cast<pcl::index_t>(v));
      }
    if (members.empty())
      continue;
    DisjointSets sets(members.size());
    for (const auto& t : tri.triangles)
      for (int k = 0; k < 3; ++k) {
        const auto a = slot[static_cast<std::size_t>(t[k])];
        const auto b = slot[static_cast<std::size_t>(t[(k + 1) % 3])];
        if (a >= 0 && b >= 0)
          sets.unite(static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b));
      }
    // Tiles start at the component's smallest angles: a component that fits in one
    // tile gives one window. Its smallest theta is its root's, the smallest vertex
    // (vertices are numbered in theta order: checked by the caller).
    const std::size_t m = members.size();
    std::vector<std::uint32_t> root(m), size(m, 0);
    std::vector<double> start_phi(m, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < m; ++i) {
      root[i] = sets.find(static_cast<std::uint32_t>(i));
      ++size[root[i]];
      start_phi[root[i]] = std::min(start_phi[root[i]],
                                    angles[static_cast<std::size_t>(members[i])].y());
    }
    // Each kept member's group, then the groups filled at their final sizes (their
    // lists grown one vertex at a time spent most of this in reallocations). Groups
    // are few (thousands), but consecutive members mostly lie in different ones (they
    // differ in phi): a direct-mapped cache of the keys seen is tried before the map.
    groups.clear();
    group_of.clear();
    std::vector<std::uint32_t> group(m, kNoGroup);
    std::vector<std::size_t> count;
    std::fill(cache.begin(), cache.end(), CachedGroup{});
    for (std::size_t i = 0; i < m; ++i) {
      const auto v = static_cast<std::size_t>(members[i]);
      slot[v] = -1; // ready for the next kind
      if (size[root[i]] < p.min_component_vertices)
        continue;
      kept[v] |= kind;
      // At most pi / 1e-9 (validate()): the tile numbers fit an integer.
      const Eigen::Vector2d start(
          angles[static_cast<std::size_t>(members[root[i]])].x(), start_phi[root[i]]);
      const Eigen::Vector2d tile = (angles[v] - start) / p.max_window_size;
      const std::array<std::int64_t, 3> key = {
          static_cast<std::int64_t>(members[root[i]]),
          static_cast<std::int64_t>(std::floor(tile.x())),
          static_cast<std::int64_t>(std::floor(tile.y()))};
      CachedGroup& cached = cache[hash(key) & (cache.size() - 1)];
      if (cached.group == kNoGroup || cached.key != key) {
        const auto [it, fresh] = group_of.try_emplace(key, groups.size());
        if (fresh) {
          groups.push_back({key, Window::none(), {}});
          groups.back().window.reasons = kind;
          count.push_back(0);
        }
        cached = {key, static_cast<std::uint32_t>(it->second)};
      }
      group[i] = cached.group;
      ++count[cached.group];
      groups[cached.group].window.include(angles[v]);
    }
    for (std::size_t g = 0; g < groups.size(); ++g) {
      groups[g].window.evidence.reserve(count[g]);
      groups[g].spacing.reserve(count[g]);
    }
    for (std::size_t i = 0; i < m; ++i)
      if (group[i] != kNoGroup) {
        Group& g = groups[group[i]];
        g.window.evidence.push_back(members[i]);
        g.spacing.push_back(spacing[static_cast<std::size_t>(members[i])]);
      }
    std::sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) {
      return a.key < b.key;
    });
    for (auto& g : groups) {
      Window& w = g.window;
      growWithin(
          w, p.margin + p.margin_spacings * median(std::move(g.spacing)), p, view);
      if (w.width() > 0.0 && w.height() > 0.0)
        windows.push_back(std::move(w));
    }
  }
  return windows;
}

bool
windowLess(const Window& a, const Window& b)
{
  return std::tie(a.theta_min, a.phi_min, a.theta_max, a.phi_max) <
         std::tie(b.theta_min, b.phi_min, b.theta_max, b.phi_max);
}

/** Whether b merges into a: they meet, their bounding window fits the tile size and
 * wastes little area. */
bool
mergeable(const Window& a, const Window& b, const RegionOfInterestParameters& p)
{
  if (!meet(a, b))
    return false;
  const Window u = boundingWindow(a, b);
  return u.width() <= std::max({p.max_window_size, a.width(), b.width()}) &&
         u.height() <= std::max({p.max_window_size, a.height(), b.height()}) &&
         u.area() <= p.merge_area_ratio * (a.area() + b.area() - overlapArea(a, b));
}

/** Merge overlapping windows while the bounding window wastes little area. A sweep in
 * theta: window i is compared only with the later windows whose theta range starts
 * inside its own; passes repeat until nothing merges. */
void
mergeWindows(std::vector<Window>& windows, const RegionOfInterestParameters& p)
{
  bool changed = true;
  while (changed) {
    changed = false;
    std::sort(windows.begin(), windows.end(), windowLess);
    std::vector<char> alive(windows.size(), 1);
    for (std::size_t i = 0; i < windows.size(); ++i) {
      if (!alive[i])
        continue;
      for (bool grew = true; grew;) {
        grew = false;
        for (std::size_t j = i + 1;
             j < windows.size() && windows[j].theta_min <= windows[i].theta_max;
             ++j) {
          if (!alive[j] || !mergeable(windows[i], windows[j], p))
            continue;
          Window& a = windows[i];
          Window& b = windows[j];
          Window u = boundingWindow(a, b);
          u.reasons = a.reasons | b.reasons;
          u.evidence = std::move(a.evidence);
          u.evidence.insert(u.evidence.end(), b.evidence.begin(), b.evidence.end());
          b.evidence.clear();
          a = std::move(u);
          alive[j] = 0;
          changed = grew = true;
        }
      }
    }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < windows.size(); ++i)
      if (alive[i]) {
        if (kept != i)
          windows[kept] = std::move(windows[i]);
        ++kept;
      }
    windows.resize(kept);
  }
}

/** The vertices bucketed by their angles on a uniform grid of about four vertices a
 * cell, so that the vertices inside a window are found among the cells it overlaps
 * rather than in its whole band of theta. Each cell also holds its vertex count and
 * the bounds of its vertices' positions, for the cells wholly inside a window. */
class VertexGrid {
public:
  /** Bounds of the finite positions of a cell's vertices (none: min > max). */
  struct Summary {
    Eigen::Vector3f min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f max =
        Eigen::Vector3f::Constant(std::numeric_limits<float>::lowest());
  };

  /** \a position(v): vertex v's position, as windows' boxes are made of. */
  template <typename Position>
  VertexGrid(const VertexAngles& angles, Position position, int threads)
      : angles_(angles)
  {
    const std::size_t n = angles.size();
    // The grid spans the angles between the 0.1% and 99.9% quantiles of each axis (of
    // a sample of at most 2^16 vertices), not their whole extent: a few far outliers
    // would otherwise widen every cell and crowd the scan's vertices into a few of
    // them. Vertices beyond go to the border cells (cell() clamps).
    lo_ = Eigen::Vector2d::Zero();
    Eigen::Vector2d hi = lo_;
    if (n > 0) {
      const std::size_t stride = std::max<std::size_t>(1, n >> 16);
      std::vector<double> sample;
      sample.reserve(n / stride + 1);
      for (int axis = 0; axis < 2; ++axis) {
        sample.clear();
        for (std::size_t v = 0; v < n; v += stride)
          sample.push_back(angles[v][axis]);
        const auto at = [&sample](double q) {
          const auto k = static_cast<std::ptrdiff_t>(
              std::floor(q * static_cast<double>(sample.size() - 1)));
          std::nth_element(sample.begin(), sample.begin() + k, sample.end());
          return sample[static_cast<std::size_t>(k)];
        };
        lo_[axis] = at(0.001);
        hi[axis] = at(0.999);
        if (!(hi[axis] > lo_[axis])) { // most vertices on one line: the whole extent
          lo_[axis] = *std::min_element(sample.begin(), sample.end());
          hi[axis] = *std::max_element(sample.begin(), sample.end());
        }
      }
    }
    Eigen::Vector2d extent = hi - lo_;
    if (!extent.allFinite()) // not for a caller's angles (checked), but never NaN cells
      lo_ = extent = Eigen::Vector2d::Zero();
    const double cells = std::max(1.0, static_cast<double>(n) / 4.0);
    double cols = 1.0, rows = 1.0;
    if (extent.x() > 0.0 && extent.y() > 0.0) {
      cols = std::clamp(
          std::round(std::sqrt(cells * extent.x() / extent.y())), 1.0, cells);
      rows = std::clamp(std::round(cells / cols), 1.0, cells);
    } else if (extent.x() > 0.0)
      cols = cells;
    else if (extent.y() > 0.0)
      rows = cells;
    size_ = {static_cast<std::int64_t>(cols), static_cast<std::int64_t>(rows)};
    scale_ = Eigen::Vector2d(extent.x() > 0.0 ? cols / extent.x() : 0.0,
                             extent.y() > 0.0 ? rows / extent.y() : 0.0);
    start_.assign(static_cast<std::size_t>(size_[0] * size_[1]) + 1, 0);
    for (std::size_t v = 0; v < n; ++v) {
      const Eigen::Vector2d a = angles[v];
      ++start_[index(a.x(), a.y()) + 1];
    }
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    vertices_.resize(n);
    std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
    for (std::size_t v = 0; v < n; ++v) {
      const Eigen::Vector2d a = angles[v];
      vertices_[next[index(a.x(), a.y())]++] = v;
    }
    summaries_.resize(start_.size() - 1);
    const auto count = static_cast<std::ptrdiff_t>(summaries_.size());
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (n >= kParallelFrom)
#endif
    for (std::ptrdiff_t k = 0; k < count; ++k) {
      Summary& sum = summaries_[static_cast<std::size_t>(k)];
      for (std::size_t i = start_[k]; i < start_[k + 1]; ++i) {
        const Eigen::Vector3f x = position(vertices_[i]);
        if (!x.allFinite())
          continue;
        sum.min = sum.min.cwiseMin(x);
        sum.max = sum.max.cwiseMax(x);
      }
    }
  }

  /** The vertices whose angles lie in the window, borders included: g(count, summary)
   * for every cell all of whose vertices do, f(v) for each of the others. (cell() is
   * monotone: a vertex of a cell strictly between the window's first and last cells
   * along an axis lies between the window's borders along it.) */
  template <typename F, typename G>
  void forEachIn(double theta_min,
                 double theta_max,
                 double phi_min,
                 double phi_max,
                 F f,
                 G g) const
  {
    const std::int64_t c0 = cell(theta_min, 0), c1 = cell(theta_max, 0);
    const std::int64_t r0 = cell(phi_min, 1), r1 = cell(phi_max, 1);
    for (std::int64_t c = c0; c <= c1; ++c)
      for (std::int64_t r = r0; r <= r1; ++r) {
        const auto k = static_cast<std::size_t>(c * size_[1] + r);
        if (c > c0 && c < c1 && r > r0 && r < r1) {
          g(start_[k + 1] - start_[k], summaries_[k]);
          continue;
        }
        for (std::size_t i = start_[k]; i < start_[k + 1]; ++i) {
          const std::size_t v = vertices_[i];
          const Eigen::Vector2d& a = angles_[v];
          if (a.x() >= theta_min && a.x() <= theta_max && a.y() >= phi_min &&
              a.y() <= phi_max)
            f(v);
        }
      }
  }

private:
  /** The cell of an angle along an axis, clamped to the grid; monotone in the angle,
   * so a vertex inside a window lies in one of the window's cells. */
  std::int64_t cell(double x, int axis) const
  {
    const double t = (x - lo_[axis]) * scale_[axis];
    if (!(t > 0.0))
      return 0;
    return t < static_cast<double>(size_[axis] - 1) ? static_cast<std::int64_t>(t)
                                                    : size_[axis] - 1;
  }
  std::size_t index(double theta, double phi) const
  {
    return static_cast<std::size_t>(cell(theta, 0) * size_[1] + cell(phi, 1));
  }

  const VertexAngles& angles_;
  Eigen::Vector2d lo_, scale_;
  std::array<std::int64_t, 2> size_{{1, 1}};
  std::vector<std::size_t> start_;    ///< first entry of each cell in vertices_
  std::vector<std::size_t> vertices_; ///< by cell, in increasing number in each
  std::vector<Summary> summaries_;    ///< by cell
};

/** Windows registered in the cells of a uniform grid of angles that they overlap, for
 * the windows near another one without a pass over all of them. */
class WindowGrid {
public:
  explicit WindowGrid(double cell)
      : cell_(cell)
  {
  }

  /** Registers window \a w under \a id. */
  void add(const Window& w, std::size_t id)
  {
    forEachCell(w, [&](std::uint64_t key) { cells_[key].push_back(id); });
  }

  /** Calls f(id) for every window registered in a cell that \a w overlaps (a window
   * that overlaps w among them; some more than once). */
  template <typename F> void forEachNear(const Window& w, F f) const
  {
    forEachCell(w, [&](std::uint64_t key) {
      const auto it = cells_.find(key);
      if (it != cells_.end())
        for (const std::size_t id : it->second)
          f(id);
    });
  }

private:
  template <typename F> void forEachCell(const Window& w, F f) const
  {
    // Cells are as large as the largest window: a window spans at most two along each
    // axis. Cell numbers beyond 32 bits wrap in the key, which only puts far cells'
    // windows in one list (each is compared exactly).
    const auto at = [this](double x) {
      return static_cast<std::int64_t>(std::floor(x / cell_));
    };
    for (std::int64_t c = at(w.theta_min); c <= at(w.theta_max); ++c)
      for (std::int64_t r = at(w.phi_min); r <= at(w.phi_max); ++r)
        f((static_cast<std::uint64_t>(c) << 32) ^
          static_cast<std::uint64_t>(static_cast<std::uint32_t>(r)));
  }

  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

/** The parts of window \a c outside window \a s, which overlaps it: left and right of
 * s over c's whole height, below and above s over their common width. The parts
 * overlap neither s nor each other. A part's evidence is c's evidence inside it (c's
 * evidence inside s, borders included, is s's); it is fitted again to that evidence
 * and to the evidence whose margin (c's margin: margin + margin_spacings x the median
 * spacing) reaches into it, plus the margin, within the part: every margin around c's
 * evidence that s does not cover stays covered. Parts that no evidence reaches are
 * dropped. */
std::vector<Window>
cutAround(const Window& c,
          const Window& s,
          const VertexAngles& angles,
          const std::vector<std::uint8_t>& kept,
          const std::vector<double>& spacing,
          const RegionOfInterestParameters& p)
{
  const std::size_t ne = c.evidence.size(), n = ne + c.reach.size();
  // c's evidence, then the evidence whose margin reaches into it.
  const auto vertex = [&](std::size_t i) {
    return i < ne ? c.evidence[i] : c.reach[i - ne];
  };
  std::vector<double> local(n);
  for (std::size_t i = 0; i < n; ++i)
    local[i] = spacing[static_cast<std::size_t>(vertex(i))];
  const double margin = p.margin + p.margin_spacings * median(std::move(local));
  std::array<Window, 4> limits;
  limits.fill(c);
  limits[0].theta_max = s.theta_min; // left
  limits[1].theta_min = s.theta_max; // right
  for (int k = 2; k < 4; ++k) {
    limits[k].theta_min = std::max(c.theta_min, s.theta_min);
    limits[k].theta_max = std::min(c.theta_max, s.theta_max);
  }
  limits[2].phi_max = s.phi_min; // below
  limits[3].phi_min = s.phi_max; // above
  // The part that holds a vertex of c's evidence: -1 inside s.
  const auto owner = [&](const Eigen::Vector2d& a) {
    if (a.x() < s.theta_min)
      return 0;
    if (a.x() > s.theta_max)
      return 1;
    if (a.y() < s.phi_min)
      return 2;
    if (a.y() > s.phi_max)
      return 3;
    return -1;
  };
  // Otherwise, the margin box about a vertex must reach into a part by more than a
  // touch (rounding of the margins along a shared border). One pass over the vertices
  // fills the four parts, each in the vertices' order.
  const double reach = margin - kTouch;
  std::array<Window, 4> parts;
  std::array<std::uint8_t, 4> reach_reasons{};
  std::array<bool, 4> open{};
  for (int k = 0; k < 4; ++k) {
    parts[k] = Window::none();
    open[k] = limits[k].width() > 0.0 && limits[k].height() > 0.0;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = vertex(i);
    const Eigen::Vector2d& a = angles[static_cast<std::size_t>(v)];
    const int own = i < ne ? owner(a) : -1;
    for (int k = 0; k < 4; ++k) {
      if (!open[k])
        continue;
      const Window& lim = limits[k];
      if (own != k &&
          !(a.x() + reach > lim.theta_min && a.x() - reach < lim.theta_max &&
            a.y() + reach > lim.phi_min && a.y() - reach < lim.phi_max))
        continue;
      Window& part = parts[k];
      part.include(a);
      if (own == k) {
        part.reasons |= kept[v] & c.reasons;
        part.evidence.push_back(v);
      } else {
        reach_reasons[k] |= kept[v] & c.reasons;
        part.reach.push_back(v);
      }
    }
  }
  std::vector<Window> out;
  for (int k = 0; k < 4; ++k) {
    Window& part = parts[k];
    if (!open[k] || (part.evidence.empty() && part.reach.empty()))
      continue;
    growWithin(part, margin, p, limits[k]);
    if (part.reasons == 0)
      part.reasons = reach_reasons[k] != 0 ? reach_reasons[k] : c.reasons;
    if (part.width() > kTouch && part.height() > kTouch)
      out.push_back(std::move(part));
  }
  return out;
}

double
kindWeight(std::uint8_t kinds,
           double transition_strength,
           const RegionOfInterestParameters& p)
{
  double w = 0.0;
  if (kinds & kTransition)
    w = std::max(w, transition_strength);
  if (kinds & kSmallSegment)
    w = std::max(w, p.small_segment_weight);
  if (kinds & kSparse)
    w = std::max(w, p.sparse_weight);
  return w;
}

} // namespace

std::string
reasonsToString(std::uint8_t reasons)
{
  std::string s;
  const auto add = [&](std::uint8_t bit, const char* name) {
    if (reasons & bit)
      s += (s.empty() ? "" : "+") + std::string(name);
  };
  add(kTransition, "transition");
  add(kSmallSegment, "small_segment");
  add(kSparse, "sparse");
  return s;
}

double
fisherConfidenceAngle(std::size_t n, double resultant, double confidence)
{
  if (n < 2 || !(resultant > 0.0) || !(confidence > 0.0 && confidence < 1.0))
    return M_PI;
  const double nd = static_cast<double>(n);
  const double r = std::min(resultant, nd);
  const double c =
      1.0 - (nd - r) / r * (std::pow(1.0 / (1.0 - confidence), 1.0 / (nd - 1.0)) - 1.0);
  return c < -1.0 ? M_PI : std::acos(std::min(c, 1.0));
}

bool
RegionOfInterestParameters::validate(std::string* why) const
{
  if (!std::isfinite(leaf_sigma_threshold))
    return reject(why, "leaf_sigma_threshold", leaf_sigma_threshold, "finite [rad]");
  if (!(min_side_angle >= 0.0 && min_side_angle <= M_PI))
    return reject(why, "min_side_angle", min_side_angle, "[0, pi] [rad]");
  if (!(side_confidence >= 0.0 && side_confidence < 1.0))
    return reject(why, "side_confidence", side_confidence, "[0, 1)");
  if (!(edge_on_angle > 0.0 && edge_on_angle <= kHalfPi))
    return reject(why, "edge_on_angle", edge_on_angle, "(0, pi/2] [rad]");
  if (!(sparse_factor == 0.0 || finiteAtLeast(sparse_factor, 1.0)))
    return reject(why, "sparse_factor", sparse_factor, "0 or [1, inf)");
  if (min_component_vertices < 1)
    return reject(why, "min_component_vertices", 0.0, "[1, inf)");
  if (!(max_window_size >= kMinWindowSize && max_window_size <= M_PI))
    return reject(why, "max_window_size", max_window_size, "[1e-9, pi] [rad]");
  if (!(min_window_size >= 0.0 && min_window_size <= max_window_size))
    return reject(
        why, "min_window_size", min_window_size, "[0, max_window_size] [rad]");
  if (!finiteAtLeast(margin, 0.0))
    return reject(why, "margin", margin, "[0, inf) [rad]");
  if (!finiteAtLeast(margin_spacings, 0.0))
    return reject(why, "margin_spacings", margin_spacings, "[0, inf)");
  if (!finiteAtLeast(merge_area_ratio, 1.0))
    return reject(why, "merge_area_ratio", merge_area_ratio, "[1, inf)");
  if (!finiteAtLeast(target_step, 0.0))
    return reject(why, "target_step", target_step, "[0, inf) [rad]");
  if (!(std::isfinite(refinement_factor) && refinement_factor > 1.0))
    return reject(why, "refinement_factor", refinement_factor, "(1, inf)");
  if (!finiteAtLeast(min_refinement, 1.0))
    return reject(why, "min_refinement", min_refinement, "[1, inf)");
  if (!finiteAtLeast(transition_weight, 0.0))
    return reject(why, "transition_weight", transition_weight, "[0, inf)");
  if (!finiteAtLeast(leaf_weight, 0.0))
    return reject(why, "leaf_weight", leaf_weight, "[0, inf)");
  if (!finiteAtLeast(valid_edge_weight, 0.0))
    return reject(why, "valid_edge_weight", valid_edge_weight, "[0, inf)");
  if (!finiteAtLeast(small_segment_weight, 0.0))
    return reject(why, "small_segment_weight", small_segment_weight, "[0, inf)");
  if (!finiteAtLeast(sparse_weight, 0.0))
    return reject(why, "sparse_weight", sparse_weight, "[0, inf)");
  if (!finiteAtLeast(max_solid_angle, 0.0))
    return reject(
        why, "max_solid_angle", max_solid_angle, "[0, inf) [sr], 0 = no limit");
  if (!(sample_yield > 0.0 && sample_yield <= 1.0))
    return reject(why, "sample_yield", sample_yield, "(0, 1]");
  if (!(num_threads >= 0 && num_threads <= 1024))
    return reject(why, "num_threads", num_threads, "[0, 1024], 0 = automatic");
  return true;
}

double
windowSolidAngle(double theta_min,
                 double theta_max,
                 double phi_min,
                 double phi_max,
                 ViewProjection projection)
{
  if (projection == ViewProjection::Panoramic)
    return (theta_max - theta_min) * (std::sin(phi_max) - std::sin(phi_min));
  // On the plane z = 1 the window is the rectangle [tan theta] x [tan phi]; the solid
  // angle of [0, u] x [0, v] there is atan(u v / sqrt(1 + u^2 + v^2)).
  const double u0 = std::tan(theta_min), u1 = std::tan(theta_max);
  const double v0 = std::tan(phi_min), v1 = std::tan(phi_max);
  // A small window: the four corners' terms cancel to rounding (a window of 1e-9 rad
  // came out negative), so the rectangle's area du dv times the density
  // (1 + u^2 + v^2)^(-3/2) at its centre, whose relative error is below the squared
  // size, 1e-8 at most here.
  if (theta_max - theta_min < 1e-4 && phi_max - phi_min < 1e-4) {
    // tan a - tan b = sin(a - b) / (cos a cos b), without the cancellation.
    const double du =
        std::sin(theta_max - theta_min) / (std::cos(theta_max) * std::cos(theta_min));
    const double dv =
        std::sin(phi_max - phi_min) / (std::cos(phi_max) * std::cos(phi_min));
    const double u = 0.5 * (u0 + u1), v = 0.5 * (v0 + v1);
    const double w = 1.0 + u * u + v * v;
    return du * dv / (w * std::sqrt(w));
  }
  const auto corner = [](double u, double v) {
    return std::atan(u * v / std::sqrt(1.0 + u * u + v * v));
  };
  return corner(u1, v1) - corner(u0, v1) - corner(u1, v0) + corner(u0, v0);
}

namespace {

/** computeRegionsOfInterest() but for its handling of std::bad_alloc. */
bool
regionsOfInterest(const SegmentationResult& result,
                  const SphericalTriangulation& tri,
                  const Eigen::Affine3f& sensor_to_cloud,
                  const RegionOfInterestParameters& p,
                  std::vector<RegionOfInterest>& regions,
                  RegionOfInterestStats* stats)
{
  regions.clear();
  RegionOfInterestStats local;
  RegionOfInterestStats& st = stats ? *stats : local;
  st = RegionOfInterestStats();
  std::string why;
  if (!p.validate(&why)) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] %s\n", why.c_str());
    return false;
  }
  const std::size_t nv = tri.vertex_point.size();
  if (tri.vertex_angles.size() != nv || tri.vertex_positions.size() != nv ||
      result.labels.size() != tri.point_vertex.size() ||
      result.mesh.triangles.size() != tri.triangles.size() ||
      result.mesh.classes.size() != tri.triangles.size() ||
      result.mesh.neighbours.size() != tri.triangles.size() ||
      !sensor_to_cloud.matrix().allFinite()) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] the segmentation result "
              "(%zu labels, %zu triangles) does not belong to the triangulation (%zu "
              "points, %zu triangles), or the sensor pose is not finite\n",
              result.labels.size(),
              result.mesh.triangles.size(),
              tri.point_vertex.size(),
              tri.triangles.size());
    return false;
  }
  const int threads = detail::threadCount(p.num_threads);
  if (const std::size_t v =
          firstWhere(nv,
                     threads,
                     [&](std::size_t v) {
                       return tri.vertex_point[v] < 0 ||
                              static_cast<std::size_t>(tri.vertex_point[v]) >=
                                  result.labels.size();
                     });
      v < nv) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] vertex %zu has no "
              "input point\n",
              v);
    return false;
  }
  if (tri.triangles.size() > std::numeric_limits<std::uint32_t>::max() / 3) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] %zu triangles: at most "
              "(2^32 - 1) / 3 are supported\n",
              tri.triangles.size());
    return false;
  }
  const auto nt = static_cast<pcl::index_t>(tri.triangles.size());
  // Per triangle: 0 fine, 1 a corner or neighbour out of range, 2 a corner that is not
  // the result's.
  const auto triangleFault = [&](std::size_t t) {
    for (int k = 0; k < 3; ++k) {
      if (tri.triangles[t][k] < 0 ||
          static_cast<std::size_t>(tri.triangles[t][k]) >= nv ||
          result.mesh.neighbours[t][k] < -1 || result.mesh.neighbours[t][k] >= nt)
        return 1;
      // The result's mesh names each corner by its point: the triangulation's.
      if (result.mesh.triangles[t][k] != tri.vertex_point[tri.triangles[t][k]])
        return 2;
    }
    return 0;
  };
  if (const std::size_t t = firstWhere(tri.triangles.size(),
                                       threads,
                                       [&](std::size_t t) { return triangleFault(t); });
      t < tri.triangles.size()) {
    if (triangleFault(t) == 1)
      PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] triangle %zu refers to "
                "a vertex or neighbour out of range\n",
                t);
    else
      PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] triangle %zu of the "
                "result does not join the triangulation's points (a result of "
                "another cloud, or of the same points in another order?)\n",
                t);
    return false;
  }
  if (nv == 0)
    return true;
  const double q = tri.angle_quantization;
  if (!(std::isfinite(q) && q > 0.0)) {
    PCL_ERROR(
        "[pcl::selective_seg::computeRegionsOfInterest] the triangulation's angle "
        "quantization %g is not a positive step [rad]\n",
        q);
    return false;
  }
  // The pose's rotation part must be invertible: evidence in the leaves is matched in
  // the sensor frame.
  const Eigen::Affine3d to_cloud = sensor_to_cloud.cast<double>();
  const Eigen::Affine3d to_sensor = to_cloud.inverse();
  if (!(std::abs(to_cloud.linear().determinant()) > 1e-9) ||
      !to_sensor.matrix().allFinite()) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] the sensor pose is not "
              "invertible (its rotation part is singular)\n");
    return false;
  }
  // A vertex's position may overflow float in the sensor frame (a point near float's
  // limit, rotated): the segmentation leaves it without a normal, and here it counts
  // for its angles only (no leaf evidence, no part of a box).
  if (const std::size_t v = firstWhere(nv - 1,
                                       threads,
                                       [&](std::size_t v) {
                                         return tri.vertex_angles[v + 1][0] <
                                                tri.vertex_angles[v][0];
                                       }) +
                            1;
      v < nv) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] vertex %zu is out of "
              "theta order (vertices are numbered in increasing quantized theta)\n",
              v);
    return false;
  }
  const VertexAngles angles(tri, q);
  // Angles of a view: within [-pi, pi] up to the rounding to a quantum (a panorama's
  // azimuth near the seam rounds up to half a quantum beyond pi; a quantization far
  // too coarse for its quantized angles, e.g. 1e304, is not a triangulation of
  // directions).
  if (const std::size_t v = firstWhere(nv,
                                       threads,
                                       [&](std::size_t v) {
                                         const Eigen::Vector2d a = angles[v];
                                         return !(std::abs(a.x()) <= M_PI + q &&
                                                  std::abs(a.y()) <= M_PI + q);
                                       });
      v < nv) {
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] vertex %zu has angles "
              "(%g, %g) outside [-pi, pi] by more than a quantum: the quantized angles "
              "do not fit the angle quantization %g\n",
              v,
              angles[v].x(),
              angles[v].y(),
              q);
    return false;
  }
  const std::vector<double> spacing = vertexSpacing(tri, angles, threads);
  std::vector<double> strength;
  const std::vector<std::uint8_t> kinds =
      findEvidence(result, tri, to_sensor, angles, spacing, p, threads, strength);
  for (const auto k : kinds) {
    st.transition_vertices += (k & kTransition) != 0;
    st.small_segment_vertices += (k & kSmallSegment) != 0;
    st.sparse_vertices += (k & kSparse) != 0;
  }
  std::vector<std::uint8_t> kept;
  std::vector<Window> windows = makeTileWindows(tri, angles, kinds, spacing, p, kept);
  mergeWindows(windows, p);
  st.candidates = windows.size();

  // A vertex's position in the cloud frame, for the windows' boxes.
  const auto cloudPosition = [&](std::size_t v) -> Eigen::Vector3f {
    return (to_cloud * tri.vertex_positions[v].cast<double>()).cast<float>();
  };
  const VertexGrid grid(angles, cloudPosition, threads);
  // A window as a region: steps, priority, estimates and its box; or why it is
  // dropped: already sampled about as finely as it would be (min_refinement), or a
  // part holding no evidence of its own narrower than a step.
  enum class Fate { Kept, AlreadyFine, Thin };
  const auto evaluate = [&](Window& w, RegionOfInterest& r) {
    auto& ev = w.evidence;
    if (!std::is_sorted(ev.begin(), ev.end())) // the parts of a cut keep their order
      std::sort(ev.begin(), ev.end());
    ev.erase(std::unique(ev.begin(), ev.end()), ev.end());
    std::vector<double> local;
    local.reserve(ev.size());
    double weighted = 0.0, covered = 0.0;
    for (const auto v : ev) {
      local.push_back(spacing[v]);
      const double s2 = spacing[v] * spacing[v];
      weighted += kindWeight(kept[v], strength[v], p) * s2;
      covered += s2;
    }
    r = RegionOfInterest();
    r.theta_min = w.theta_min;
    r.theta_max = w.theta_max;
    r.phi_min = w.phi_min;
    r.phi_max = w.phi_max;
    r.reasons = w.reasons;
    r.num_evidence = ev.size();
    // A part that only the margins of evidence beside it reach: the spacing there.
    if (ev.empty())
      for (const auto v : w.reach)
        local.push_back(spacing[v]);
    r.current_step = median(std::move(local));
    r.suggested_step =
        p.target_step > 0.0 ? p.target_step : r.current_step / p.refinement_factor;
    if (!(r.suggested_step > 0.0) ||
        r.current_step < p.min_refinement * r.suggested_step)
      return Fate::AlreadyFine;
    // Such a part narrower than a step of the finer scan adds no ray that the scan of
    // the window beside it does not come within a step of.
    if (ev.empty() && (w.width() < r.suggested_step || w.height() < r.suggested_step))
      return Fate::Thin;
    const double area = w.area();
    r.solid_angle = windowSolidAngle(
        r.theta_min, r.theta_max, r.phi_min, r.phi_max, tri.projection);
    r.projection = tri.projection;
    // Saturated: a tiny target step can ask for more samples than a size_t holds.
    const double estimate =
        std::round(p.sample_yield * area / (r.suggested_step * r.suggested_step));
    r.estimated_points = estimate < kMaxCount ? static_cast<std::size_t>(estimate)
                                              : std::numeric_limits<std::size_t>::max();
    // The window's vertices, their angles compared as the window was made from them
    // (angles[v]), so that evidence on a border is inside.
    r.box_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    r.box_max = Eigen::Vector3f::Constant(std::numeric_limits<float>::lowest());
    grid.forEachIn(
        r.theta_min,
        r.theta_max,
        r.phi_min,
        r.phi_max,
        [&](std::size_t v) {
          ++r.num_points;
          const Eigen::Vector3f x = cloudPosition(v);
          if (!x.allFinite())
            return;
          r.box_min = r.box_min.cwiseMin(x);
          r.box_max = r.box_max.cwiseMax(x);
        },
        [&](std::size_t count, const VertexGrid::Summary& cell) {
          r.num_points += count;
          r.box_min = r.box_min.cwiseMin(cell.min);
          r.box_max = r.box_max.cwiseMax(cell.max);
        });
    // The weighted share of the window's area its evidence stands for (each vertex
    // spacing^2), times the share of new samples a scan at the suggested step brings.
    r.priority =
        weighted / std::max(area, covered) * (1.0 - r.suggested_step / r.current_step);
    return Fate::Kept;
  };

  // Candidates in priority order, then by their angles (and, for a tie in all of
  // them, in the order they were made): the greedy selection's order and the output's.
  struct Candidate {
    RegionOfInterest region;
    Window window;
  };
  std::vector<Candidate> pool;
  const auto before = [&pool](std::size_t i, std::size_t j) {
    const RegionOfInterest& a = pool[i].region;
    const RegionOfInterest& b = pool[j].region;
    return std::tie(b.priority, a.theta_min, a.phi_min, a.theta_max, a.phi_max, i) <
           std::tie(a.priority, b.theta_min, b.phi_min, b.theta_max, b.phi_max, j);
  };
  // A max-heap on "comes first".
  const auto later = [&before](std::size_t i, std::size_t j) { return before(j, i); };
  std::vector<std::size_t> queue;
  const auto take = [&](Window&& w, RegionOfInterest& r, Fate fate, double cap) {
    if (fate != Fate::Kept) {
      ++(fate == Fate::Thin ? st.thin_parts : st.already_fine);
      return;
    }
    r.priority = std::min(r.priority, cap);
    pool.push_back({r, std::move(w)});
    queue.push_back(pool.size() - 1);
    std::push_heap(queue.begin(), queue.end(), later);
  };
  const auto offer = [&](Window&& w, double cap) {
    RegionOfInterest r;
    const Fate fate = evaluate(w, r);
    take(std::move(w), r, fate, cap);
  };
  {
    // The candidates are evaluated on the threads (each on its own), then offered in
    // their order.
    std::vector<RegionOfInterest> first(windows.size());
    std::vector<Fate> fates(windows.size());
    const auto count = static_cast<std::ptrdiff_t>(windows.size());
    detail::ParallelExceptions errors;
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (count >= 64)
#endif
    for (std::ptrdiff_t i = 0; i < count; ++i)
      errors.run([&] { fates[i] = evaluate(windows[i], first[i]); });
    errors.rethrow();
    for (std::size_t i = 0; i < windows.size(); ++i)
      take(std::move(windows[i]),
           first[i],
           fates[i],
           std::numeric_limits<double>::infinity());
  }
  std::vector<std::size_t> selected;
  // Cells as large as the largest candidate (parts are smaller than their windows):
  // a window lies in at most four of them.
  double largest = 0.0;
  for (const auto& c : pool)
    largest = std::max({largest, c.window.width(), c.window.height()});
  WindowGrid taken(largest > 0.0 ? largest : 1.0);
  while (!queue.empty()) {
    std::pop_heap(queue.begin(), queue.end(), later);
    const std::size_t i = queue.back();
    queue.pop_back();
    const RegionOfInterest& r = pool[i].region;
    // With disjoint windows, one that overlaps a window taken before it is cut around
    // that window, and its parts are candidates again.
    if (p.disjoint_windows) {
      // The first window taken that it overlaps.
      std::size_t hit = selected.size();
      taken.forEachNear(pool[i].window, [&](std::size_t order) {
        if (order < hit &&
            overlapArea(pool[i].window, pool[selected[order]].window) > 0.0)
          hit = order;
      });
      if (hit != selected.size()) {
        ++st.cut;
        // A part is no more urgent than its window: windows are taken, and listed, in
        // decreasing priority.
        const double cap = r.priority;
        for (auto& part : cutAround(
                 pool[i].window, pool[selected[hit]].window, angles, kept, spacing, p))
          offer(std::move(part), cap); // may reallocate pool: r is not used after this
        continue;
      }
    }
    const bool fits = (p.max_regions == 0 || selected.size() < p.max_regions) &&
                      (p.max_points == 0 ||
                       (r.estimated_points <= p.max_points &&
                        st.selected_points <= p.max_points - r.estimated_points)) &&
                      (p.max_solid_angle == 0.0 ||
                       st.selected_solid_angle + r.solid_angle <= p.max_solid_angle);
    if (!fits) {
      ++st.over_budget;
      continue;
    }
    if (p.disjoint_windows)
      taken.add(pool[i].window, selected.size());
    selected.push_back(i);
    const std::size_t most = std::numeric_limits<std::size_t>::max();
    st.selected_points = r.estimated_points <= most - st.selected_points
                             ? st.selected_points + r.estimated_points
                             : most;
    st.selected_solid_angle += r.solid_angle;
  }
  for (const std::size_t i : selected)
    regions.push_back(pool[i].region);
  st.selected = regions.size();
  return true;
}

} // namespace

bool
computeRegionsOfInterest(const SegmentationResult& result,
                         const SphericalTriangulation& tri,
                         const Eigen::Affine3f& sensor_to_cloud,
                         const RegionOfInterestParameters& p,
                         std::vector<RegionOfInterest>& regions,
                         RegionOfInterestStats* stats)
{
  try {
    return regionsOfInterest(result, tri, sensor_to_cloud, p, regions, stats);
  } catch (const std::bad_alloc&) {
    std::vector<RegionOfInterest>().swap(regions);
    if (stats)
      *stats = RegionOfInterestStats();
    PCL_ERROR("[pcl::selective_seg::computeRegionsOfInterest] out of memory with %zu "
              "points and %zu triangles: segment a smaller scan (crop or downsample "
              "it) or give the process more memory\n",
              tri.point_vertex.size(),
              tri.triangles.size());
    return false;
  }
}

} // namespace selective_seg
} // namespace pcl
