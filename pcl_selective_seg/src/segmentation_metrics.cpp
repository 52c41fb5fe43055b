/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/segmentation_metrics.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <tuple>
#include <unordered_map>

#include "int64_triple_hash.h"

namespace pcl {
namespace selective_seg {
namespace metrics {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/** Largest number of tolerances hooverSweep() makes. */
constexpr double kMaxSweepTolerances = 100000;

/** Finite, and no coordinate beyond kMaxMetricCoordinate [m]: the nearest-neighbour
 * searches compare squared distances in float, which overflow beyond about 1.8e19 m. */
bool
measurable(const pcl::PointXYZ& p)
{
  return pcl::isFinite(p) &&
         p.getVector3fMap().cwiseAbs().maxCoeff() <= kMaxMetricCoordinate;
}

/** count >= fraction * total, with a margin of 1e-9 * total for the rounding of the
 * fraction (see the namespace documentation). */
bool
atLeast(std::size_t count, double fraction, std::size_t total)
{
  const auto t = static_cast<double>(total);
  return static_cast<double>(count) >= fraction * t - 1e-9 * t;
}

double
ratio(std::size_t numerator, std::size_t denominator)
{
  return denominator == 0
             ? kNaN
             : static_cast<double>(numerator) / static_cast<double>(denominator);
}

bool
inUnitInterval(double value)
{
  return value > 0.0 && value <= 1.0;
}

std::vector<std::uint32_t>
sortedUnique(std::vector<std::uint32_t> labels)
{
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  return labels;
}

std::size_t
indexOf(const std::vector<std::uint32_t>& sorted_labels, std::uint32_t label)
{
  return static_cast<std::size_t>(
      std::lower_bound(sorted_labels.begin(), sorted_labels.end(), label) -
      sorted_labels.begin());
}

/** Distinct GT labels of the valid points and distinct predicted labels among them. */
void
collectLabels(const std::vector<std::uint32_t>& predicted,
              const std::vector<std::uint32_t>& ground_truth,
              LabelOverlap& overlap)
{
  std::vector<std::uint32_t> gt;
  std::vector<std::uint32_t> pred;
  gt.reserve(ground_truth.size());
  pred.reserve(ground_truth.size());
  for (std::size_t i = 0; i < ground_truth.size(); ++i) {
    if (ground_truth[i] == 0)
      continue;
    gt.push_back(ground_truth[i]);
    if (predicted[i] != 0)
      pred.push_back(predicted[i]);
  }
  overlap.gt_labels = sortedUnique(std::move(gt));
  overlap.predicted_labels = sortedUnique(std::move(pred));
}

/** Run-length encode sorted (gt << 32 | predicted) keys into entries. */
std::vector<OverlapEntry>
entriesFromKeys(std::vector<std::uint64_t>& keys)
{
  std::sort(keys.begin(), keys.end());
  std::vector<OverlapEntry> entries;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j] == keys[i])
      ++j;
    entries.push_back({static_cast<std::size_t>(keys[i] >> 32),
                       static_cast<std::size_t>(keys[i] & 0xffffffffu),
                       j - i});
    i = j;
  }
  return entries;
}

bool
validTolerance(double tolerance)
{
  return tolerance >= 0.5 && tolerance <= 1.0;
}

/** Per GT region (over = true): whether it is over-segmented; per predicted region
 * (over = false): whether it under-segments. The parts of region r are the regions
 * holding at least T of their own points in r; r is an instance when it has two or
 * more parts and they hold at least T of r's points. */
std::vector<char>
groupInstances(const LabelOverlap& overlap, double tolerance, bool over)
{
  const auto& own_sizes = over ? overlap.gt_sizes : overlap.predicted_sizes;
  const auto& part_sizes = over ? overlap.predicted_sizes : overlap.gt_sizes;
  std::vector<std::size_t> parts(own_sizes.size(), 0);
  std::vector<std::size_t> sums(own_sizes.size(), 0);
  for (const auto& e : overlap.entries) {
    const std::size_t own = over ? e.gt : e.predicted;
    const std::size_t part = over ? e.predicted : e.gt;
    if (atLeast(e.count, tolerance, part_sizes[part])) {
      ++parts[own];
      sums[own] += e.count;
    }
  }
  std::vector<char> instance(own_sizes.size(), 0);
  for (std::size_t r = 0; r < own_sizes.size(); ++r)
    instance[r] = parts[r] >= 2 && atLeast(sums[r], tolerance, own_sizes[r]);
  return instance;
}

} // namespace

