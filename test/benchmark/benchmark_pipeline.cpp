/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Google Benchmark suite: the whole pipeline (with per-stage counters) and, in the same
// run, pcl::NormalEstimation + pcl::RegionGrowing on the same clouds.
//
// Clouds: the simulated door scene (the paper's largest, Fig. 6) scanned at about 10k,
// 46k, 300k, 1M and 3M points, and the real frames of the data folder given by the
// environment variable SELSEG_DATA (mOSD test0, the stereo mug scene).
// apps/run_benchmarks.sh runs it and writes docs/performance.md.

#include <pcl_selective_seg/selective_segmentation.h>

#include <benchmark/benchmark.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/io/pcd_io.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>

#include <cstdlib>
#include <map>
#include <string>

#include "door_scan.h"
#include "page_faults.h"

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/** The simulated door scan with about n points (cached: the 3M scan takes seconds). */
Cloud::ConstPtr
doorScan(std::size_t n)
{
  static std::map<std::size_t, Cloud::ConstPtr> cache;
  auto& cloud = cache[n];
  if (!cloud)
    cloud = selseg_bench::doorScan(n);
  return cloud;
}

/** A real frame from $SELSEG_DATA, or null. */
Cloud::ConstPtr
realFrame(const std::string& relative)
{
  static std::map<std::string, Cloud::ConstPtr> cache;
  auto& cloud = cache[relative];
  const char* dir = std::getenv("SELSEG_DATA");
  if (!cloud && dir) {
    auto c = pcl::make_shared<Cloud>();
    if (pcl::io::loadPCDFile(std::string(dir) + "/" + relative, *c) == 0) {
      c->sensor_origin_.setZero(); // the camera frame, whatever the header says
      c->sensor_orientation_.setIdentity();
      cloud = c;
    }
  }
  return cloud;
}

/** The pipeline on \a cloud: a new segmenter each iteration, or (\a frame_loop) one
 * segmenter for every iteration after a first frame that is not timed, as a program
 * segmenting a sensor's frames one after another holds it. The counter "faults" is the
 * page faults per timed iteration (the cost of memory the process maps afresh). */
void
runPipeline(benchmark::State& state,
            const Cloud::ConstPtr& cloud,
            bool frame_loop = false)
{
  if (!cloud) {
    state.SkipWithError("cloud not available (set SELSEG_DATA)");
    return;
  }
  pcl::selective_seg::StageTimings sum;
  std::size_t segments = 0;
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> kept;
  if (frame_loop) {
    std::vector<pcl::PointIndices> first;
    kept.setInputCloud(cloud);
    if (!kept.extract(first)) {
      state.SkipWithError("segmentation failed");
      return;
    }
  }
  const double faults_before = selseg_bench::minorFaults();
  for (auto _ : state) {
    pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> fresh;
    auto& seg = frame_loop ? kept : fresh;
    seg.setInputCloud(cloud);
    std::vector<pcl::PointIndices> clusters;
    if (!seg.extract(clusters)) {
      state.SkipWithError("segmentation failed");
      return;
    }
    const auto& t = seg.getResult().timings;
    sum.delaunay += t.delaunay;
    sum.normals += t.normals;
    sum.octree += t.octree;
    sum.merge += t.merge;
    segments = clusters.size();
  }
  const auto avg = benchmark::Counter::kAvgIterations;
  state.counters["points"] = static_cast<double>(cloud->size());
  state.counters["segments"] = static_cast<double>(segments);
  state.counters["delaunay_s"] = benchmark::Counter(sum.delaunay, avg);
  state.counters["normals_s"] = benchmark::Counter(sum.normals, avg);
  state.counters["octree_s"] = benchmark::Counter(sum.octree, avg);
  state.counters["merge_s"] = benchmark::Counter(sum.merge, avg);
  state.counters["faults"] =
      benchmark::Counter(selseg_bench::minorFaults() - faults_before, avg);
}

/** The PCL tutorial's region growing: 30-neighbour normals (OpenMP, both cores),
 * 30-neighbour growing, 5 deg smoothness. */
void
runRegionGrowing(benchmark::State& state, const Cloud::ConstPtr& cloud)
{
  if (!cloud) {
    state.SkipWithError("cloud not available (set SELSEG_DATA)");
    return;
  }
  auto valid = pcl::make_shared<pcl::Indices>();
  for (pcl::index_t i = 0; i < static_cast<pcl::index_t>(cloud->size()); ++i)
    if (pcl::isFinite((*cloud)[i]))
      valid->push_back(i);
  for (auto _ : state) {
    auto tree = pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
    auto normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(2);
    ne.setSearchMethod(tree);
    ne.setInputCloud(cloud);
    ne.setKSearch(30);
    ne.compute(*normals); // NaN points get NaN normals and are not in the indices
    pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> rg;
    rg.setMinClusterSize(50);
    rg.setSearchMethod(tree);
    rg.setNumberOfNeighbours(30);
    rg.setInputCloud(cloud);
    rg.setIndices(valid);
    rg.setInputNormals(normals);
    rg.setSmoothnessThreshold(5.0f * static_cast<float>(M_PI) / 180.0f);
    rg.setCurvatureThreshold(1.0f);
    std::vector<pcl::PointIndices> clusters;
    rg.extract(clusters);
    benchmark::DoNotOptimize(clusters.data());
  }
  state.counters["points"] = static_cast<double>(cloud->size());
}

void
BM_Pipeline_Door(benchmark::State& state)
{
  runPipeline(state, doorScan(static_cast<std::size_t>(state.range(0))));
}

/** Frames of one size one after another (runPipeline(), frame_loop). */
void
BM_FrameLoop_Door(benchmark::State& state)
{
  runPipeline(state, doorScan(static_cast<std::size_t>(state.range(0))), true);
}

void
BM_RegionGrowing_Door(benchmark::State& state)
{
  runRegionGrowing(state, doorScan(static_cast<std::size_t>(state.range(0))));
}

void
BM_Pipeline_Mosd(benchmark::State& state)
{
  runPipeline(state, realFrame("mosd/test0.pcd"));
}

void
BM_RegionGrowing_Mosd(benchmark::State& state)
{
  runRegionGrowing(state, realFrame("mosd/test0.pcd"));
}

void
BM_Pipeline_Mug(benchmark::State& state)
{
  runPipeline(state, realFrame("pcl_test/table_scene_mug_stereo_textured.pcd"));
}

void
BM_RegionGrowing_Mug(benchmark::State& state)
{
  runRegionGrowing(state, realFrame("pcl_test/table_scene_mug_stereo_textured.pcd"));
}

/** Sizes of the simulated door scans. */
void
sizes(benchmark::internal::Benchmark* b, bool include_3m)
{
  for (const long n : {10000L, 46255L, 300000L, 1000000L})
    b->Arg(n);
  if (include_3m)
    b->Arg(3000000L);
}

} // namespace

BENCHMARK(BM_Pipeline_Door)
    ->Apply([](benchmark::internal::Benchmark* b) { sizes(b, true); })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
// At least two timed frames at 3M points (about 2-3 s each).
BENCHMARK(BM_FrameLoop_Door)
    ->Apply([](benchmark::internal::Benchmark* b) { sizes(b, true); })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(4.0)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_RegionGrowing_Door)
    ->Apply([](benchmark::internal::Benchmark* b) { sizes(b, true); })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_Pipeline_Mosd)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_RegionGrowing_Mosd)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_Pipeline_Mug)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_RegionGrowing_Mug)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

BENCHMARK_MAIN();
