/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// pcl_selective_seg_compare: run this project's segmentation and PCL's segmenters on
// the same ground-truth clouds, measure quality and run time, and print a markdown
// table.
//
// Inputs are PCD files with x y z and a ground-truth "label" field (0 = invalid), seen
// from the file's VIEWPOINT (the simulator's output and the mOSD frames: the origin,
// looking along +z).
// Exit codes: 0 = success, 1 = runtime error, 2 = usage error.

#include <pcl_selective_seg/segmentation_metrics.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <pcl/common/point_tests.h>
#include <pcl/common/time.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/features/normal_3d.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/lccp_segmentation.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/region_growing.h>
#include <pcl/segmentation/supervoxel_clustering.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "outputs.h"
#include "process_memory.h"
#include "scan_io.h"
#include "segmentation_options.h"

using namespace pcl::console;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Labels = std::vector<std::uint32_t>;

namespace {

constexpr int kRuntimeError = 1;
constexpr int kUsageError = 2;
constexpr double kDeg = M_PI / 180.0;

/** A method's labels (one per input point, 0 = none) and its run time. */
struct Run {
  Labels labels;
  double seconds = 0.0;
  bool ok = false;
};

struct Method {
  std::string name;
  std::function<Run(const Cloud::ConstPtr&)> run;
  bool organized_only = false;
};

Labels
fromClusters(std::size_t n, const std::vector<pcl::PointIndices>& clusters)
{
  Labels labels(n, 0);
  for (std::size_t c = 0; c < clusters.size(); ++c)
    for (const auto i : clusters[c].indices)
      labels[i] = static_cast<std::uint32_t>(c + 1);
  return labels;
}

Run
runSelective(const Cloud::ConstPtr& cloud,
             const pcl::selective_seg::SelectiveSegmentationParameters& params)
{
  Run r;
  pcl::StopWatch watch;
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(params);
  seg.setInputCloud(cloud); // the sensor pose: the file's VIEWPOINT
  std::vector<pcl::PointIndices> clusters;
  r.ok = seg.extract(clusters);
  r.seconds = watch.getTimeSeconds();
  r.labels = r.ok ? seg.getResult().labels : Labels(cloud->size(), 0);
  return r;
}

/** pcl::NormalEstimation (30 neighbours) + pcl::RegionGrowing (30 neighbours, 5 deg
 * smoothness, curvature 1.0, at least 50 points), the PCL tutorial's setup. */
Run
runRegionGrowing(const Cloud::ConstPtr& cloud)
{
  Run r;
  pcl::StopWatch watch;
  auto valid = pcl::make_shared<pcl::Indices>();
  for (pcl::index_t i = 0; i < static_cast<pcl::index_t>(cloud->size()); ++i)
    if (pcl::isFinite((*cloud)[i]))
      valid->push_back(i);
  auto tree = pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
  auto normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setSearchMethod(tree);
  ne.setInputCloud(cloud);
  ne.setIndices(valid);
  ne.setKSearch(30);
  ne.compute(*normals);
  // NormalEstimation with indices returns one normal per index: spread them back.
  auto full =
      pcl::make_shared<pcl::PointCloud<pcl::Normal>>(cloud->width, cloud->height);
  for (std::size_t k = 0; k < valid->size(); ++k)
    (*full)[(*valid)[k]] = (*normals)[k];
  pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> rg;
  rg.setMinClusterSize(50);
  rg.setSearchMethod(tree);
  rg.setNumberOfNeighbours(30);
  rg.setInputCloud(cloud);
  rg.setIndices(valid);
  rg.setInputNormals(full);
  rg.setSmoothnessThreshold(5.0 * kDeg);
  rg.setCurvatureThreshold(1.0);
  std::vector<pcl::PointIndices> clusters;
  rg.extract(clusters);
  r.seconds = watch.getTimeSeconds();
  r.labels = fromClusters(cloud->size(), clusters);
  r.ok = true;
  return r;
}

/** pcl::SupervoxelClustering (voxel 1 cm, seed 4 cm, spatial 1, normal 4, no colour)
 * + pcl::LCCPSegmentation (concavity 10 deg, smoothness and sanity checks), as in
 * PCL's LCCP example. */
Run
runLccp(const Cloud::ConstPtr& cloud)
{
  Run r;
  pcl::StopWatch watch;
  const float voxel = 0.01f, seed = 0.04f;
  // PCL's octree aborts (an assertion in getKeyBitSize) when the cloud spans too many
  // voxels: beyond 2^24 voxels (168 km) the method is reported as failed.
  Eigen::Array3f lo = Eigen::Array3f::Constant(std::numeric_limits<float>::max());
  Eigen::Array3f hi = -lo;
  for (const auto& p : *cloud)
    if (pcl::isFinite(p)) {
      lo = lo.min(p.getArray3fMap());
      hi = hi.max(p.getArray3fMap());
    }
  if (!((hi - lo).maxCoeff() / voxel < static_cast<float>(1 << 24))) {
    print_warn("Supervoxel+LCCP: the cloud spans more than 2^24 voxels of %g m; "
               "reported as failed.\n",
               voxel);
    return r;
  }
  pcl::SupervoxelClustering<pcl::PointXYZ> super(voxel, seed);
  super.setUseSingleCameraTransform(false);
  super.setInputCloud(cloud);
  super.setColorImportance(0.0f);
  super.setSpatialImportance(1.0f);
  super.setNormalImportance(4.0f);
  std::map<std::uint32_t, pcl::Supervoxel<pcl::PointXYZ>::Ptr> supervoxels;
  super.extract(supervoxels);
  std::multimap<std::uint32_t, std::uint32_t> adjacency;
  super.getSupervoxelAdjacency(adjacency);
  pcl::LCCPSegmentation<pcl::PointXYZ> lccp;
  lccp.setConcavityToleranceThreshold(10.0f);
  lccp.setSanityCheck(true);
  lccp.setSmoothnessCheck(true, voxel, seed, 0.1f);
  lccp.setKFactor(0);
  lccp.setInputSupervoxels(supervoxels, adjacency);
  lccp.setMinSegmentSize(0);
  lccp.segment();
  auto labeled = super.getLabeledCloud();
  lccp.relabelCloud(*labeled);
  r.seconds = watch.getTimeSeconds();
  r.labels.resize(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i)
    r.labels[i] = (*labeled)[i].label;
  r.ok = true;
  return r;
}

/** pcl::IntegralImageNormalEstimation (covariance, depth change 0.02, smoothing 10) +
 * pcl::OrganizedMultiPlaneSegmentation (1000 inliers, 3 deg, 2 cm), refined. */
Run
runMultiPlane(const Cloud::ConstPtr& cloud)
{
  Run r;
  // PCL's integral images read past a smaller image with this smoothing size (a
  // crash): such a cloud is reported as failed.
  constexpr std::uint32_t kMinSide = 20;
  if (cloud->width < kMinSide || cloud->height < kMinSide) {
    print_warn(
        "OrganizedMultiPlane: the cloud is %u x %u; at least %u x %u are needed; "
        "reported as failed.\n",
        cloud->width,
        cloud->height,
        kMinSide,
        kMinSide);
    return r;
  }
  pcl::StopWatch watch;
  auto normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setNormalEstimationMethod(ne.COVARIANCE_MATRIX);
  ne.setMaxDepthChangeFactor(0.02f);
  ne.setNormalSmoothingSize(10.0f);
  ne.setInputCloud(cloud);
  ne.compute(*normals);
  pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
  mps.setMinInliers(1000);
  mps.setAngularThreshold(3.0 * kDeg);
  mps.setDistanceThreshold(0.02);
  mps.setInputNormals(normals);
  mps.setInputCloud(cloud);
  std::vector<pcl::PlanarRegion<pcl::PointXYZ>,
              Eigen::aligned_allocator<pcl::PlanarRegion<pcl::PointXYZ>>>
      regions;
  std::vector<pcl::ModelCoefficients> coefficients;
  std::vector<pcl::PointIndices> inliers, label_indices, boundaries;
  auto plane_labels = pcl::make_shared<pcl::PointCloud<pcl::Label>>();
  mps.segmentAndRefine(
      regions, coefficients, inliers, plane_labels, label_indices, boundaries);
  r.seconds = watch.getTimeSeconds();
  r.labels = fromClusters(cloud->size(), inliers);
  r.ok = true;
  return r;
}

std::vector<Method>
methods()
{
  using pcl::selective_seg::EdgeTriangleNormal;
  using pcl::selective_seg::SelectiveSegmentationParameters;
  SelectiveSegmentationParameters paper;
  paper.max_view_incidence_angle = 90.0 * kDeg; // the literal paper
  const SelectiveSegmentationParameters defaults;
  SelectiveSegmentationParameters rings3 = defaults;
  rings3.normal_rings = 3;
  SelectiveSegmentationParameters robust2 = defaults;
  robust2.normal_rings = 2;
  robust2.edge_triangle_normal = EdgeTriangleNormal::VertexMean;
  SelectiveSegmentationParameters robust3 = robust2;
  robust3.normal_rings = 3;
  SelectiveSegmentationParameters mean_frame = defaults;
  mean_frame.normal_spread_frame = pcl::selective_seg::NormalSpreadFrame::MeanNormal;
  SelectiveSegmentationParameters area_weight = defaults;
  area_weight.segment_normal_weight = pcl::selective_seg::SegmentNormalWeight::Area;
  SelectiveSegmentationParameters not_edge_on = defaults;
  not_edge_on.point_normal_triangles =
      pcl::selective_seg::PointNormalTriangles::NotEdgeOn;
  SelectiveSegmentationParameters grown = defaults;
  grown.merge_with = pcl::selective_seg::MergeWith::Segments;
  const auto selective = [](const SelectiveSegmentationParameters& p) {
    return [p](const Cloud::ConstPtr& c) { return runSelective(c, p); };
  };
  return {{"selective (paper)", selective(paper)},
          {"selective (default)", selective(defaults)},
          {"selective (eq. 5 in the voxel's frame)", selective(mean_frame)},
          {"selective (eq. 7 weighted by area)", selective(area_weight)},
          {"selective (eq. 2 without edge-on triangles)", selective(not_edge_on)},
          {"selective (eq. 9-10 with grown segments)", selective(grown)},
          {"selective (rings 3)", selective(rings3)},
          {"selective (rings 2, vertex-mean eq. 8)", selective(robust2)},
          {"selective (rings 3, vertex-mean eq. 8)", selective(robust3)},
          {"RegionGrowing", runRegionGrowing},
          {"Supervoxel+LCCP", runLccp},
          {"OrganizedMultiPlane", runMultiPlane, true}};
}

std::string
row(const std::string& scene,
    const std::string& method,
    const Cloud& cloud,
    const Labels& truth,
    const Run& run)
{
  namespace m = pcl::selective_seg::metrics;
  if (!run.ok)
    return "| " + scene + " | " + method + " | failed ||||||||||||\n";
  m::HooverScores h;
  m::hooverMetrics(run.labels, truth, 0.8, h);
  std::vector<m::HooverScores> sweep;
  m::hooverSweep(run.labels, truth, sweep);
  std::string correct_by_tolerance;
  for (const auto& t : sweep)
    correct_by_tolerance += (correct_by_tolerance.empty() ? "" : " ") +
                            std::to_string(t.correct_detections);
  m::ObjectScores o;
  m::ObjectMetricsParams params;
  params.boundary_radius = params.boundary_match_distance = 0.02;
  m::objectMetrics(cloud, run.labels, truth, params, o);
  // A scene with one ground-truth region has no boundary to recall: "-", not nan.
  char recall[32] = "-";
  if (std::isfinite(o.boundary.recall))
    std::snprintf(recall, sizeof(recall), "%.2f", o.boundary.recall);
  char line[640];
  std::snprintf(line,
                sizeof(line),
                "| %s | %s | %.3f | %zu | %zu | %zu | %zu | %zu | %zu | %.2f%% | %s | "
                "%zu | %.2f | %s |\n",
                scene.c_str(),
                method.c_str(),
                run.seconds,
                h.num_predicted_regions,
                h.correct_detections,
                h.over_segmentations,
                h.under_segmentations,
                h.missed,
                h.noise,
                100.0 * o.under_segmentation.error,
                recall,
                o.coverage.segments,
                o.parts.fraction,
                correct_by_tolerance.c_str());
  return line;
}

const char* kHeader =
    "| scene | method | time (s) | segments | correct | over | under | missed | noise "
    "| under-seg. error | boundary recall | segments for 90% | recoverable parts "
    "| correct at T = 0.50, 0.55, ..., 0.95 |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";

bool
evaluate(const std::string& path, std::string& table)
{
  auto cloud = pcl::make_shared<Cloud>();
  Labels truth;
  std::string error;
  if (!selseg_apps::loadLabeledScan(path, *cloud, truth, error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  if (cloud->empty()) {
    print_error("'%s' holds no point.\n", path.c_str());
    return false;
  }
  std::size_t labeled = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (!pcl::isFinite((*cloud)[i]))
      truth[i] = 0; // a point without a position is in no region
    labeled += truth[i] != 0;
  }
  // (This also keeps PCL's segmenters, which crash on a cloud without a finite point,
  // from running on one.)
  if (labeled == 0) {
    print_error("'%s' has no ground-truth label on a finite point (every label is 0, "
                "the invalid label): give a cloud with its regions labeled 1, 2, ...\n",
                path.c_str());
    return false;
  }
  const std::string scene = path.substr(path.find_last_of('/') + 1);
  for (const auto& method : methods()) {
    if (method.organized_only && !cloud->isOrganized()) {
      print_warn("%s is left out for '%s': it needs an organized cloud (height > 1), "
                 "and this one is %u x %u.\n",
                 method.name.c_str(),
                 path.c_str(),
                 cloud->width,
                 cloud->height);
      continue;
    }
    const Run run = method.run(cloud);
    const std::string line = row(scene, method.name, *cloud, truth, run);
    std::fputs(line.c_str(), stdout);
    std::fflush(stdout);
    table += line;
  }
  return true;
}

struct Options {
  std::vector<std::string> inputs;
  std::string output;
};

/** \return 0 on success, else the exit code. */
int
parseOptions(int argc, char** argv, Options& opt)
{
  if (!selseg_apps::optionsGivenOnce(
          argc, argv, [](const std::string& arg) { return arg == "-o"; }))
    return kUsageError;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-o") {
      if (++i >= argc || argv[i][0] == '\0') {
        print_error("Option -o needs a file name (see -h).\n");
        return kUsageError;
      }
      opt.output = argv[i];
    } else if (arg.size() > 1 && arg[0] == '-') {
      print_error("Unknown option '%s' (see -h).\n", arg.c_str());
      return kUsageError;
    } else if (selseg_apps::lowerExtension(arg) != ".pcd") {
      print_error("'%s' is not a .pcd file: give PCD clouds with a label field (see "
                  "-h).\n",
                  arg.c_str());
      return kUsageError;
    } else
      opt.inputs.push_back(arg);
  }
  if (opt.inputs.empty()) {
    print_error("Give at least one CLOUD.pcd (see -h).\n");
    return kUsageError;
  }
  for (const auto& input : opt.inputs)
    if (!opt.output.empty() && selseg_apps::samePath(opt.output, input)) {
      print_error("Option -o names the input file '%s': give another output name.\n",
                  input.c_str());
      return kUsageError;
    }
  return 0;
}