bool
buildLabelOverlap(const std::vector<std::uint32_t>& predicted,
                  const std::vector<std::uint32_t>& ground_truth,
                  LabelOverlap& overlap)
{
  overlap = LabelOverlap{};
  if (predicted.size() != ground_truth.size()) {
    PCL_ERROR("[pcl::selective_seg::metrics::buildLabelOverlap] predicted labels "
              "(%zu) != ground-truth labels (%zu)\n",
              predicted.size(),
              ground_truth.size());
    return false;
  }
  collectLabels(predicted, ground_truth, overlap);
  overlap.gt_sizes.assign(overlap.gt_labels.size(), 0);
  overlap.predicted_sizes.assign(overlap.predicted_labels.size(), 0);
  std::vector<std::uint64_t> keys;
  keys.reserve(ground_truth.size());
  for (std::size_t i = 0; i < ground_truth.size(); ++i) {
    if (ground_truth[i] == 0)
      continue;
    ++overlap.num_valid_points;
    const std::size_t n = indexOf(overlap.gt_labels, ground_truth[i]);
    ++overlap.gt_sizes[n];
    if (predicted[i] == 0) {
      ++overlap.num_unlabeled_points;
      continue;
    }
    const std::size_t m = indexOf(overlap.predicted_labels, predicted[i]);
    ++overlap.predicted_sizes[m];
    keys.push_back(static_cast<std::uint64_t>(n) << 32 | static_cast<std::uint64_t>(m));
  }
  overlap.entries = entriesFromKeys(keys);
  return true;
}

HooverScores
hooverScores(const LabelOverlap& overlap, double tolerance)
{
  HooverScores scores;
  scores.tolerance = tolerance;
  scores.num_gt_regions = overlap.gt_labels.size();
  scores.num_predicted_regions = overlap.predicted_labels.size();
  const std::vector<char> over = groupInstances(overlap, tolerance, true);
  const std::vector<char> under = groupInstances(overlap, tolerance, false);
  std::vector<char> gt_used(scores.num_gt_regions, 0);
  std::vector<char> predicted_used(scores.num_predicted_regions, 0);
  for (const auto& e : overlap.entries) {
    const bool of_predicted =
        atLeast(e.count, tolerance, overlap.predicted_sizes[e.predicted]);
    const bool of_gt = atLeast(e.count, tolerance, overlap.gt_sizes[e.gt]);
    if (of_predicted && of_gt)
      ++scores.correct_detections;
    if ((of_predicted && of_gt) || (of_predicted && over[e.gt]) ||
        (of_gt && under[e.predicted])) {
      gt_used[e.gt] = 1;
      predicted_used[e.predicted] = 1;
    }
  }
  scores.over_segmentations =
      static_cast<std::size_t>(std::count(over.begin(), over.end(), 1));
  scores.under_segmentations =
      static_cast<std::size_t>(std::count(under.begin(), under.end(), 1));
  scores.missed =
      static_cast<std::size_t>(std::count(gt_used.begin(), gt_used.end(), 0));
  scores.noise = static_cast<std::size_t>(
      std::count(predicted_used.begin(), predicted_used.end(), 0));
  return scores;
}

bool
hooverMetrics(const std::vector<std::uint32_t>& predicted,
              const std::vector<std::uint32_t>& ground_truth,
              double tolerance,
              HooverScores& scores)
{
  scores = HooverScores{};
  if (!validTolerance(tolerance)) {
    PCL_ERROR("[pcl::selective_seg::metrics::hooverMetrics] tolerance %g is not in "
              "[0.5, 1]\n",
              tolerance);
    return false;
  }
  LabelOverlap overlap;
  if (!buildLabelOverlap(predicted, ground_truth, overlap))
    return false;
  scores = hooverScores(overlap, tolerance);
  return true;
}

