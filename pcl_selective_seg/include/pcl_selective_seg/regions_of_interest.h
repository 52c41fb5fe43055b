/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/segmentation_result.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <Eigen/Geometry>
#include <pcl/pcl_macros.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl {
namespace selective_seg {

/** \brief Why a region of interest was proposed (bit flags of
 * RegionOfInterest::reasons). */
enum RegionReason : std::uint8_t {
  /** Transition region: vertices of invalid edge triangles (eq. 8) or of finest-size
   * octree leaves whose normals still spread more than the split threshold. */
  kTransition = 1,
  /** A segment with few points: a small object or a part the coarse scan resolves
   * badly. */
  kSmallSegment = 2,
  /** Sparsely sampled area: vertices whose angular spacing is well above the scan's
   * median; vertices of both other kinds that are sparse count as sparse only. */
  kSparse = 4
};

/** \brief "transition", "small_segment", "sparse", joined by '+' for several. */
PCL_EXPORTS std::string reasonsToString(std::uint8_t reasons);

/** \brief Parameters of computeRegionsOfInterest(). Angles in radians. */
struct PCL_EXPORTS RegionOfInterestParameters {
  // --- what counts as evidence ---
  /** \brief Invalid edge triangles are transition evidence. */
  bool use_invalid_edges = true;
  /** \brief Valid edge triangles (segment borders the surface continues across) are
   * transition evidence too (with use_invalid_edges). */
  bool use_valid_edges = false;
  /** \brief Triangles seen edge-on (more than edge_on_angle between their normal and
   * the line of sight: a depth discontinuity) are transition evidence whatever their
   * class, with transition_weight: two surfaces at different depths whose normals
   * agree can share a coarse octree leaf and so one segment (a box's top face before
   * the floor behind it), and then give no edge triangle. */
  bool use_edge_on = false;
  /** \brief Edge triangles (invalid, and valid with use_valid_edges) are evidence only
   * where the segmentation sees two different surfaces: the triangle is seen edge-on
   * (more than edge_on_angle between its normal and the line of sight: a depth
   * discontinuity), or the normals of the segments of its corners differ by more than
   * this angle [rad] (a crease by the merge criterion: the segmentation's
   * max_merge_angle, 25 deg by default, is the natural value), or a corner has no
   * segment. Edge triangles between segments whose normals agree are splits by range
   * noise, not transitions. 0: every edge triangle is evidence. Valid: [0, pi]. */
  double min_side_angle = 0.0;
  /** \brief With min_side_angle > 0: the normals of two segments tell two surfaces
   * apart only when both segments hold at least this many points. The borders of
   * smaller segments, often fragments that range noise cut out of one surface, are
   * then no transition evidence unless seen edge-on (the small segments remain
   * small-segment evidence, small_segment_points). It trades small true parts for
   * noise fragments: docs/selective_sensing.md measures both. 0: off. */
  std::size_t min_side_points = 0;
  /** \brief With min_side_angle > 0 and a value in (0, 1): two segments are two
   * surfaces by their normals only when the angle between them exceeds
   * min_side_angle by more than the uncertainty of that angle, sqrt(a_i^2 + a_j^2),
   * where a is the cone of confidence at this level of a segment's mean normal
   * (fisherConfidenceAngle() over the unit normals of its interior triangles). A
   * segment a few noisy triangles wide, whose normal differs from its neighbour's
   * only by chance, then makes no transition evidence; one with fewer than two
   * interior triangles never does by its normal (edge-on triangles and corners
   * without a segment still count). 0: off, the plain comparison. Valid: [0, 1). */
  double side_confidence = 0.0;
  /** \brief See use_edge_on and min_side_angle [rad]; the segmentation's
   * max_view_incidence_angle (85 deg by default) is the natural value. Valid: (0,
   * pi/2]. */
  double edge_on_angle = 85.0 * M_PI / 180.0;
  /** \brief Finest-size octree leaves (the smallest leaf size of the result) whose
   * sigma_theta or sigma_phi exceeds this are transition evidence [rad]; the
   * segmentation's split threshold (max_normal_std_dev, 7.6 deg by default) is the
   * natural value. 0 or less: leaves are not used. Valid: finite. */
  double leaf_sigma_threshold = 7.6 * M_PI / 180.0;
  /** \brief Segments with fewer points than this are small-segment evidence; 0: off.
   */
  std::size_t small_segment_points = 30;
  /** \brief Vertices whose angular spacing exceeds this many times the median vertex
   * spacing of the scan are sparse evidence; 0: off. Valid: 0 or >= 1. */
  double sparse_factor = 2.0;
  /** \brief The scan's typical spacing for sparse_factor: false, the median over the
   * vertices; true, the median over the view's area (each vertex weighted by its
   * spacing squared), which a few finely rescanned windows do not shift: with the
   * vertex median, a scan refined in places calls every coarse vertex sparse. */
  bool sparse_by_area = false;