/** The table, written under a temporary name and renamed into place when complete. */
bool
writeTable(const std::string& path, const std::string& table)
{
  selseg_apps::OutputTransaction output;
  std::ofstream out(output.stage(path), std::ios::binary);
  out << table;
  out.close();
  std::string error;
  if (!out) {
    print_error("Cannot write '%s': check that the folder exists, is writable and has "
                "free space.\n",
                path.c_str());
    return false;
  }
  if (!output.commit(error)) {
    print_error("%s\n", error.c_str());
    return false;
  }
  return true;
}

/** main() but for its handling of memory running out. */
int
run(int argc, char** argv)
{
  if (argc < 2 || find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help")) {
    print_info("Compare segmenters on ground-truth clouds.\n\n"
               "Usage: %s CLOUD.pcd [CLOUD.pcd ...] [-o TABLE.md]\n"
               "  CLOUD.pcd  x y z label (ground truth; 0 = invalid), seen from the "
               "file's VIEWPOINT\n"
               "  -o FILE    also write the markdown table to FILE (only when every "
               "cloud was read)\n"
               "Methods: this project's, RegionGrowing, Supervoxel+LCCP, and on "
               "organized clouds\n(height > 1) OrganizedMultiPlane.\n",
               argv[0]);
    return argc < 2 ? kUsageError : 0;
  }
  Options opt;
  if (const int code = parseOptions(argc, argv, opt))
    return code;
  // Every input a readable file, and the table's folder writable, before the work.
  for (const auto& input : opt.inputs) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(input, ec) || !std::ifstream(input)) {
      print_error("Cannot read '%s': give an existing PCD file.\n", input.c_str());
      return kRuntimeError;
    }
  }
  std::string error;
  if (!opt.output.empty() && !selseg_apps::outputWritable(opt.output, error)) {
    print_error("%s\n", error.c_str());
    return kRuntimeError;
  }
  std::string table = kHeader;
  std::fputs(kHeader, stdout);
  for (const auto& input : opt.inputs)
    if (!evaluate(input, table))
      return kRuntimeError;
  if (!opt.output.empty() && !writeTable(opt.output, table))
    return kRuntimeError;
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  return selseg_apps::runReportingOutOfMemory(
      [&] { return run(argc, argv); },
      "compare smaller clouds (crop or downsample them).",
      kRuntimeError);
}