bool
hooverSweep(const std::vector<std::uint32_t>& predicted,
            const std::vector<std::uint32_t>& ground_truth,
            std::vector<HooverScores>& sweep,
            double min_tolerance,
            double max_tolerance,
            double step)
{
  sweep.clear();
  if (!validTolerance(min_tolerance) || !validTolerance(max_tolerance) ||
      max_tolerance < min_tolerance || !(step > 0.0) || !std::isfinite(step)) {
    PCL_ERROR("[pcl::selective_seg::metrics::hooverSweep] bad range %g..%g step %g "
              "(need 0.5 <= min <= max <= 1, a finite step > 0)\n",
              min_tolerance,
              max_tolerance,
              step);
    return false;
  }
  // Tolerance i is min + i step while it exceeds max by at most step / 1000. Counted
  // first: a loop that added steps until it passed max would never end for a step too
  // small to move min.
  const double last = std::floor((max_tolerance - min_tolerance) / step + 1e-3);
  if (!(last < kMaxSweepTolerances)) {
    PCL_ERROR("[pcl::selective_seg::metrics::hooverSweep] step %g makes more than %g "
              "tolerances from %g to %g: use a larger step\n",
              step,
              kMaxSweepTolerances,
              min_tolerance,
              max_tolerance);
    return false;
  }
  LabelOverlap overlap;
  if (!buildLabelOverlap(predicted, ground_truth, overlap))
    return false;
  for (std::size_t i = 0; i <= static_cast<std::size_t>(last); ++i) {
    const double tolerance = min_tolerance + static_cast<double>(i) * step;
    sweep.push_back(hooverScores(overlap, std::min(tolerance, max_tolerance)));
  }
  return true;
}

std::vector<MajorityLabel>
majorityLabels(const LabelOverlap& overlap)
{
  std::vector<MajorityLabel> majority(overlap.predicted_labels.size());
  for (const auto& e : overlap.entries) {
    auto& best = majority[e.predicted];
    if (e.count > best.count) {
      best.gt = e.gt;
      best.count = e.count;
    }
  }
  for (std::size_t m = 0; m < majority.size(); ++m)
    majority[m].purity = ratio(majority[m].count, overlap.predicted_sizes[m]);
  return majority;
}

UnderSegmentationError
underSegmentationError(const LabelOverlap& overlap)
{
  const std::vector<MajorityLabel> majority = majorityLabels(overlap);
  UnderSegmentationError result;
  result.valid_points = overlap.num_valid_points;
  for (const auto& e : overlap.entries)
    if (e.gt != majority[e.predicted].gt)
      result.leaked_points += e.count;
  result.error = ratio(result.leaked_points, result.valid_points);
  return result;
}

SegmentCoverage
segmentsCovering(const LabelOverlap& overlap, double fraction)
{
  const auto& sizes = overlap.predicted_sizes;
  std::vector<std::size_t> order(sizes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&sizes](std::size_t a, std::size_t b) {
    return sizes[a] > sizes[b];
  });
  SegmentCoverage result;
  result.fraction = fraction;
  const std::size_t total = overlap.num_valid_points;
  std::size_t covered = 0;
  while (!atLeast(covered, fraction, total) && result.segments < order.size())
    covered += sizes[order[result.segments++]];
  result.reached = atLeast(covered, fraction, total);
  result.covered_fraction = ratio(covered, total);
  return result;
}

PartRecovery
recoverableParts(const LabelOverlap& overlap,
                 double min_purity,
                 double min_part_fraction)
{
  const std::vector<MajorityLabel> majority = majorityLabels(overlap);
  std::vector<std::size_t> recovered(overlap.gt_labels.size(), 0);
  for (std::size_t m = 0; m < majority.size(); ++m)
    if (atLeast(majority[m].count, min_purity, overlap.predicted_sizes[m]))
      recovered[majority[m].gt] += majority[m].count;
  PartRecovery result;
  result.num_parts = overlap.gt_labels.size();
  for (std::size_t n = 0; n < result.num_parts; ++n)
    if (atLeast(recovered[n], min_part_fraction, overlap.gt_sizes[n]))
      ++result.recoverable_parts;
  result.fraction = ratio(result.recoverable_parts, result.num_parts);
  return result;
}

