/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <Eigen/Core>
#include <pcl/pcl_macros.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace pcl {
namespace selective_seg {
/** \brief Scores of a segmentation against per-point ground truth.
 *
 * Common conventions of every function here:
 * - inputs are two label vectors of one entry per point and equal length: the
 *   predicted labels (0 = unlabeled: the point belongs to no predicted region) and the
 *   ground-truth labels (0 = invalid: the point is ignored by every metric);
 * - a "region" or "segment" is the set of GT-valid points sharing one nonzero label;
 *   its size counts GT-valid points only, so a predicted region lying entirely on
 *   GT-invalid points does not exist for the metrics;
 * - label values are arbitrary (they need not be consecutive); regions are handled in
 *   increasing label order, so every result depends on the labelling only;
 * - a fraction compared with a threshold ("at least T of P points") is tested as
 *   count >= T * P - 1e-9 * P, so that a threshold such as 0.8 accepts exactly 8 of 10
 *   points whatever the rounding of 0.8 (the margin is below one point for any cloud
 *   of fewer than 10^9 points);
 * - a ratio with a zero denominator is NaN.
 */
namespace metrics {

/** \brief Largest coordinate magnitude of a point the distance-based metrics use [m]:
 * their nearest-neighbour searches compare squared distances in float, which overflow
 * beyond about 1.8e19 m. Points beyond it are skipped like non-finite ones. */
constexpr float kMaxMetricCoordinate = 1e18f;

/** \brief One nonzero entry O_mn of the overlap table. */
struct OverlapEntry {
  std::size_t gt = 0;        ///< index of the GT region in LabelOverlap::gt_labels
  std::size_t predicted = 0; ///< index of the region in LabelOverlap::predicted_labels
  std::size_t count = 0;     ///< O_mn: GT-valid points in both regions (> 0)
};

/** \brief Sparse overlap (contingency) table of a predicted and a GT labelling. */
struct LabelOverlap {
  /** \#G distinct nonzero GT labels, increasing. */
  std::vector<std::uint32_t> gt_labels;
  /** \#G points of each GT region (P_n). */
  std::vector<std::size_t> gt_sizes;
  /** \#M distinct nonzero predicted labels found on GT-valid points, increasing. */
  std::vector<std::uint32_t> predicted_labels;
  /** \#M GT-valid points of each predicted region (P_m). */
  std::vector<std::size_t> predicted_sizes;
  /** Nonzero overlaps, sorted by (gt, predicted); their counts sum to
   * num_valid_points - num_unlabeled_points. */
  std::vector<OverlapEntry> entries;
  /** Points with a nonzero GT label. */
  std::size_t num_valid_points = 0;
  /** GT-valid points with predicted label 0. */
  std::size_t num_unlabeled_points = 0;
};

/** \brief Build the overlap table of two labellings.
 * \param[in] predicted \#N predicted labels, 0 = unlabeled
 * \param[in] ground_truth \#N GT labels, 0 = invalid (ignored)
 * \param[out] overlap the table; cleared on failure
 * \return false (with PCL_ERROR) when the two vectors differ in length
 */
PCL_EXPORTS bool buildLabelOverlap(const std::vector<std::uint32_t>& predicted,
                                   const std::vector<std::uint32_t>& ground_truth,
                                   LabelOverlap& overlap);

/** \brief Counts of Hoover et al. (1996) at one tolerance T.
 *
 * \note A. Hoover et al., "An experimental comparison of range image segmentation
 * algorithms", IEEE PAMI 18(7), 1996, Sec. 3. With P_m (P_n) the size of predicted
 * (GT) region m (n) and O_mn their overlap, all in GT-valid points:
 * - correct detection: a pair (m, n) with O_mn >= T P_m and O_mn >= T P_n;
 * - over-segmentation: a GT region n with a set of x >= 2 predicted regions m_i such
 *   that O_{m_i n} >= T P_{m_i} for every i and sum_i O_{m_i n} >= T P_n;
 * - under-segmentation: a predicted region m with a set of x >= 2 GT regions n_i such
 *   that O_{m n_i} >= T P_{n_i} for every i and sum_i O_{m n_i} >= T P_m;
 * - missed: a GT region that takes part in no instance above;
 * - noise: a predicted region that takes part in no instance above.
 *
 * No tie-breaking is needed. The predicted regions that can join an
 * over-segmentation of n are exactly those with O_mn >= T P_m, and taking all of them
 * maximises the sum; so n is over-segmented iff it has at least two of them and they
 * hold >= T P_n together, and it then counts as one instance made of all of them.
 * Under-segmentation is the mirror image, one instance per predicted region. For
 * T > 0.5 a region has at least T of its points in at most one region of the other
 * labelling, so it takes part in at most one instance of each type. As in the paper,
 * instances of different types may share a region and each is counted: a fragment of
 * at most (1 - T) P_n points inside a correctly detected GT region n makes n also an
 * over-segmentation (and the fragment is not noise); a small GT region inside a
 * correct detection likewise adds an under-segmentation. At T = 0.5 a region split
 * exactly in half meets the correct-detection test with both halves; every pair that
 * meets it is counted.
 */
struct HooverScores {
  double tolerance = 0.8;                ///< T, in [0.5, 1]
  std::size_t num_gt_regions = 0;        ///< \#G
  std::size_t num_predicted_regions = 0; ///< \#M (regions with a GT-valid point)
  std::size_t correct_detections = 0;    ///< pairs (m, n)
  std::size_t over_segmentations = 0;    ///< GT regions over-segmented
  std::size_t under_segmentations = 0;   ///< predicted regions under-segmenting
  std::size_t missed = 0;                ///< GT regions in no instance
  std::size_t noise = 0;                 ///< predicted regions in no instance
};

/** \brief Hoover counts of a built overlap table (see HooverScores).
 * \param[in] overlap the table, from buildLabelOverlap()
 * \param[in] tolerance T, in [0.5, 1]; the caller checks the range
 */
PCL_EXPORTS HooverScores hooverScores(const LabelOverlap& overlap, double tolerance);

/** \brief Hoover counts of two labellings at one tolerance (see HooverScores).
 * \param[in] predicted \#N predicted labels, 0 = unlabeled
 * \param[in] ground_truth \#N GT labels, 0 = invalid (ignored)
 * \param[in] tolerance T, in [0.5, 1] (the paper's range; 0.8 in its tables)
 * \param[out] scores the counts; zero on failure
 * \return false (with PCL_ERROR) on a length mismatch or T out of range
 */
PCL_EXPORTS bool hooverMetrics(const std::vector<std::uint32_t>& predicted,
                               const std::vector<std::uint32_t>& ground_truth,
                               double tolerance,
                               HooverScores& scores);

/** \brief Hoover counts over a range of tolerances (the paper's plots over T).
 *
 * Tolerances are min_tolerance + i * step for i = 0, 1, ... while they do not exceed
 * max_tolerance by more than step / 1000 (so 0.5..0.95 by 0.05 gives 10 values, the
 * last 0.95), at most 100,000 of them. The overlap table is built once.
 *
 * \param[in] predicted \#N predicted labels, 0 = unlabeled
 * \param[in] ground_truth \#N GT labels, 0 = invalid (ignored)
 * \param[out] sweep one HooverScores per tolerance, increasing; empty on failure
 * \param[in] min_tolerance first T, in [0.5, 1]
 * \param[in] max_tolerance last T, in [min_tolerance, 1]
 * \param[in] step increment of T, finite and > 0
 * \return false (with PCL_ERROR) on a length mismatch, a bad range, or a step that
 *         would make more than 100,000 tolerances
 */
PCL_EXPORTS bool hooverSweep(const std::vector<std::uint32_t>& predicted,
                             const std::vector<std::uint32_t>& ground_truth,
                             std::vector<HooverScores>& sweep,
                             double min_tolerance = 0.5,
                             double max_tolerance = 0.95,
                             double step = 0.05);

/** \brief Majority GT region of each predicted region.
 *
 * The GT region holding most of the region's points; on a tie the smallest GT label.
 */
struct MajorityLabel {
  std::size_t gt = 0;    ///< index in LabelOverlap::gt_labels
  std::size_t count = 0; ///< points of the region in that GT region
  double purity = 0.0;   ///< count / P_m, in (0, 1]
};

/** \brief \#M majority GT regions, one per LabelOverlap::predicted_labels entry. */
PCL_EXPORTS std::vector<MajorityLabel> majorityLabels(const LabelOverlap& overlap);

/** \brief Under-segmentation error of object-level segmentation. */
struct UnderSegmentationError {
  std::size_t valid_points = 0;  ///< GT-valid points (the denominator)
  std::size_t leaked_points = 0; ///< of those, in a region whose majority is not theirs
  double error = 0.0;            ///< leaked_points / valid_points, NaN when none valid
};

/** \brief Fraction of the GT-valid points lying in a predicted region whose majority
 * GT label (MajorityLabel) is not theirs.
 *
 * Points predicted 0 lie in no region and never leak, but stay in the denominator
 * (they are measured by LabelOverlap::num_unlabeled_points).
 */
PCL_EXPORTS UnderSegmentationError underSegmentationError(const LabelOverlap& overlap);

/** \brief How many predicted regions, largest first, cover a fraction of the points. */
struct SegmentCoverage {
  double fraction = 0.9;    ///< the target fraction of GT-valid points
  std::size_t segments = 0; ///< regions needed; all \#M when the target is not reached
  bool reached = false;     ///< false when all regions together fall short
  double covered_fraction = 0; ///< fraction covered by those regions, NaN when no point
};

/** \brief Smallest number of predicted regions, taken largest first (ties: smaller
 * label first), whose GT-valid points reach at least \a fraction of all GT-valid
 * points (unlabeled points included, so they can keep the target out of reach).
 * \param[in] overlap the table, from buildLabelOverlap()
 * \param[in] fraction target, in (0, 1]
 */
PCL_EXPORTS SegmentCoverage segmentsCovering(const LabelOverlap& overlap,
                                             double fraction = 0.9);

/** \brief Parts recoverable as a union of pure predicted regions. */
struct PartRecovery {
  std::size_t num_parts = 0;         ///< GT regions (\#G)
  std::size_t recoverable_parts = 0; ///< parts meeting the criterion
  double fraction = 0.0; ///< recoverable_parts / num_parts, NaN when \#G = 0
};

/** \brief Fraction of GT parts recoverable from pure predicted regions.
 *
 * A part n is recoverable when the predicted regions whose majority GT region
 * (MajorityLabel) is n and whose purity is at least \a min_purity together hold at
 * least \a min_part_fraction of the part's points. Pure regions of n that are
 * smaller than n still count: the part is recovered by their union.
 *
 * \param[in] overlap the table, from buildLabelOverlap()
 * \param[in] min_purity smallest purity of a usable region, in (0, 1] (0.8)
 * \param[in] min_part_fraction fraction f of the part that the union must cover,
 *            in (0, 1] (0.8)
 */
PCL_EXPORTS PartRecovery recoverableParts(const LabelOverlap& overlap,
                                          double min_purity = 0.8,
                                          double min_part_fraction = 0.8);

/** \brief Boundary recall and the boundary point counts behind it. */
struct BoundaryRecall {
  std::size_t gt_boundary_points = 0;        ///< GT boundary points (the denominator)
  std::size_t predicted_boundary_points = 0; ///< predicted boundary points
  std::size_t matched_points = 0; ///< GT boundary points near a predicted one
  double recall = 0.0; ///< matched_points / gt_boundary_points, NaN when none
};

/** \brief Recall of the GT object boundaries by the predicted region boundaries.
 *
 * Only GT-valid points with finite coordinates, none beyond kMaxMetricCoordinate, take
 * part (GT-invalid points neither
 * make nor break a boundary). Neighbours are the points closer than \a radius
 * (pcl::search::KdTree radius search, strict).
 * - GT boundary point: a point with a neighbour of another GT label.
 * - Predicted boundary point: a point with a nonzero predicted label and a neighbour
 *   whose predicted label differs (0 included: a region ends at unlabeled points,
 *   but unlabeled points themselves are never boundary points, so an empty
 *   prediction recalls nothing).
 * - A GT boundary point is matched when a predicted boundary point lies within
 *   \a match_distance of it (inclusive).
 *
 * \param[in] cloud \#N points [m]
 * \param[in] predicted \#N predicted labels, 0 = unlabeled
 * \param[in] ground_truth \#N GT labels, 0 = invalid (ignored)
 * \param[in] radius neighbourhood radius r of both boundaries [m], > 0
 * \param[in] match_distance largest GT-to-predicted boundary distance d [m], >= 0;
 *            distances are those of the stored float coordinates (two points 0.01 apart
 *            on a 0.01 grid may be 0.0100000016 apart)
 * \param[out] result counts and recall; zero on failure
 * \return false (with PCL_ERROR) on a size mismatch or a bad distance
 */
PCL_EXPORTS bool boundaryRecall(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                const std::vector<std::uint32_t>& predicted,
                                const std::vector<std::uint32_t>& ground_truth,
                                double radius,
                                double match_distance,
                                BoundaryRecall& result);

/** \brief Parameters of objectMetrics(). Distances depend on the sampling density:
 * the defaults suit RGB-D frames at about 1 m (1-2 mm point spacing). */
struct ObjectMetricsParams {
  double boundary_radius = 0.01;         ///< r of boundaryRecall() [m]
  double boundary_match_distance = 0.01; ///< d of boundaryRecall() [m]
  double coverage_fraction = 0.9;        ///< fraction of segmentsCovering()
  double min_purity = 0.8;               ///< min_purity of recoverableParts()
  double min_part_fraction = 0.8;        ///< min_part_fraction of recoverableParts()
};

/** \brief All object-level metrics of one labelling. */
struct ObjectScores {
  std::size_t num_gt_regions = 0;        ///< \#G
  std::size_t num_predicted_regions = 0; ///< \#M
  double unlabeled_fraction = 0.0; ///< GT-valid points predicted 0, NaN when none valid
  UnderSegmentationError under_segmentation;
  BoundaryRecall boundary;
  SegmentCoverage coverage;
  PartRecovery parts;
};

/** \brief Object-level metrics, for ground truth with one label per whole object.
 * \param[in] cloud \#N points [m]
 * \param[in] predicted \#N predicted labels, 0 = unlabeled
 * \param[in] ground_truth \#N GT labels, 0 = invalid (ignored)
 * \param[in] params distances and fractions
 * \param[out] scores the metrics; zero on failure
 * \return false (with PCL_ERROR) on a size mismatch or a parameter out of range
 */
PCL_EXPORTS bool objectMetrics(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                               const std::vector<std::uint32_t>& predicted,
                               const std::vector<std::uint32_t>& ground_truth,
                               const ObjectMetricsParams& params,
                               ObjectScores& scores);

/** \brief The boundary points of a labelling of a triangulated scan.
 *
 * A boundary edge is a mesh edge (a side of a triangle) whose two end points both have
 * finite coordinates, have different labels, at least one of them nonzero, and subtend
 * at most \a max_edge_angle at the sensor (the angle between the two rays from
 * \a sensor_origin; this leaves out the long edges across holes and sparse regions;
 * an edge with an end point at the sensor origin has no such angle and is left out).
 * Its boundary point is the end point nearer to the sensor (on a tie the smaller
 * index): at a depth jump that is the point on the occluding contour, at a crease a
 * point on one of the two faces. The result lists each boundary point once.
 *
 * \param[in] cloud \#N points [m]
 * \param[in] triangles mesh triangles over point indices in [0, N)
 * \param[in] labels \#N labels (predicted or ground truth)
 * \param[in] sensor_origin the sensor's position in the cloud's frame [m]
 * \param[in] max_edge_angle largest angle an edge subtends at the sensor [rad], > 0
 *            (infinity: every edge)
 * \param[out] boundary indices of the boundary points, increasing; empty on failure
 * \return false (with PCL_ERROR) on a size mismatch, an index out of range or a bad
 *         angle
 */
PCL_EXPORTS bool
labelBoundaryPoints(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                    const std::vector<std::array<pcl::index_t, 3>>& triangles,
                    const std::vector<std::uint32_t>& labels,
                    const Eigen::Vector3f& sensor_origin,
                    double max_edge_angle,
                    pcl::Indices& boundary);

/** \brief The kind of true edge a boundary point lies on (describeBoundaryPoints()). */
struct BoundaryEdgeKind {
  /** At least one of the point's boundary edges is seen edge-on: a depth jump. */
  bool depth_jump = false;
  /** The largest angle between the surface normals on the two sides of the point's
   * other boundary edges [rad]: 0 on a smooth (C1) border between two labels, the
   * dihedral angle's complement on a crease (90 deg between two faces of a box). NaN
   * when no such edge has triangles of its own label on both sides. */
  float crease_angle = std::numeric_limits<float>::quiet_NaN();
};

/** \brief Describe the boundary points of labelBoundaryPoints() by the edges they lie
 * on: depth jump or crease, and how sharp the crease is.
 *
 * The boundary edges of a point are those of labelBoundaryPoints() whose nearer end
 * point it is. An edge is a depth jump when the angle between it and the line of sight
 * to its midpoint is less than 90 deg - \a max_view_incidence_angle (seen edge-on).
 * Otherwise the normal of each side is the sum of the (area-weighted, sensor-facing)
 * normals of the triangles at that end point whose three corners carry its label, and
 * the crease angle is the angle between the two sides' normals. Meant for dense,
 * noise-free reference scans with ground-truth labels (simulation): on them the
 * triangle normals are the surfaces' normals.
 *
 * \param[in] cloud, triangles, labels, sensor_origin, max_edge_angle as for
 *            labelBoundaryPoints()
 * \param[in] max_view_incidence_angle edges closer than 90 deg minus this to the line
 *            of sight are depth jumps [rad], in (0, pi/2]
 * \param[in] boundary the boundary points (labelBoundaryPoints() of the same input)
 * \param[out] kinds one per boundary point, in its order (a point listed twice is
 *             described twice, the same way); empty on failure
 * \return false (with PCL_ERROR) on the inputs labelBoundaryPoints() refuses, a bad
 *         incidence angle or a boundary index out of range
 */
PCL_EXPORTS bool
describeBoundaryPoints(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                       const std::vector<std::array<pcl::index_t, 3>>& triangles,
                       const std::vector<std::uint32_t>& labels,
                       const Eigen::Vector3f& sensor_origin,
                       double max_edge_angle,
                       double max_view_incidence_angle,
                       const pcl::Indices& boundary,
                       std::vector<BoundaryEdgeKind>& kinds);

/** \brief Distances from one set of boundary points to the nearest point of another. */
struct BoundaryDistances {
  std::size_t num_from = 0; ///< points measured (the "from" set)
  std::size_t num_to = 0;   ///< points of the "to" set
  double mean = 0.0;        ///< mean distance [m]; NaN when a set is empty
  double median = 0.0;      ///< 50th percentile [m] (nearest rank); NaN likewise
  double p90 = 0.0;         ///< 90th percentile [m] (nearest rank); NaN likewise
  double max = 0.0;         ///< largest distance [m]; NaN likewise
};

/** \brief For every point of \a from, the Euclidean distance to the nearest point of
 * \a to; their mean, median, 90th percentile and maximum.
 *
 * Boundary accuracy (docs/selective_sensing.md) is this with \a from the ground-truth
 * boundary points of a very dense reference scan and \a to the predicted boundary
 * points (labelBoundaryPoints() of both): how far each true edge lies from the nearest
 * segment boundary. The reverse direction measures spurious boundaries.
 * Percentiles use the nearest rank: the value at position ceil(q n) of the sorted
 * distances.
 * \param[in] from points to measure [m]; non-finite points, and points with a
 *            coordinate beyond kMaxMetricCoordinate, are skipped
 * \param[in] to points to measure to [m]; skipped likewise
 * \param[out] result the statistics
 * \param[out] per_point if non-null: the distance of every point of \a from, in its
 *             order (NaN for skipped points or an empty \a to)
 */
PCL_EXPORTS void boundaryDistances(const pcl::PointCloud<pcl::PointXYZ>& from,
                                   const pcl::PointCloud<pcl::PointXYZ>& to,
                                   BoundaryDistances& result,
                                   std::vector<float>* per_point = nullptr);

} // namespace metrics
} // namespace selective_seg
} // namespace pcl
