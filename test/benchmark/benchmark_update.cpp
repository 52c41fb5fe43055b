/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// SelectiveSegmentation::update() against extract() on the same union of points: a
// simulated door scan (the paper's Fig. 6 scene, irregular density) plus a finer scan
// (4x the density) of one angular window holding 5% of the union's points. The ratio
// of the two medians is the speed-up of the incremental update
// (docs/selective_sensing.md). Run: build/test/selseg_benchmark_update

#include <pcl_selective_seg/selective_segmentation.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>

#include "door_scan.h"
#include "page_faults.h"

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

struct Scenario {
  Cloud::Ptr coarse, fine, all;
};

/** The coarse scan of about n points and a 4x finer scan of a centred window, grown
 * until it holds 5% of the union's points. */
const Scenario&
scenario(std::size_t n)
{
  static std::map<std::size_t, Scenario> cache;
  Scenario& s = cache[n];
  if (s.coarse)
    return s;
  s.coarse = selseg_bench::doorScan(n, 1);
  const auto dense = selseg_bench::doorScan(4 * n, 2);
  const std::size_t wanted = n * 5 / 95;
  s.fine = pcl::make_shared<Cloud>();
  for (double half = 0.01; half < 1.0 && s.fine->size() < wanted; half *= 1.05) {
    s.fine->clear();
    for (const auto& p : *dense)
      if (std::abs(std::atan2(p.x, p.z)) <= half &&
          std::abs(std::atan2(p.y, p.z)) <= half)
        s.fine->push_back(p);
  }
  s.all = pcl::make_shared<Cloud>(*s.coarse);
  *s.all += *s.fine;
  return s;
}

void
setTimings(benchmark::State& state, const pcl::selective_seg::SegmentationResult& r)
{
  state.counters["delaunay_s"] = r.timings.delaunay;
  state.counters["normals_s"] = r.timings.normals;
  state.counters["octree_s"] = r.timings.octree;
  state.counters["merge_s"] = r.timings.merge;
}

void
BM_ExtractUnion(benchmark::State& state)
{
  const Scenario& s = scenario(static_cast<std::size_t>(state.range(0)));
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> first;
  first.setInputCloud(s.coarse);
  std::vector<pcl::PointIndices> clusters;
  first.extract(clusters);
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setMinVoxelSize(first.getResult().min_voxel_size); // as update() keeps it
  seg.setInputCloud(s.all);
  const double faults_before = selseg_bench::minorFaults();
  for (auto _ : state)
    benchmark::DoNotOptimize(seg.extract(clusters));
  state.counters["faults"] = benchmark::Counter(
      selseg_bench::minorFaults() - faults_before, benchmark::Counter::kAvgIterations);
  setTimings(state, seg.getResult());
  state.counters["points"] = static_cast<double>(s.all->size());
  state.counters["window_points"] = static_cast<double>(s.fine->size());
}

void
BM_Update(benchmark::State& state)
{
  const Scenario& s = scenario(static_cast<std::size_t>(state.range(0)));
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ> seg;
  std::vector<pcl::PointIndices> clusters;
  double faults = 0.0; // those of the updates only
  for (auto _ : state) {
    state.PauseTiming();
    seg.setInputCloud(s.coarse);
    seg.extract(clusters);
    const double before = selseg_bench::minorFaults();
    state.ResumeTiming();
    benchmark::DoNotOptimize(seg.update(*s.fine, clusters));
    state.PauseTiming();
    faults += selseg_bench::minorFaults() - before;
    state.ResumeTiming();
  }
  state.counters["faults"] =
      benchmark::Counter(faults, benchmark::Counter::kAvgIterations);
  setTimings(state, seg.getResult());
  const auto& u = seg.getUpdateStatistics();
  state.counters["incremental"] = u.incremental;
  state.counters["replaced_triangles"] = static_cast<double>(u.replaced_triangles);
  state.counters["kept_leaves"] = static_cast<double>(u.kept_leaves);
  state.counters["replayed_segments"] = static_cast<double>(u.replayed_segments);
  state.counters["segments"] = static_cast<double>(seg.getResult().segments.size());
  state.counters["leaves"] = static_cast<double>(seg.getResult().leaves.size());
  state.counters["points"] = static_cast<double>(s.all->size());
}

/** Both benchmarks on the same sizes and settings, so that they pair up. */
void
sizes(benchmark::internal::Benchmark* b)
{
  b->Arg(46000)
      ->Arg(300000)
      ->Arg(1000000)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Repetitions(3)
      ->ReportAggregatesOnly(true);
}

} // namespace

BENCHMARK(BM_ExtractUnion)->Apply(sizes);
BENCHMARK(BM_Update)->Apply(sizes);

BENCHMARK_MAIN();