namespace {

/** The GT-valid points with finite coordinates, and their input indices. */
pcl::PointCloud<pcl::PointXYZ>::Ptr
validPoints(const pcl::PointCloud<pcl::PointXYZ>& cloud,
            const std::vector<std::uint32_t>& ground_truth,
            std::vector<std::size_t>& input_index)
{
  auto valid = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  input_index.clear();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (ground_truth[i] != 0 && measurable(cloud[i])) {
      valid->push_back(cloud[i]);
      input_index.push_back(i);
    }
  }
  return valid;
}

/** Whether b lies within \a radius of a as pcl::search::KdTree's radius search decides
 * it (FLANN's L2_Simple<float>: the squared differences summed in float, x then y then
 * z, strictly below the squared radius rounded to float). */
bool
withinRadius(const pcl::PointXYZ& a, const pcl::PointXYZ& b, float squared_radius)
{
  float sum = 0.0f;
  const float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  sum += dx * dx;
  sum += dy * dy;
  sum += dz * dz;
  return sum < squared_radius;
}

/** Flags the GT and predicted boundary points among the valid points: a point is a
 * boundary when a point within the radius carries another label (for the prediction,
 * a labeled point only). The points are bucketed in cells a little larger than the
 * radius, each cell's points grouped by label, so that a point looks only at the
 * other labels' points of the 27 cells around it and stops at the first within the
 * radius: a search of the whole ball per point is quadratic in a dense cloud (50,000
 * points within one radius took minutes). The flags are those of a radius search of
 * pcl::search::KdTree (its distance rule, withinRadius()). */
void
findBoundaries(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& valid,
               const std::vector<std::uint32_t>& predicted,
               const std::vector<std::uint32_t>& ground_truth,
               double radius,
               std::vector<char>& gt_boundary,
               std::vector<char>& predicted_boundary)
{
  const std::size_t n = valid->size();
  gt_boundary.assign(n, 0);
  predicted_boundary.assign(n, 0);
  if (n == 0)
    return;
  const auto squared_radius = static_cast<float>(radius * radius);
  // Every point within the radius of a point lies in its cell or the 26 around it.
  const double side = radius * (1.0 + 1e-5);
  const Eigen::Vector3d origin = (*valid)[0].getVector3fMap().cast<double>();
  using Key = std::array<std::int64_t, 3>;
  std::unordered_map<Key, std::uint32_t, detail::Int64TripleHash> cell_of;
  std::vector<Key> keys(n);
  std::vector<std::uint32_t> cell(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d c =
        ((*valid)[k].getVector3fMap().cast<double>() - origin) / side;
    for (int i = 0; i < 3; ++i) // saturated far away: those cells share a key, which
      keys[k][i] = static_cast<std::int64_t>( // only makes them hold more points
          std::floor(std::clamp(c[i], -1e15, 1e15)));
    cell[k] = cell_of.try_emplace(keys[k], static_cast<std::uint32_t>(cell_of.size()))
                  .first->second;
  }
  const std::size_t num_cells = cell_of.size();
  /** The points by cell, then by label; per cell, its runs of one label. */
  struct Grouping {
    std::vector<std::uint32_t> order;      ///< point indices
    std::vector<std::uint32_t> run_start;  ///< per run: first entry in order
    std::vector<std::uint32_t> cell_start; ///< per cell: first run
  };
  const auto group = [&](const std::vector<std::uint32_t>& labels) {
    Grouping g;
    g.order.resize(n);
    std::iota(g.order.begin(), g.order.end(), 0u);
    std::sort(g.order.begin(), g.order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return std::tie(cell[a], labels[a], a) < std::tie(cell[b], labels[b], b);
    });
    g.cell_start.assign(num_cells + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t p = g.order[i];
      if (i == 0 || cell[p] != cell[g.order[i - 1]] ||
          labels[p] != labels[g.order[i - 1]]) {
        g.run_start.push_back(static_cast<std::uint32_t>(i));
        ++g.cell_start[cell[p] + 1];
      }
    }
    g.run_start.push_back(static_cast<std::uint32_t>(n));
    std::partial_sum(g.cell_start.begin(), g.cell_start.end(), g.cell_start.begin());
    return g;
  };
  const Grouping by_truth = group(ground_truth);
  const Grouping by_prediction = group(predicted);
  // Whether a point of another label than labels[k] lies within the radius of k.
  const auto otherLabelNear =
      [&](std::size_t k, const std::vector<std::uint32_t>& labels, const Grouping& g) {
        const pcl::PointXYZ& q = (*valid)[k];
        for (std::int64_t dx = -1; dx <= 1; ++dx)
          for (std::int64_t dy = -1; dy <= 1; ++dy)
            for (std::int64_t dz = -1; dz <= 1; ++dz) {
              const auto it =
                  cell_of.find({keys[k][0] + dx, keys[k][1] + dy, keys[k][2] + dz});
              if (it == cell_of.end())
                continue;
              for (std::uint32_t run = g.cell_start[it->second];
                   run < g.cell_start[it->second + 1];
                   ++run) {
                if (labels[g.order[g.run_start[run]]] == labels[k])
                  continue;
                for (std::uint32_t i = g.run_start[run]; i < g.run_start[run + 1]; ++i)
                  if (withinRadius(q, (*valid)[g.order[i]], squared_radius))
                    return true;
              }
            }
        return false;
      };
  for (std::size_t k = 0; k < n; ++k) {
    gt_boundary[k] = otherLabelNear(k, ground_truth, by_truth);
    predicted_boundary[k] =
        predicted[k] != 0 && otherLabelNear(k, predicted, by_prediction);
  }
}

