/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/parameters.h>
#include <pcl_selective_seg/regions_of_interest.h>
#include <pcl_selective_seg/segmentation_metrics.h>
#include <pcl_selective_seg/sensor_simulator.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <functional>
#include <string>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace simulation {

/** \brief Ground-truth boundary points of a scene for boundary accuracy: the boundary
 * points (metrics::labelBoundaryPoints()) of the ground-truth labels over the
 * spherical Delaunay mesh of a very dense, noise-free scan. */
struct PCL_EXPORTS ReferenceBoundary {
  pcl::PointCloud<pcl::PointXYZ> points; ///< the boundary points [m]
  /** The true edge each point lies on (metrics::describeBoundaryPoints() with the
   * segmentation's default max_view_incidence_angle, 85 deg), in the order of points.
   */
  std::vector<metrics::BoundaryEdgeKind> kinds;
  std::size_t scan_points = 0;           ///< points of the reference scan
  double step = 0.0;                     ///< its angular step [rad]
};

/** \brief Scan the sensor's view window at \a step without range noise and extract the
 * ground-truth boundary points; mesh edges longer than 4 steps (across holes) are left
 * out.
 * \return false (with PCL_ERROR) when the scan or the triangulation fails. */
PCL_EXPORTS bool makeReferenceBoundary(const SimulationSetup& setup,
                                       double step,
                                       ReferenceBoundary& reference);

/** \brief The scores of one segmented scan against the ground truth. */
struct PCL_EXPORTS ScanScore {
  std::size_t points = 0;         ///< points acquired so far
  /// Windows scanned in the step that led to this score: 1 for the coarse scan (the
  /// whole view), then the windows the round before scanned (0 when it fitted none).
  std::size_t windows = 0;
  double scanned_solid_angle = 0; ///< solid angle scanned so far, overlaps counted [sr]
  double seconds = 0.0; ///< computing time so far: segmentation, update, ROI [s]
  std::size_t segments = 0;
  /** Ground-truth boundary points to the nearest predicted boundary point: boundary
   * accuracy (mean, median, p90). */
  metrics::BoundaryDistances accuracy;
  /** The distance of every reference boundary point [m] (ReferenceBoundary order). */
  std::vector<float> reference_distances;
  /** Predicted boundary points to the nearest ground-truth boundary point (spurious
   * boundaries). */
  metrics::BoundaryDistances spurious;
  metrics::HooverScores hoover;    ///< at T = 0.8
  double under_segmentation = 0.0; ///< metrics::underSegmentationError
};

/** \brief Score a segmentation of a labeled scan: the labels and the triangles (over
 * point indices) of \a result, ground truth from the cloud's labels.
 * \param[in] cloud the scan, each point labeled with the surface it hit
 * \param[in] result the segmentation of \a cloud
 * \param[in] reference the scene's ground-truth boundary (makeReferenceBoundary())
 * \param[in] max_edge_angle predicted boundary edges subtending more are left out
 *            [rad]
 * \param[out] score the figures; points, windows and times are left as they are */
PCL_EXPORTS bool scoreSegmentation(const pcl::PointCloud<pcl::PointXYZL>& cloud,
                                   const SegmentationResult& result,
                                   const ReferenceBoundary& reference,
                                   double max_edge_angle,
                                   ScanScore& score);

/** \brief The loop's regions of interest: the library defaults, with half a spacing
 * of margin (the default of one spacing is for a single finer look without follow-up
 * rounds), and as transition evidence every edge triangle, valid or invalid, between
 * two surfaces: seen edge-on (a depth jump, 85 deg: the segmentation's
 * max_view_incidence_angle), or between segments whose normals differ by more than the
 * segmentation's merge angle (25 deg) plus their 95% cones of confidence
 * (side_confidence), whatever the triangle's class; sparse areas
 * relative to the median spacing over the view's area, which the refined windows do
 * not shift (docs/selective_sensing.md measures each choice). */
PCL_EXPORTS RegionOfInterestParameters loopRegionParameters();

