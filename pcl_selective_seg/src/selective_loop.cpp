/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/selective_loop.h>
#include <pcl_selective_seg/selective_segmentation.h>
#include <pcl_selective_seg/spherical_delaunay.h>

#include <pcl/common/time.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>

namespace pcl {
namespace selective_seg {
namespace simulation {

namespace {

/** Scan ids: the reference, the uniform scans and the loop draw different rays. */
constexpr std::uint32_t kReferenceScan = 0x7fffffffu;
constexpr std::uint32_t kUniformScan = 1;
constexpr std::uint32_t kCoarseScan = 2;
/** Window k of round r is scan (r + 1) * 2^20 + k: distinct for fewer than 2^20
 * windows a round (the loop scans no more) and kMaxIterations rounds, and below
 * kReferenceScan. */
constexpr int kRoundScanBits = 20;
constexpr std::size_t kMaxWindowsPerRound = std::size_t{1} << kRoundScanBits;
constexpr int kMaxIterations = 2000;
static_assert((std::uint64_t{kMaxIterations + 1} << kRoundScanBits) +
                      kMaxWindowsPerRound <
                  kReferenceScan,
              "round scan ids must stay below the reference scan's");

/** The part of a window inside the sensor's view, its solid angle and point estimate
 * scaled to that part; false when nothing of it is inside. */
bool
clipToView(const SensorParameters& view, RegionOfInterest& r)
{
  const double before = r.solid_angle;
  r.theta_min = std::max(r.theta_min, view.theta_min);
  r.theta_max = std::min(r.theta_max, view.theta_max);
  r.phi_min = std::max(r.phi_min, view.phi_min);
  r.phi_max = std::min(r.phi_max, view.phi_max);
  if (!(r.theta_min < r.theta_max && r.phi_min < r.phi_max))
    return false;
  r.solid_angle = windowSolidAngle(r.theta_min, r.theta_max, r.phi_min, r.phi_max);
  if (before > 0.0 && r.solid_angle < before)
    r.estimated_points = static_cast<std::size_t>(
        std::ceil(static_cast<double>(r.estimated_points) * r.solid_angle / before));
  return true;
}

ScanWindow
viewOf(const SensorParameters& sensor, double step, std::uint32_t scan_id)
{
  ScanWindow w;
  w.theta_min = sensor.theta_min;
  w.theta_max = sensor.theta_max;
  w.phi_min = sensor.phi_min;
  w.phi_max = sensor.phi_max;
  w.step = step;
  w.scan_id = scan_id;
  return w;
}

pcl::PointCloud<pcl::PointXYZ>
toXYZ(const pcl::PointCloud<pcl::PointXYZL>& in)
{
  pcl::PointCloud<pcl::PointXYZ> out;
  out.resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i)
    out[i].getVector3fMap() = in[i].getVector3fMap();
  return out;
}

std::vector<std::uint32_t>
labelsOf(const pcl::PointCloud<pcl::PointXYZL>& in)
{
  std::vector<std::uint32_t> labels(in.size());
  for (std::size_t i = 0; i < in.size(); ++i)
    labels[i] = in[i].label;
  return labels;
}

bool
fail(const char* what)
{
  PCL_ERROR("[pcl::selective_seg::simulation::runSelectiveLoop] %s\n", what);
  return false;
}

} // namespace

RegionOfInterestParameters
loopRegionParameters()
{
  RegionOfInterestParameters p;
  p.margin_spacings = 0.5;
  p.use_valid_edges = true;
  p.use_edge_on = true;
  p.edge_on_angle = 85.0 * M_PI / 180.0;
  p.min_side_angle = 25.0 * M_PI / 180.0;
  p.side_confidence = 0.95;
  p.sparse_by_area = true;
  return p;
}

bool
makeReferenceBoundary(const SimulationSetup& setup,
                      double step,
                      ReferenceBoundary& reference)
{
  reference = ReferenceBoundary();
  SensorParameters sensor = setup.sensor;
  sensor.range_noise = 0.0;
  SensorSimulator simulator;
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  if (!simulator.setParameters(sensor) ||
      !simulator.simulateWindow(
          setup.scene, viewOf(sensor, step, kReferenceScan), *cloud))
    return false;
  SphericalDelaunay<pcl::PointXYZL> delaunay;
  delaunay.setInputCloud(cloud);
  if (!delaunay.triangulate())
    return false;
  const auto& tri = delaunay.getTriangulation();
  std::vector<std::array<pcl::index_t, 3>> triangles(tri.triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      triangles[t][k] = tri.vertex_point[tri.triangles[t][k]];
  pcl::Indices boundary;
  const auto xyz = toXYZ(*cloud);
  if (!metrics::labelBoundaryPoints(xyz,
                                    triangles,
                                    labelsOf(*cloud),
                                    Eigen::Vector3f::Zero(),
                                    4.0 * step,
                                    boundary))
    return false;
  if (!metrics::describeBoundaryPoints(
          xyz,
          triangles,
          labelsOf(*cloud),
          Eigen::Vector3f::Zero(),
          4.0 * step,
          SelectiveSegmentationParameters().max_view_incidence_angle,
          boundary,
          reference.kinds))
    return false;
  for (const auto i : boundary)
    reference.points.push_back(xyz[i]);
  reference.scan_points = cloud->size();
  reference.step = step;
  return true;
}

bool
scoreSegmentation(const pcl::PointCloud<pcl::PointXYZL>& cloud,
                  const SegmentationResult& result,
                  const ReferenceBoundary& reference,
                  double max_edge_angle,
                  ScanScore& score)
{
  const auto xyz = toXYZ(cloud);
  const auto truth = labelsOf(cloud);
  pcl::Indices boundary;
  if (!metrics::labelBoundaryPoints(xyz,
                                    result.mesh.triangles,
                                    result.labels,
                                    Eigen::Vector3f::Zero(),
                                    max_edge_angle,
                                    boundary))
    return false;
  pcl::PointCloud<pcl::PointXYZ> predicted;
  for (const auto i : boundary)
    predicted.push_back(xyz[i]);
  metrics::boundaryDistances(
      reference.points, predicted, score.accuracy, &score.reference_distances);
  metrics::boundaryDistances(predicted, reference.points, score.spurious);
  metrics::LabelOverlap overlap;
  if (!metrics::buildLabelOverlap(result.labels, truth, overlap))
    return false;
  score.hoover = metrics::hooverScores(overlap, 0.8);
  score.under_segmentation = metrics::underSegmentationError(overlap).error;
  score.segments = result.segments.size();
  return true;
}

namespace {

/** The score's acquisition figures after one scan of the whole view. */
void
startScore(const SensorParameters& view,
           std::size_t points,
           double seconds,
           ScanScore& score)
{
  score.points = points;
  score.windows = 1;
  score.scanned_solid_angle =
      windowSolidAngle(view.theta_min, view.theta_max, view.phi_min, view.phi_max);
  score.seconds = seconds;
}

} // namespace

bool
runUniformScan(const SimulationSetup& setup,
               double step,
               const SelectiveSegmentationParameters& segmentation,
               const ReferenceBoundary& reference,
               ScanScore& score,
               pcl::PointCloud<pcl::PointXYZL>* out)
{
  score = ScanScore();
  SensorSimulator simulator;
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  if (!simulator.setParameters(setup.sensor) ||
      !simulator.simulateWindow(
          setup.scene, viewOf(setup.sensor, step, kUniformScan), *cloud))
    return false;
  SelectiveSegmentation<pcl::PointXYZL> seg;
  seg.setParameters(segmentation);
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  if (!seg.extract(clusters))
    return false;
  startScore(setup.sensor, cloud->size(), seg.getResult().timings.total, score);
  if (out)
    *out = *cloud;
  return scoreSegmentation(*cloud, seg.getResult(), reference, 4.0 * step, score);
}

bool
runSelectiveLoop(const SimulationSetup& setup,
                 const SelectiveLoopParameters& params,
                 const ReferenceBoundary& reference,
                 std::vector<ScanScore>& rounds,
                 const std::function<void(const LoopRound&)>& observer)
{
  rounds.clear();
  if (!(params.fine_step > 0.0) || !std::isfinite(params.fine_step) ||
      !(params.coarse_factor >= 1.0) || !std::isfinite(params.coarse_factor) ||
      params.iterations < 0 || params.iterations > kMaxIterations ||
      params.point_budget == 0 || !(params.min_voxel_factor >= 0.0) ||
      !(params.boundary_edge_steps > 0.0) || !(params.window_steps >= 0.0) ||
      !std::isfinite(params.window_steps))
    return fail("invalid parameters: need fine_step > 0 [rad], coarse_factor >= 1, "
                "0 <= iterations <= 2000, point_budget > 0, min_voxel_factor >= 0, "
                "boundary_edge_steps > 0, window_steps >= 0");
  SensorSimulator simulator;
  if (!simulator.setParameters(setup.sensor))
    return fail("invalid sensor parameters (reason above)");
  const double coarse_step = params.coarse_factor * params.fine_step;
  const double edge_angle = params.boundary_edge_steps * coarse_step;
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  SimulationDetails details;
  if (!simulator.simulateWindow(setup.scene,
                                viewOf(setup.sensor, coarse_step, kCoarseScan),
                                *cloud,
                                &details))
    return fail("the coarse scan failed (reason above)");
  if (cloud->empty())
    return fail("the coarse scan has no point");
  if (cloud->size() > params.point_budget) {
    PCL_ERROR(
        "[pcl::selective_seg::simulation::runSelectiveLoop] the coarse scan's %zu "
        "points exceed the point budget of %zu, which includes them: give a "
        "larger budget or a larger coarse_factor\n",
        cloud->size(),
        params.point_budget);
    return false;
  }
  // Points per candidate ray: from the coarse scan, then from every window scanned so
  // far (their points over their estimates at yield 1).
  double yield =
      std::clamp(static_cast<double>(cloud->size()) /
                     static_cast<double>(std::max<std::size_t>(details.candidates, 1)),
                 1e-3,
                 1.0);
  double window_points = 0.0;
  double window_candidates = 0.0;

  SelectiveSegmentation<pcl::PointXYZL> seg;
  seg.setParameters(params.segmentation);
  if (params.min_voxel_factor > 0.0) {
    std::vector<float> ranges;
    for (const auto& p : *cloud)
      ranges.push_back(p.getVector3fMap().norm());
    std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
    seg.setMinVoxelSize(params.min_voxel_factor * params.fine_step *
                        ranges[ranges.size() / 2]);
  }
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  if (!seg.extract(clusters))
    return fail("segmenting the coarse scan failed (reason above)");

  ScanScore score;
  startScore(setup.sensor, cloud->size(), seg.getResult().timings.total, score);
  std::vector<RegionOfInterest> regions;
  RegionOfInterestStats stats;
  for (int round = 0;; ++round) {
    if (!scoreSegmentation(*cloud, seg.getResult(), reference, edge_angle, score))
      return fail("scoring failed (reason above)");
    regions.clear();
    stats = RegionOfInterestStats();
    RegionOfInterestParameters roi = params.regions;
    if (round < params.iterations && score.points < params.point_budget) {
      // Progressive: round r + 1 of n refines to coarse x (fine / coarse)^((r + 1) /
      // n).
      roi.target_step =
          params.progressive
              ? coarse_step * std::pow(params.fine_step / coarse_step,
                                       double(round + 1) / double(params.iterations))
              : params.fine_step;
      if (params.window_steps > 0.0)
        roi.max_window_size = std::min(M_PI, params.window_steps * coarse_step);
      roi.min_window_size = std::min(roi.min_window_size, roi.max_window_size);
      roi.sample_yield = yield;
      roi.num_threads = params.segmentation.num_threads;
      roi.max_points = std::max<std::size_t>(
          1,
          (params.point_budget - score.points) /
              static_cast<std::size_t>(params.iterations - round));
      pcl::StopWatch watch;
      Eigen::Affine3f pose = Eigen::Affine3f::Identity();
      if (!computeRegionsOfInterest(
              seg.getResult(), seg.getTriangulation(), pose, roi, regions, &stats))
        return fail("computing the regions of interest failed (reason above)");
      score.seconds += watch.getTimeSeconds();
    }
    // Windows in priority order, clipped to the sensor's view (a window's margins may
    // reach past it, where the uniform scans see nothing), while the points actually
    // acquired leave room for the window's estimate (at least one point): the budget
    // holds up to one window's estimation error.
    pcl::PointCloud<pcl::PointXYZL> fresh;
    std::vector<RegionOfInterest> scanned;
    double solid_angle = 0.0;
    double estimated = 0.0;
    for (std::size_t k = 0; k < regions.size() && scanned.size() < kMaxWindowsPerRound;
         ++k) {
      RegionOfInterest r = regions[k];
      if (!clipToView(setup.sensor, r))
        continue;
      r.estimated_points = std::max<std::size_t>(r.estimated_points, 1);
      const std::size_t acquired = cloud->size() + fresh.size();
      if (acquired + r.estimated_points > params.point_budget)
        continue;
      const std::size_t index = scanned.size();
      scanned.push_back(r);
      estimated += static_cast<double>(r.estimated_points);
      ScanWindow w;
      w.theta_min = r.theta_min;
      w.theta_max = r.theta_max;
      w.phi_min = r.phi_min;
      w.phi_max = r.phi_max;
      w.step = r.suggested_step;
      w.scan_id = static_cast<std::uint32_t>(
          (static_cast<std::uint64_t>(round + 1) << kRoundScanBits) + index);
      pcl::PointCloud<pcl::PointXYZL> part;
      if (!simulator.simulateWindow(setup.scene, w, part))
        return fail("a window scan failed (reason above)");
      fresh += part;
      solid_angle += r.solid_angle;
    }
    const bool no_candidates = regions.empty();
    regions = scanned;
    rounds.push_back(score);
    if (observer) {
      LoopRound r;
      r.iteration = round;
      r.cloud = cloud.get();
      r.result = &seg.getResult();
      r.regions = &regions;
      r.region_stats = stats;
      r.region_parameters = roi;
      r.score = score;
      observer(r);
    }
    score.windows = scanned.size(); // the next score's step (none when it is empty)
    if (scanned.empty()) {
      // Nothing to refine, or the last round: done. Otherwise this round's share of
      // the budget fitted no window; the next round's share is larger.
      if (no_candidates || round >= params.iterations)
        break;
      continue;
    }
    score.scanned_solid_angle += solid_angle;
    window_points += static_cast<double>(fresh.size());
    window_candidates += estimated / yield;
    yield = std::clamp(window_points / window_candidates, 1e-3, 1.0);
    fresh.width = static_cast<std::uint32_t>(fresh.size());
    fresh.height = 1;
    if (!seg.update(fresh, clusters))
      return fail("update() failed (reason above)");
    // update() appends the new points to the input: keep the same union with labels.
    auto merged = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>(*cloud);
    *merged += fresh;
    cloud = merged;
    score.points = cloud->size();
    score.seconds += seg.getResult().timings.total;
  }
  return true;
}

} // namespace simulation
} // namespace selective_seg
} // namespace pcl