/** Labels of the valid points, in the order of validPoints(). */
std::vector<std::uint32_t>
gather(const std::vector<std::uint32_t>& labels, const std::vector<std::size_t>& index)
{
  std::vector<std::uint32_t> out(index.size());
  for (std::size_t k = 0; k < index.size(); ++k)
    out[k] = labels[index[k]];
  return out;
}

/** Number of GT boundary points within match_distance of a predicted one. */
std::size_t
matchBoundaries(const pcl::PointCloud<pcl::PointXYZ>& valid,
                const std::vector<char>& gt_boundary,
                const std::vector<char>& predicted_boundary,
                double match_distance)
{
  auto targets = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (std::size_t k = 0; k < valid.size(); ++k)
    if (predicted_boundary[k])
      targets->push_back(valid[k]);
  if (targets->empty())
    return 0;
  pcl::search::KdTree<pcl::PointXYZ> tree(false);
  tree.setInputCloud(targets);
  pcl::Indices nearest;
  std::vector<float> sqr_distances;
  std::size_t matched = 0;
  for (std::size_t k = 0; k < valid.size(); ++k) {
    if (!gt_boundary[k] || tree.nearestKSearch(valid[k], 1, nearest, sqr_distances) < 1)
      continue;
    if (std::sqrt(static_cast<double>(sqr_distances[0])) <= match_distance)
      ++matched;
  }
  return matched;
}

} // namespace

bool
boundaryRecall(const pcl::PointCloud<pcl::PointXYZ>& cloud,
               const std::vector<std::uint32_t>& predicted,
               const std::vector<std::uint32_t>& ground_truth,
               double radius,
               double match_distance,
               BoundaryRecall& result)
{
  result = BoundaryRecall{};
  if (predicted.size() != cloud.size() || ground_truth.size() != cloud.size()) {
    PCL_ERROR("[pcl::selective_seg::metrics::boundaryRecall] points (%zu), predicted "
              "labels (%zu) and ground-truth labels (%zu) differ\n",
              static_cast<std::size_t>(cloud.size()),
              predicted.size(),
              ground_truth.size());
    return false;
  }
  if (!(radius > 0.0) || !std::isfinite(radius) || !(match_distance >= 0.0) ||
      !std::isfinite(match_distance)) {
    PCL_ERROR("[pcl::selective_seg::metrics::boundaryRecall] radius %g must be > 0 "
              "and match distance %g >= 0 [m]\n",
              radius,
              match_distance);
    return false;
  }
  std::vector<std::size_t> input_index;
  const auto valid = validPoints(cloud, ground_truth, input_index);
  std::vector<char> gt_boundary;
  std::vector<char> predicted_boundary;
  findBoundaries(valid,
                 gather(predicted, input_index),
                 gather(ground_truth, input_index),
                 radius,
                 gt_boundary,
                 predicted_boundary);
  result.gt_boundary_points =
      static_cast<std::size_t>(std::count(gt_boundary.begin(), gt_boundary.end(), 1));
  result.predicted_boundary_points = static_cast<std::size_t>(
      std::count(predicted_boundary.begin(), predicted_boundary.end(), 1));
  result.matched_points =
      matchBoundaries(*valid, gt_boundary, predicted_boundary, match_distance);
  result.recall = ratio(result.matched_points, result.gt_boundary_points);
  return true;
}