/** \brief Parameters of the simulated coarse-to-fine loop. */
struct PCL_EXPORTS SelectiveLoopParameters {
  /** \brief Angular step of the finest scans: the target step of the last round's
   * regions of interest [rad], > 0. */
  double fine_step = 0.004;
  /** \brief The coarse scan's step is this many times fine_step, >= 1. */
  double coarse_factor = 3.0;
  /** \brief Refinement rounds (ROI, scan, update), in [0, 2000]. A round whose share
   * of the budget fits no window scans nothing and leaves its share to the next. */
  int iterations = 3;
  /** \brief Each round a step finer: round r of n targets coarse_step x (fine_step /
   * coarse_step)^(r / n), the last fine_step (a round confirms and narrows the
   * transitions the previous one found). false: every round targets fine_step. */
  bool progressive = true;
  /** \brief Points the whole loop may acquire, the coarse scan included, > 0 (a coarse
   * scan with more points fails the loop); each round may use the remaining budget
   * divided by the remaining rounds. */
  std::size_t point_budget = 10000;
  /** \brief Finest octree voxel: this many times fine_step times the coarse scan's
   * median range [m] (the automatic size of a scan at fine_step); 0: the automatic
   * size of the coarse scan, which update() then keeps. */
  double min_voxel_factor = 2.0;
  /** \brief Predicted boundary edges longer than this many coarse steps are left out
   * of boundary accuracy (edges across holes). */
  double boundary_edge_steps = 4.0;
  /** \brief Evidence tiles (RegionOfInterestParameters::max_window_size) of this
   * many coarse steps (one: each window wraps the evidence at the resolution the
   * coarse scan knows it; docs/selective_sensing.md); 0: keep
   * regions.max_window_size. */
  double window_steps = 1.0;
  SelectiveSegmentationParameters segmentation;
  /** \brief The regions of interest; target_step, max_points and sample_yield are set
   * by the loop (the yield from the coarse scan, then the points all windows scanned
   * so far returned over their candidate rays). The windows are clipped to the
   * sensor's view before they are scanned, their estimates scaled to what is left. */
  RegionOfInterestParameters regions = loopRegionParameters();
};

/** \brief One round of the loop, as reported to the observer. */
struct LoopRound {
  int iteration = 0;                                      ///< 0 = the coarse scan
  const pcl::PointCloud<pcl::PointXYZL>* cloud = nullptr; ///< everything acquired
  const SegmentationResult* result = nullptr;             ///< its segmentation
  /** The windows chosen after this round and scanned for the next one (those of
   * computeRegionsOfInterest() that the points acquired so far left room for). */
  const std::vector<RegionOfInterest>* regions = nullptr;
  RegionOfInterestStats region_stats; ///< of computeRegionsOfInterest() this round
  /** The parameters computeRegionsOfInterest() ran with this round: the loop's
   * regions with the round's step, point budget, yield and window size (the loop's
   * regions as given when it did not run: the last round, or no budget left). */
  RegionOfInterestParameters region_parameters;
  ScanScore score;
};

/** \brief Coarse scan, segment, regions of interest under the point budget, finer scans
 * of them, SelectiveSegmentation::update(), repeated.
 * \param[in] setup the scene and sensor (view window, noise, seed)
 * \param[in] params the loop
 * \param[in] reference ground-truth boundaries (makeReferenceBoundary())
 * \param[out] rounds one score per round, the coarse scan first
 * \param[in] observer if set, called after every round (pictures, files)
 * \return false (with PCL_ERROR) on invalid parameters or a failed stage. */
PCL_EXPORTS bool
runSelectiveLoop(const SimulationSetup& setup,
                 const SelectiveLoopParameters& params,
                 const ReferenceBoundary& reference,
                 std::vector<ScanScore>& rounds,
                 const std::function<void(const LoopRound&)>& observer = {});

/** \brief A uniform scan of the whole view window at \a step, segmented and scored
 * (boundary edges up to 4 steps).
 * \param[in] setup the scene and its sensor
 * \param[in] step the scan's angular step [rad]
 * \param[in] segmentation the segmentation's parameters
 * \param[in] reference the scene's ground-truth boundary (makeReferenceBoundary())
 * \param[out] score the figures of the scan and its segmentation
 * \param[out] cloud if non-null: the scan */
PCL_EXPORTS bool runUniformScan(const SimulationSetup& setup,
                                double step,
                                const SelectiveSegmentationParameters& segmentation,
                                const ReferenceBoundary& reference,
                                ScanScore& score,
                                pcl::PointCloud<pcl::PointXYZL>* cloud = nullptr);

} // namespace simulation
} // namespace selective_seg
} // namespace pcl