  /** \brief Evidence of one kind in mesh-connected groups of fewer vertices is
   * ignored (isolated noise). Valid: >= 1. */
  std::size_t min_component_vertices = 3;

  // --- windows ---
  /** \brief Evidence is split into tiles of at most this size in each angle before
   * windows are made (a long diagonal edge becomes a staircase of small windows rather
   * than one large one), and two windows merge only into one that fits it [rad]. The
   * margins come on top: a window can exceed it by twice its margin. Windows that
   * overlap without meeting the merge rule are cut apart (disjoint_windows). Valid:
   * [1e-9, pi]. */
  double max_window_size = 0.05;
  /** \brief Windows smaller than this in an angle are widened to it, about their
   * centre, moved inside the view (or, for a part of a cut window, the part) where it
   * leaves room [rad]. Valid: [0, max_window_size]. */
  double min_window_size = 0.0;
  /** \brief Margin added around the evidence [rad], besides margin_spacings.
   * Valid: >= 0, finite. */
  double margin = 0.0;
  /** \brief Margin added around the evidence in units of its current angular spacing
   * (the true edge lies anywhere between the coarse samples). Valid: >= 0, finite. */
  double margin_spacings = 1.0;
  /** \brief Two overlapping (or edge-sharing) windows merge when their bounding window
   * is at most this many times the area they cover together (and fits max_window_size):
   * overlaps are removed where that wastes little. Valid: >= 1, finite. */
  double merge_area_ratio = 1.25;
  /** \brief The selected windows overlap nowhere (they may share borders), so that a
   * finer scan of them casts no ray twice and the budget counts each part of the view
   * once. Candidates are taken in priority order; one that overlaps a window taken
   * before it is cut into the parts of it left and right of that window (over its
   * whole height) and below and above it (over their common width). Each part keeps
   * the evidence inside it (evidence inside the window taken is that window's), is
   * fitted again to it and to the evidence whose margin reaches into it, plus
   * margins, within the part (a margin that the window taken does not cover stays
   * covered), evaluated again (steps, priority, estimates, box) and offered again. A
   * part that only margins reach has priority 0 and the spacing of the evidence
   * beside it, and is dropped when narrower than its suggested step; parts already
   * fine are dropped too. The parts respect min_window_size where the part leaves
   * room. false: windows that do not merge may overlap, and the budget counts an
   * overlap once for each window that holds it. */
  bool disjoint_windows = true;

  // --- sampling ---
  /** \brief Suggested angular step of the finer scan [rad]; 0: each window's current
   * spacing divided by refinement_factor. Valid: >= 0, finite. */
  double target_step = 0.0;
  /** \brief Refinement of the step when target_step is 0. Valid: > 1, finite. */
  double refinement_factor = 3.0;
  /** \brief Windows whose current spacing is below this many times the suggested step
   * are already fine enough and dropped; with a target_step, so is every evidence
   * vertex whose own spacing is below this many target steps (a region already
   * scanned finely proposes no window). Valid: >= 1, finite. */
  double min_refinement = 1.5;

  // --- priority ---
  /** \brief Weight of transition evidence from invalid edge triangles, >= 0. */
  double transition_weight = 1.0;
  /** \brief Weight of transition evidence from finest octree leaves only, >= 0. */
  double leaf_weight = 0.7;
  /** \brief Weight of transition evidence from valid edge triangles only, >= 0. */
  double valid_edge_weight = 0.5;
  double small_segment_weight = 0.6; ///< weight of small-segment evidence, >= 0
  double sparse_weight = 0.3;        ///< weight of sparse evidence, >= 0