bool
objectMetrics(const pcl::PointCloud<pcl::PointXYZ>& cloud,
              const std::vector<std::uint32_t>& predicted,
              const std::vector<std::uint32_t>& ground_truth,
              const ObjectMetricsParams& params,
              ObjectScores& scores)
{
  scores = ObjectScores{};
  if (!inUnitInterval(params.coverage_fraction) || !inUnitInterval(params.min_purity) ||
      !inUnitInterval(params.min_part_fraction)) {
    PCL_ERROR("[pcl::selective_seg::metrics::objectMetrics] coverage fraction %g, "
              "min purity %g and min part fraction %g must be in (0, 1]\n",
              params.coverage_fraction,
              params.min_purity,
              params.min_part_fraction);
    return false;
  }
  LabelOverlap overlap;
  BoundaryRecall boundary;
  if (!boundaryRecall(cloud,
                      predicted,
                      ground_truth,
                      params.boundary_radius,
                      params.boundary_match_distance,
                      boundary) ||
      !buildLabelOverlap(predicted, ground_truth, overlap))
    return false;
  scores.num_gt_regions = overlap.gt_labels.size();
  scores.num_predicted_regions = overlap.predicted_labels.size();
  scores.unlabeled_fraction =
      ratio(overlap.num_unlabeled_points, overlap.num_valid_points);
  scores.under_segmentation = underSegmentationError(overlap);
  scores.boundary = boundary;
  scores.coverage = segmentsCovering(overlap, params.coverage_fraction);
  scores.parts = recoverableParts(overlap, params.min_purity, params.min_part_fraction);
  return true;
}

namespace {

/** The checks of labelBoundaryPoints() and describeBoundaryPoints(). */
bool
checkBoundaryInputs(const char* function,
                    const pcl::PointCloud<pcl::PointXYZ>& cloud,
                    const std::vector<std::array<pcl::index_t, 3>>& triangles,
                    const std::vector<std::uint32_t>& labels,
                    const Eigen::Vector3f& sensor_origin,
                    double max_edge_angle)
{
  const std::size_t n = cloud.size();
  if (labels.size() != n) {
    PCL_ERROR(
        "[pcl::selective_seg::metrics::%s] points (%zu) and labels (%zu) differ\n",
        function,
        n,
        labels.size());
    return false;
  }
  if (!(max_edge_angle > 0.0) || !sensor_origin.allFinite()) {
    PCL_ERROR("[pcl::selective_seg::metrics::%s] max edge angle %g must be > 0 [rad] "
              "and the sensor origin finite\n",
              function,
              max_edge_angle);
    return false;
  }
  for (const auto& t : triangles)
    for (const auto v : t)
      if (v < 0 || static_cast<std::size_t>(v) >= n) {
        PCL_ERROR("[pcl::selective_seg::metrics::%s] triangle vertex %d out of range "
                  "[0, %zu)\n",
                  function,
                  static_cast<int>(v),
                  n);
        return false;
      }
  return true;
}

/** Call f(nearer, farther) for every boundary edge of labelBoundaryPoints(), once per
 * triangle side (an inner edge twice). Inputs checked by checkBoundaryInputs(). */
template <typename F>
void
forEachBoundaryEdge(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                    const std::vector<std::array<pcl::index_t, 3>>& triangles,
                    const std::vector<std::uint32_t>& labels,
                    const Eigen::Vector3f& sensor_origin,
                    double max_edge_angle,
                    F&& f)
{
  const double cos_max = max_edge_angle >= M_PI ? -2.0 : std::cos(max_edge_angle);
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      const pcl::index_t a = t[k];
      const pcl::index_t b = t[(k + 1) % 3];
      if (labels[a] == labels[b])
        continue;
      const Eigen::Vector3d ra =
          (cloud[a].getVector3fMap() - sensor_origin).cast<double>();
      const Eigen::Vector3d rb =
          (cloud[b].getVector3fMap() - sensor_origin).cast<double>();
      if (!ra.allFinite() || !rb.allFinite())
        continue;
      const double na = ra.norm();
      const double nb = rb.norm();
      if (!(na > 0.0 && nb > 0.0) || ra.dot(rb) < cos_max * na * nb)
        continue;
      const bool a_nearer = na < nb || (na == nb && a < b);
      f(a_nearer ? a : b, a_nearer ? b : a);
    }
}

} // namespace

