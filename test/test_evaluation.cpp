/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Smoke test of the evaluation: simulated scenes with ground truth, segmented, scored
// with the metrics module. The full evaluation is apps/run_evaluation.sh.

#include <pcl_selective_seg/segmentation_metrics.h>
#include <pcl_selective_seg/selective_segmentation.h>
#include <pcl_selective_seg/sensor_simulator.h>

#include <gtest/gtest.h>

namespace sim = pcl::selective_seg::simulation;
namespace metrics = pcl::selective_seg::metrics;
using pcl::selective_seg::SelectiveSegmentationParameters;

namespace {

struct Scored {
  metrics::HooverScores hoover;
  metrics::UnderSegmentationError under;
  metrics::SegmentCoverage coverage;
};

Scored
score(const sim::SimulationSetup& setup, const SelectiveSegmentationParameters& params)
{
  auto labeled = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  sim::SensorSimulator simulator;
  EXPECT_TRUE(simulator.setParameters(setup.sensor));
  EXPECT_TRUE(simulator.simulate(setup.scene, *labeled));
  std::vector<std::uint32_t> truth;
  for (const auto& p : *labeled)
    truth.push_back(p.label);
  pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZL> seg;
  seg.setParameters(params);
  seg.setInputCloud(labeled);
  std::vector<pcl::PointIndices> segments;
  EXPECT_TRUE(seg.extract(segments));
  Scored s;
  EXPECT_TRUE(metrics::hooverMetrics(seg.getResult().labels, truth, 0.8, s.hoover));
  metrics::LabelOverlap overlap;
  EXPECT_TRUE(metrics::buildLabelOverlap(seg.getResult().labels, truth, overlap));
  s.under = metrics::underSegmentationError(overlap);
  s.coverage = metrics::segmentsCovering(overlap, 0.9);
  return s;
}

} // namespace

// The paper's Fig. 7 scene at its point count: every face found, little leakage.
TEST(Evaluation, CubeSceneAtThePapersDensity)
{
  auto setup = sim::makeCubeScene(1.0);
  setup.sensor.range_noise = 0.0005;
  setup.sensor.density_ratio = 10.0;
  const Scored s = score(setup, SelectiveSegmentationParameters());
  EXPECT_EQ(s.hoover.num_gt_regions, 5u);
  EXPECT_GE(s.hoover.correct_detections, 4u);
  EXPECT_EQ(s.hoover.under_segmentations, 0u);
  EXPECT_LT(s.under.error, 0.05);
  EXPECT_LE(s.coverage.segments, 6u);
}

// Range noise above the point spacing fragments the paper's method; the noise-robust
// options (2-ring normals, vertex-mean normals in eq. 8) recover large segments.
TEST(Evaluation, NoiseRobustOptionsReduceFragmentation)
{
  auto setup = sim::makeCubeScene(3.0);
  setup.sensor.range_noise = 0.002;
  setup.sensor.density_ratio = 10.0;
  const Scored paper = score(setup, SelectiveSegmentationParameters());
  SelectiveSegmentationParameters robust;
  robust.normal_rings = 2;
  robust.edge_triangle_normal = pcl::selective_seg::EdgeTriangleNormal::VertexMean;
  const Scored fixed = score(setup, robust);
  EXPECT_GT(paper.coverage.segments, 100u);
  EXPECT_LT(fixed.coverage.segments, 20u);
  EXPECT_GE(fixed.hoover.correct_detections, paper.hoover.correct_detections);
  EXPECT_LT(fixed.under.error, 0.03);
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