  // --- budget (0 = no limit) ---
  /** \brief Largest total solid angle of the selected windows [sr]. Valid: >= 0. */
  double max_solid_angle = 0.0;
  /** \brief Largest total of estimated_points of the selected windows. */
  std::size_t max_points = 0;
  /** \brief Largest number of selected windows. */
  std::size_t max_regions = 0;
  /** \brief Density model: the fraction of the rays of a scan at the suggested step
   * that returns a point (texture, dropouts, misses). Valid: (0, 1]. */
  double sample_yield = 1.0;

  /** \brief Threads for the passes over vertices, triangles and candidate windows;
   * 0 = automatic (defaultThreads()). The regions are identical for any value. Valid:
   * [0, 1024]. */
  int num_threads = 0;

  /** \brief Check every parameter.
   * \param[out] why when invalid and non-null: the parameter, its value and its
   *             valid range.
   * \return true when all parameters are valid. */
  bool validate(std::string* why = nullptr) const;
};

/** \brief A region of the view worth a finer acquisition. */
struct RegionOfInterest {
  /** Angular window in the sensor frame [rad], in the angles of the triangulation's
   * projection: eq. 1's theta = atan2(x, z), phi = atan2(y, z), or with the panoramic
   * projection azimuth theta = atan2(x, z) in [-pi, pi] and elevation phi = atan2(y,
   * sqrt(x^2 + z^2)). A panoramic window does not cross the seam at theta = +-pi:
   * evidence on both sides gives a window on each side. */
  double theta_min = 0.0;
  double theta_max = 0.0;
  double phi_min = 0.0;
  double phi_max = 0.0;
  /** Axis-aligned box, in the cloud frame, of the mesh vertices whose angles lie in the
   * window [m]: each vertex's representative point (the nearest to the sensor among
   * the points sharing its ray; farther points on that ray are not in the box), within
   * float rounding (the positions pass through the sensor frame). An empty box (min >
   * max) when no vertex lies in the window. */
  Eigen::Vector3f box_min = Eigen::Vector3f::Zero();
  Eigen::Vector3f box_max = Eigen::Vector3f::Zero();
  /** The weighted share of the window's area that its evidence stands for (each
   * evidence vertex for its spacing squared: sum of weight x spacing^2 over
   * max(window area, sum of spacing^2)) times the share of new samples a scan at the
   * suggested step brings, 1 - suggested_step / current_step; in [0, largest
   * weight]. */
  double priority = 0.0;
  double suggested_step = 0.0;  ///< angular step of the finer scan [rad]
  double current_step = 0.0;    ///< median angular spacing of its evidence now [rad]
  std::uint8_t reasons = 0;     ///< RegionReason bits
  std::size_t num_evidence = 0; ///< evidence vertices inside
  std::size_t num_points = 0;   ///< mesh vertices of the scan inside the window
  std::size_t estimated_points = 0; ///< sample_yield x window area / step^2
  double solid_angle = 0.0;         ///< of the window [sr]
  /** The mapping of theta and phi (the triangulation's). */
  ViewProjection projection = ViewProjection::Forward;
};

/** \brief What computeRegionsOfInterest() found. */
struct RegionOfInterestStats {
  /** Vertices with evidence of each kind, counted before groups smaller than
   * min_component_vertices are ignored. */
  std::size_t transition_vertices = 0;
  std::size_t small_segment_vertices = 0; ///< (as transition_vertices)
  std::size_t sparse_vertices = 0;        ///< (as transition_vertices)
  std::size_t candidates = 0;             ///< windows after merging
  /** Candidates cut around a window selected before them (disjoint_windows). */
  std::size_t cut = 0;
  /** Parts of cut candidates dropped because they hold no evidence of their own (only
   * the margins of evidence beside them reach them) and are narrower than their
   * suggested step. */
  std::size_t thin_parts = 0;
  /** Candidates (windows after merging, and parts of cut ones) dropped by
   * min_refinement. */
  std::size_t already_fine = 0;
  std::size_t over_budget = 0;       ///< candidates (and parts) left out by the budget
  std::size_t selected = 0;          ///< windows returned
  double selected_solid_angle = 0.0; ///< [sr]
  std::size_t selected_points = 0;   ///< sum of estimated_points
};

/** \brief Solid angle of an angular window [sr]: of eq. 1's angles a rectangle on the
 * plane z = 1 (exact; below 1e-4 rad a side, where the exact formula's terms cancel,
 * its area times the density at its centre, within 1e-8 relative); of the panoramic
 * azimuth and elevation (theta_max - theta_min)(sin phi_max - sin phi_min). */
PCL_EXPORTS double
windowSolidAngle(double theta_min,
                 double theta_max,
                 double phi_min,
                 double phi_max,
                 ViewProjection projection = ViewProjection::Forward);

/** \brief Semi-angle of the cone of confidence of the mean of \a n unit vectors
 * whose sum has length \a resultant (Fisher, 1953): the true mean direction lies
 * within it with probability \a confidence, cos a = 1 - (n - R) / R ((1 / (1 -
 * confidence))^(1 / (n - 1)) - 1). Returns pi when it is not defined (n < 2, R <= 0,
 * or the cosine below -1) [rad]. \a confidence in (0, 1). */
PCL_EXPORTS double
fisherConfidenceAngle(std::size_t n, double resultant, double confidence);

/** \brief Regions of interest of a segmentation for a finer acquisition.
 *
 * Evidence vertices (RegionReason) are grouped by kind into mesh-connected components,
 * each component is cut into tiles of max_window_size from its smallest angles, each
 * tile gives a window (its vertices' angles plus margins), overlapping windows merge
 * (merge_area_ratio), windows already sampled at about the suggested step are dropped,
 * and the budget picks windows greedily by priority; with disjoint_windows a window
 * that overlaps one picked before it is cut around it first. Output order: the order
 * the budget took them, priority decreasing (among equal priorities theta_min,
 * phi_min, theta_max, phi_max increasing, of the candidates queued at the time), so
 * that a budget of k regions gives the first k of an unlimited run. The result depends
 * on the segmentation only.
 *
 * \param[in] result the segmentation (labels, mesh classes, leaves)
 * \param[in] triangulation its triangulation
 * (SelectiveSegmentation::getTriangulation()) \param[in] sensor_to_cloud the sensor
 * pose used by the segmentation \param[in] params the parameters \param[out] regions
 * the selected windows; empty on failure \param[out] stats if non-null: counts of
 * evidence and windows \return false (with PCL_ERROR saying why) on invalid parameters,
 * a result that does not belong to the triangulation, or when memory runs out
 * (std::bad_alloc is caught, on every thread). An empty scan gives no region.
 * With a panoramic triangulation the windows are rectangles of azimuth and elevation;
 * angle steps across the seam are taken the short way round.
 */
PCL_EXPORTS bool computeRegionsOfInterest(const SegmentationResult& result,
                                          const SphericalTriangulation& triangulation,
                                          const Eigen::Affine3f& sensor_to_cloud,
                                          const RegionOfInterestParameters& params,
                                          std::vector<RegionOfInterest>& regions,
                                          RegionOfInterestStats* stats = nullptr);

/** \brief The same for a SelectiveSegmentation after a successful extract() or
 * update(), with the sensor pose of that run (SelectiveSegmentation::getSensorPose():
 * setSensorPose()'s, or the input cloud's sensor_origin_ / sensor_orientation_). */
template <typename Segmentation>
bool
computeRegionsOfInterest(const Segmentation& seg,
                         const RegionOfInterestParameters& params,
                         std::vector<RegionOfInterest>& regions,
                         RegionOfInterestStats* stats = nullptr)
{
  return computeRegionsOfInterest(seg.getResult(),
                                  seg.getTriangulation(),
                                  seg.getSensorPose(),
                                  params,
                                  regions,
                                  stats);
}

} // namespace selective_seg
} // namespace pcl