bool
labelBoundaryPoints(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                    const std::vector<std::array<pcl::index_t, 3>>& triangles,
                    const std::vector<std::uint32_t>& labels,
                    const Eigen::Vector3f& sensor_origin,
                    double max_edge_angle,
                    pcl::Indices& boundary)
{
  boundary.clear();
  const std::size_t n = cloud.size();
  if (!checkBoundaryInputs("labelBoundaryPoints",
                           cloud,
                           triangles,
                           labels,
                           sensor_origin,
                           max_edge_angle))
    return false;
  std::vector<char> is_boundary(n, 0);
  forEachBoundaryEdge(
      cloud,
      triangles,
      labels,
      sensor_origin,
      max_edge_angle,
      [&](pcl::index_t nearer, pcl::index_t) { is_boundary[nearer] = 1; });
  for (std::size_t i = 0; i < n; ++i)
    if (is_boundary[i])
      boundary.push_back(static_cast<pcl::index_t>(i));
  return true;
}

bool
describeBoundaryPoints(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                       const std::vector<std::array<pcl::index_t, 3>>& triangles,
                       const std::vector<std::uint32_t>& labels,
                       const Eigen::Vector3f& sensor_origin,
                       double max_edge_angle,
                       double max_view_incidence_angle,
                       const pcl::Indices& boundary,
                       std::vector<BoundaryEdgeKind>& kinds)
{
  kinds.clear();
  const std::size_t n = cloud.size();
  if (!checkBoundaryInputs("describeBoundaryPoints",
                           cloud,
                           triangles,
                           labels,
                           sensor_origin,
                           max_edge_angle))
    return false;
  if (!(max_view_incidence_angle > 0.0 && max_view_incidence_angle <= M_PI / 2)) {
    PCL_ERROR("[pcl::selective_seg::metrics::describeBoundaryPoints] view incidence "
              "angle %g must be in (0, pi/2] [rad]\n",
              max_view_incidence_angle);
    return false;
  }
  std::vector<std::size_t> slot(n, std::numeric_limits<std::size_t>::max());
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    const pcl::index_t i = boundary[k];
    if (i < 0 || static_cast<std::size_t>(i) >= n) {
      PCL_ERROR("[pcl::selective_seg::metrics::describeBoundaryPoints] boundary point "
                "%d out of range [0, %zu)\n",
                static_cast<int>(i),
                n);
      return false;
    }
    slot[i] = k;
  }
  // Sensor-facing, area-weighted normal of every triangle with finite corners.
  std::vector<Eigen::Vector3d> normal(triangles.size(), Eigen::Vector3d::Zero());
  std::vector<std::size_t> first(n + 1, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3d p0 = cloud[triangles[t][0]].getVector3fMap().cast<double>();
    const Eigen::Vector3d p1 = cloud[triangles[t][1]].getVector3fMap().cast<double>();
    const Eigen::Vector3d p2 = cloud[triangles[t][2]].getVector3fMap().cast<double>();
    Eigen::Vector3d m = (p1 - p0).cross(p2 - p0);
    if (!m.allFinite() || m.isZero())
      continue; // no side normal from a degenerate triangle
    if (m.dot(sensor_origin.cast<double>() - (p0 + p1 + p2) / 3.0) < 0.0)
      m = -m;
    normal[t] = m;
    for (const auto v : triangles[t])
      ++first[v + 1];
  }
  for (std::size_t i = 0; i < n; ++i)
    first[i + 1] += first[i];
  std::vector<std::size_t> incident(first[n]);
  {
    std::vector<std::size_t> next(first.begin(), first.end() - 1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      if (!normal[t].isZero())
        for (const auto v : triangles[t])
          incident[next[v]++] = t;
  }
  // Normal of the surface of v's own label at v; zero when no triangle has it at
  // all three corners.
  const auto sideNormal = [&](pcl::index_t v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = first[v]; k < first[v + 1]; ++k) {
      const auto& t = triangles[incident[k]];
      if (labels[t[0]] == labels[v] && labels[t[1]] == labels[v] &&
          labels[t[2]] == labels[v])
        sum += normal[incident[k]];
    }
    return sum;
  };
  const double sin_jump = std::sin(M_PI / 2 - max_view_incidence_angle);
  kinds.assign(boundary.size(), BoundaryEdgeKind());
  forEachBoundaryEdge(
      cloud,
      triangles,
      labels,
      sensor_origin,
      max_edge_angle,
      [&](pcl::index_t nearer, pcl::index_t farther) {
        if (slot[nearer] == std::numeric_limits<std::size_t>::max())
          return;
        BoundaryEdgeKind& kind = kinds[slot[nearer]];
        const Eigen::Vector3d a = cloud[nearer].getVector3fMap().cast<double>();
        const Eigen::Vector3d b = cloud[farther].getVector3fMap().cast<double>();
        const Eigen::Vector3d edge = b - a;
        const Eigen::Vector3d sight = (a + b) / 2.0 - sensor_origin.cast<double>();
        // Angle between the edge and the line of sight below 90 deg - incidence:
        // |edge x sight| < sin(90 deg - incidence) |edge| |sight|.
        if (edge.cross(sight).norm() < sin_jump * edge.norm() * sight.norm()) {
          kind.depth_jump = true;
          return;
        }
        const Eigen::Vector3d na = sideNormal(nearer);
        const Eigen::Vector3d nb = sideNormal(farther);
        if (na.isZero() || nb.isZero())
          return;
        const float angle =
            static_cast<float>(std::atan2(na.cross(nb).norm(), na.dot(nb)));
        if (std::isnan(kind.crease_angle) || angle > kind.crease_angle)
          kind.crease_angle = angle;
      });
  // A point listed more than once was described at its last place: copy that.
  for (std::size_t k = 0; k < boundary.size(); ++k)
    kinds[k] = kinds[slot[boundary[k]]];
  return true;
}

void
boundaryDistances(const pcl::PointCloud<pcl::PointXYZ>& from,
                  const pcl::PointCloud<pcl::PointXYZ>& to,
                  BoundaryDistances& result,
                  std::vector<float>* per_point)
{
  result = BoundaryDistances{};
  if (per_point)
    per_point->assign(from.size(), std::numeric_limits<float>::quiet_NaN());
  auto targets = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : to)
    if (measurable(p))
      targets->push_back(p);
  result.num_to = targets->size();
  std::vector<double> distances;
  distances.reserve(from.size());
  if (!targets->empty()) {
    pcl::search::KdTree<pcl::PointXYZ> tree;
    tree.setInputCloud(targets);
    pcl::Indices index(1);
    std::vector<float> sqr(1);
    for (std::size_t i = 0; i < from.size(); ++i) {
      const auto& p = from[i];
      if (!measurable(p) || tree.nearestKSearch(p, 1, index, sqr) != 1)
        continue;
      distances.push_back(((*targets)[index[0]].getVector3fMap() - p.getVector3fMap())
                              .cast<double>()
                              .norm());
      if (per_point)
        (*per_point)[i] = static_cast<float>(distances.back());
    }
  } else
    for (const auto& p : from)
      if (measurable(p))
        distances.push_back(kNaN);
  result.num_from = distances.size();
  if (distances.empty() || targets->empty()) {
    result.mean = result.median = result.p90 = result.max = kNaN;
    return;
  }
  std::sort(distances.begin(), distances.end());
  const auto rank = [&](double q) {
    const auto k = static_cast<std::size_t>(
        std::ceil(q * static_cast<double>(distances.size()) - 1e-9));
    return distances[std::min(distances.size(), std::max<std::size_t>(k, 1)) - 1];
  };
  result.mean = std::accumulate(distances.begin(), distances.end(), 0.0) /
                static_cast<double>(distances.size());
  result.median = rank(0.5);
  result.p90 = rank(0.9);
  result.max = distances.back();
}

} // namespace metrics
} // namespace selective_seg
} // namespace pcl
