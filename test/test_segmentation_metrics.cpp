/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 *
 *  Unit tests of the segmentation metrics: Hoover et al. (1996) counts and the
 *  object-level scores, on hand-built labellings with known answers.
 */

#include <pcl_selective_seg/segmentation_metrics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace metrics = pcl::selective_seg::metrics;

namespace {

using Labels = std::vector<std::uint32_t>;

/** Labels from runs of (label, count). */
Labels
runs(std::initializer_list<std::pair<std::uint32_t, std::size_t>> parts)
{
  Labels labels;
  for (const auto& [label, count] : parts)
    labels.insert(labels.end(), count, label);
  return labels;
}

metrics::HooverScores
hoover(const Labels& predicted, const Labels& ground_truth, double tolerance = 0.8)
{
  metrics::HooverScores scores;
  EXPECT_TRUE(metrics::hooverMetrics(predicted, ground_truth, tolerance, scores));
  return scores;
}

/** Counts as (correct, over, under, missed, noise), for one-line comparisons. */
std::vector<std::size_t>
counts(const metrics::HooverScores& s)
{
  return {s.correct_detections,
          s.over_segmentations,
          s.under_segmentations,
          s.missed,
          s.noise};
}

metrics::LabelOverlap
overlapOf(const Labels& predicted, const Labels& ground_truth)
{
  metrics::LabelOverlap overlap;
  EXPECT_TRUE(metrics::buildLabelOverlap(predicted, ground_truth, overlap));
  return overlap;
}

/** n points on the x axis, spacing 0.1 m from the origin. */
pcl::PointCloud<pcl::PointXYZ>
line(std::size_t n)
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (std::size_t i = 0; i < n; ++i)
    cloud.push_back(pcl::PointXYZ(0.1f * static_cast<float>(i), 0.0f, 0.0f));
  return cloud;
}

metrics::BoundaryRecall
recall(const Labels& predicted,
       const Labels& ground_truth,
       double match_distance,
       const pcl::PointCloud<pcl::PointXYZ>& cloud = line(20))
{
  metrics::BoundaryRecall result;
  EXPECT_TRUE(metrics::boundaryRecall(
      cloud, predicted, ground_truth, 0.15, match_distance, result));
  return result;
}

using Counts = std::vector<std::size_t>;

} // namespace

TEST(BuildLabelOverlap, CountsSizesAndOverlaps)
{
  // GT 5 x3, 9 x2, 0 x2 (ignored); predicted 7 on 2 + 1 points, 4 on 1, 0 on 1.
  const Labels gt = {5, 5, 5, 9, 9, 0, 0};
  const Labels predicted = {7, 7, 4, 7, 0, 4, 3};
  const auto overlap = overlapOf(predicted, gt);
  EXPECT_EQ(overlap.gt_labels, (Labels{5, 9}));
  EXPECT_EQ(overlap.gt_sizes, (std::vector<std::size_t>{3, 2}));
  EXPECT_EQ(overlap.predicted_labels, (Labels{4, 7})); // 3 lies only on GT 0
  EXPECT_EQ(overlap.predicted_sizes, (std::vector<std::size_t>{1, 3}));
  EXPECT_EQ(overlap.num_valid_points, 5u);
  EXPECT_EQ(overlap.num_unlabeled_points, 1u);
  ASSERT_EQ(overlap.entries.size(), 3u);
  EXPECT_EQ(overlap.entries[0].gt, 0u); // (5, 4): 1
  EXPECT_EQ(overlap.entries[0].predicted, 0u);
  EXPECT_EQ(overlap.entries[0].count, 1u);
  EXPECT_EQ(overlap.entries[1].predicted, 1u); // (5, 7): 2
  EXPECT_EQ(overlap.entries[1].count, 2u);
  EXPECT_EQ(overlap.entries[2].gt, 1u); // (9, 7): 1
  EXPECT_EQ(overlap.entries[2].count, 1u);
}

TEST(BuildLabelOverlap, RejectsMismatchedLengths)
{
  metrics::LabelOverlap overlap;
  overlap.num_valid_points = 3;
  EXPECT_FALSE(metrics::buildLabelOverlap({1, 2}, {1, 2, 3}, overlap));
  EXPECT_EQ(overlap.num_valid_points, 0u);
  EXPECT_TRUE(overlap.gt_labels.empty());
}

TEST(HooverMetrics, PerfectSegmentationIsAllCorrect)
{
  const Labels gt = runs({{1, 10}, {2, 10}, {3, 10}});
  const Labels predicted = runs({{7, 10}, {3, 10}, {9, 10}}); // any label values
  const auto s = hoover(predicted, gt);
  EXPECT_EQ(counts(s), (Counts{3, 0, 0, 0, 0}));
  EXPECT_EQ(s.num_gt_regions, 3u);
  EXPECT_EQ(s.num_predicted_regions, 3u);
  EXPECT_DOUBLE_EQ(s.tolerance, 0.8);
}

TEST(HooverMetrics, SplitRegionIsOneOverSegmentation)
{
  const Labels gt = runs({{1, 20}, {2, 10}});
  const Labels predicted = runs({{1, 10}, {2, 10}, {3, 10}});
  EXPECT_EQ(counts(hoover(predicted, gt)), (Counts{1, 1, 0, 0, 0}));
}

TEST(HooverMetrics, MergedRegionsAreOneUnderSegmentation)
{
  const Labels gt = runs({{1, 10}, {2, 10}, {3, 10}});
  const Labels predicted = runs({{1, 20}, {2, 10}});
  EXPECT_EQ(counts(hoover(predicted, gt)), (Counts{1, 0, 1, 0, 0}));
}

TEST(HooverMetrics, TinySpuriousRegionIsNoise)
{
  // Region 3 straddles both GT regions: 2 of its 4 points in each.
  const Labels gt = runs({{1, 20}, {2, 20}});
  const Labels predicted = runs({{1, 18}, {3, 4}, {2, 18}});
  EXPECT_EQ(counts(hoover(predicted, gt)), (Counts{2, 0, 0, 0, 1}));
}

TEST(HooverMetrics, LostRegionIsMissed)
{
  const Labels gt = runs({{1, 10}, {2, 10}, {3, 4}});
  // Unlabeled: region 3 is in no predicted region.
  EXPECT_EQ(counts(hoover(runs({{1, 10}, {2, 10}, {0, 4}}), gt)),
            (Counts{2, 0, 0, 1, 0}));
  // Absorbed: half of it in each neighbour, which stay correct detections.
  EXPECT_EQ(counts(hoover(runs({{1, 10}, {2, 10}, {1, 2}, {2, 2}}), gt)),
            (Counts{2, 0, 0, 1, 0}));
}

TEST(HooverMetrics, PredictedRegionOnInvalidPointsIsIgnored)
{
  const Labels gt = runs({{1, 10}, {0, 5}, {2, 10}});
  const Labels predicted = runs({{1, 10}, {8, 5}, {2, 10}});
  const auto s = hoover(predicted, gt);
  EXPECT_EQ(counts(s), (Counts{2, 0, 0, 0, 0}));
  EXPECT_EQ(s.num_predicted_regions, 2u);
}

TEST(HooverMetrics, ToleranceBoundaryIsInclusive)
{
  // Region 1 holds 8 of the 10 points of A; region 2 the other 2 and all 10 of B.
  const Labels gt = runs({{1, 10}, {2, 10}});
  const Labels predicted = runs({{1, 8}, {2, 12}});
  EXPECT_EQ(counts(hoover(predicted, gt, 0.8)), (Counts{2, 0, 0, 0, 0}));
  // 8 < 0.81 * 10: A and region 1 are no longer matched.
  EXPECT_EQ(counts(hoover(predicted, gt, 0.81)), (Counts{1, 0, 0, 1, 1}));
  // B holds 10 of the 12 points of region 2: matched up to T = 10/12 included.
  EXPECT_EQ(counts(hoover(predicted, gt, 10.0 / 12.0)), (Counts{1, 0, 0, 1, 1}));
  EXPECT_EQ(counts(hoover(predicted, gt, 0.84)), (Counts{0, 0, 0, 2, 2}));
}

TEST(HooverMetrics, FragmentInsideDetectedRegionIsAlsoOverSegmentation)
{
  // Paper's definitions, each instance counted: 17 + 3 points of one GT region.
  const Labels gt = runs({{1, 20}});
  const Labels predicted = runs({{1, 17}, {2, 3}});
  EXPECT_EQ(counts(hoover(predicted, gt)), (Counts{1, 1, 0, 0, 0}));
  // Mirror image: a small GT region inside a correct detection.
  EXPECT_EQ(counts(hoover(runs({{1, 20}}), runs({{1, 17}, {2, 3}}))),
            (Counts{1, 0, 1, 0, 0}));
}

TEST(HooverMetrics, ExactHalvesAtToleranceOneHalf)
{
  const Labels gt = runs({{1, 20}});
  const Labels predicted = runs({{1, 10}, {2, 10}});
  EXPECT_EQ(counts(hoover(predicted, gt, 0.5)), (Counts{2, 1, 0, 0, 0}));
  EXPECT_EQ(counts(hoover(predicted, gt, 0.55)), (Counts{0, 1, 0, 0, 0}));
}

TEST(HooverMetrics, RejectsBadInput)
{
  metrics::HooverScores s;
  s.noise = 4;
  EXPECT_FALSE(metrics::hooverMetrics({1, 2}, {1}, 0.8, s));
  EXPECT_EQ(s.noise, 0u);
  EXPECT_FALSE(metrics::hooverMetrics({1}, {1}, 0.49, s));
  EXPECT_FALSE(metrics::hooverMetrics({1}, {1}, 1.01, s));
  EXPECT_FALSE(
      metrics::hooverMetrics({1}, {1}, std::numeric_limits<double>::quiet_NaN(), s));
  EXPECT_TRUE(metrics::hooverMetrics({1}, {1}, 1.0, s));
  EXPECT_EQ(counts(s), (Counts{1, 0, 0, 0, 0}));
}

TEST(HooverMetrics, EmptyInputHasNoRegions)
{
  EXPECT_EQ(counts(hoover({}, {})), (Counts{0, 0, 0, 0, 0}));
  EXPECT_EQ(counts(hoover({1, 2}, {0, 0})), (Counts{0, 0, 0, 0, 0}));
}

TEST(HooverSweep, TenTolerancesFromOneHalfTo095)
{
  const Labels gt = runs({{1, 10}, {2, 10}});
  const Labels predicted = runs({{1, 8}, {2, 12}});
  std::vector<metrics::HooverScores> sweep;
  ASSERT_TRUE(metrics::hooverSweep(predicted, gt, sweep));
  ASSERT_EQ(sweep.size(), 10u);
  for (std::size_t i = 0; i < sweep.size(); ++i) {
    EXPECT_NEAR(sweep[i].tolerance, 0.5 + 0.05 * static_cast<double>(i), 1e-12);
    // 8 of 10 points of A: correct up to T = 0.8 (i = 6) included.
    const Counts expected = i <= 6 ? Counts{2, 0, 0, 0, 0} : Counts{0, 0, 0, 2, 2};
    EXPECT_EQ(counts(sweep[i]), expected) << "T = " << sweep[i].tolerance;
  }
  ASSERT_TRUE(metrics::hooverSweep(predicted, gt, sweep, 0.6, 1.0, 0.1));
  ASSERT_EQ(sweep.size(), 5u);
  EXPECT_DOUBLE_EQ(sweep.back().tolerance, 1.0);
}

TEST(HooverSweep, FractionExactlyAtTheToleranceIsAccepted)
{
  // 51 of 60 points is exactly 0.85, but 0.5 + 7 * 0.05 rounds above 0.85.
  const Labels gt = runs({{1, 60}});
  const Labels predicted = runs({{1, 51}, {2, 9}});
  std::vector<metrics::HooverScores> sweep;
  ASSERT_TRUE(metrics::hooverSweep(predicted, gt, sweep));
  ASSERT_EQ(sweep.size(), 10u);
  EXPECT_GT(sweep[7].tolerance, 0.85);
  EXPECT_EQ(counts(sweep[7]), (Counts{1, 1, 0, 0, 0}));
  EXPECT_EQ(counts(sweep[8]), (Counts{0, 1, 0, 0, 0}));
}

TEST(HooverSweep, RejectsBadRange)
{
  std::vector<metrics::HooverScores> sweep(3);
  EXPECT_FALSE(metrics::hooverSweep({1}, {1}, sweep, 0.4, 0.9, 0.05));
  EXPECT_TRUE(sweep.empty());
  EXPECT_FALSE(metrics::hooverSweep({1}, {1}, sweep, 0.9, 0.8, 0.05));
  EXPECT_FALSE(metrics::hooverSweep({1}, {1}, sweep, 0.5, 0.9, 0.0));
  EXPECT_FALSE(metrics::hooverSweep({1}, {1, 1}, sweep));
  // An infinite step, or one too small to move the tolerance (a loop adding steps
  // until it passed the maximum would never end), is refused.
  EXPECT_FALSE(metrics::hooverSweep(
      {1}, {1}, sweep, 0.5, 1.0, std::numeric_limits<double>::infinity()));
  EXPECT_FALSE(metrics::hooverSweep({1}, {1}, sweep, 0.5, 1.0, 1e-300));
  EXPECT_FALSE(metrics::hooverSweep({1}, {1}, sweep, 0.5, 1.0, 1e-6));
  EXPECT_TRUE(sweep.empty());
}

TEST(HooverSweep, CountsTheTolerancesFirst)
{
  std::vector<metrics::HooverScores> sweep;
  // min == max: one tolerance, whatever the step.
  ASSERT_TRUE(metrics::hooverSweep({1}, {1}, sweep, 0.5, 0.5, 1e-20));
  ASSERT_EQ(sweep.size(), 1u);
  EXPECT_EQ(sweep[0].tolerance, 0.5);
  EXPECT_EQ(counts(sweep[0]), (Counts{1, 0, 0, 0, 0}));
  // 0.5 to 1 by 1e-5: 50,001 tolerances, increasing, the last 1.
  ASSERT_TRUE(metrics::hooverSweep({1}, {1}, sweep, 0.5, 1.0, 1e-5));
  ASSERT_EQ(sweep.size(), 50001u);
  EXPECT_EQ(sweep.back().tolerance, 1.0);
  for (std::size_t i = 1; i < sweep.size(); ++i)
    ASSERT_GT(sweep[i].tolerance, sweep[i - 1].tolerance) << i;
}

TEST(MajorityLabels, TieGoesToSmallerGroundTruthLabel)
{
  // Region 4: 2 points of GT 8, 2 of GT 3, 1 of GT 1.
  const auto overlap = overlapOf({4, 4, 4, 4, 4}, {8, 3, 8, 3, 1});
  const auto majority = metrics::majorityLabels(overlap);
  ASSERT_EQ(majority.size(), 1u);
  EXPECT_EQ(overlap.gt_labels[majority[0].gt], 3u);
  EXPECT_EQ(majority[0].count, 2u);
  EXPECT_DOUBLE_EQ(majority[0].purity, 0.4);
}

TEST(UnderSegmentationError, TwoLeakedOfTenIsOneFifth)
{
  // Region 1: 6 points of A and 2 of B (majority A); region 2: the other 2 of B.
  const Labels gt = runs({{1, 6}, {2, 4}});
  const Labels predicted = runs({{1, 8}, {2, 2}});
  const auto e = metrics::underSegmentationError(overlapOf(predicted, gt));
  EXPECT_EQ(e.valid_points, 10u);
  EXPECT_EQ(e.leaked_points, 2u);
  EXPECT_DOUBLE_EQ(e.error, 0.2);
}

TEST(UnderSegmentationError, UnlabeledAndInvalidPointsDoNotLeak)
{
  const Labels gt = runs({{1, 6}, {2, 4}, {0, 5}});
  const Labels predicted = runs({{1, 6}, {0, 4}, {1, 5}});
  const auto e = metrics::underSegmentationError(overlapOf(predicted, gt));
  EXPECT_EQ(e.leaked_points, 0u);
  EXPECT_DOUBLE_EQ(e.error, 0.0);
  EXPECT_TRUE(std::isnan(metrics::underSegmentationError(overlapOf({}, {})).error));
}

TEST(SegmentsCovering, LargestFirstUntilNinetyPercent)
{
  const Labels gt = runs({{1, 100}});
  // 50 + 30 = 80 < 90 <= 95.
  auto c = metrics::segmentsCovering(
      overlapOf(runs({{4, 15}, {1, 50}, {3, 5}, {2, 30}}), gt));
  EXPECT_EQ(c.segments, 3u);
  EXPECT_TRUE(c.reached);
  EXPECT_DOUBLE_EQ(c.covered_fraction, 0.95);
  // Exactly 90 points reach the target.
  c = metrics::segmentsCovering(overlapOf(runs({{1, 50}, {2, 40}, {3, 10}}), gt));
  EXPECT_EQ(c.segments, 2u);
  EXPECT_TRUE(c.reached);
  // One region: one segment.
  EXPECT_EQ(metrics::segmentsCovering(overlapOf(runs({{5, 100}}), gt)).segments, 1u);
}

TEST(SegmentsCovering, UnlabeledPointsCanKeepTheTargetOutOfReach)
{
  const Labels gt = runs({{1, 100}});
  const auto overlap = overlapOf(runs({{1, 60}, {2, 20}, {0, 20}}), gt);
  const auto c = metrics::segmentsCovering(overlap);
  EXPECT_EQ(c.segments, 2u);
  EXPECT_FALSE(c.reached);
  EXPECT_DOUBLE_EQ(c.covered_fraction, 0.8);
  EXPECT_TRUE(metrics::segmentsCovering(overlap, 0.8).reached);
}

TEST(RecoverableParts, UnionOfPureSegments)
{
  // A: 6 in region 1 (pure) + 4 in region 2 (4 A + 1 B: purity 0.8) -> 10/10.
  // B: 7 in region 3 (pure); 1 in region 2, 2 in region 4 -> 7/10 < 0.8.
  // C: 8 in region 4 (2 B + 8 C: purity 0.8) -> 8/10, exactly f; 2 unlabeled.
  const Labels gt = runs({{1, 10}, {2, 10}, {3, 10}});
  const Labels predicted = runs({{1, 6}, {2, 5}, {3, 7}, {4, 10}, {0, 2}});
  const auto overlap = overlapOf(predicted, gt);
  auto r = metrics::recoverableParts(overlap);
  EXPECT_EQ(r.num_parts, 3u);
  EXPECT_EQ(r.recoverable_parts, 2u);
  EXPECT_DOUBLE_EQ(r.fraction, 2.0 / 3.0);
  // Regions 2 and 4 are no longer pure enough: A keeps 6/10, C nothing.
  r = metrics::recoverableParts(overlap, 0.81, 0.8);
  EXPECT_EQ(r.recoverable_parts, 0u);
  // A smaller f lets B in.
  r = metrics::recoverableParts(overlap, 0.8, 0.7);
  EXPECT_EQ(r.recoverable_parts, 3u);
  EXPECT_DOUBLE_EQ(r.fraction, 1.0);
}

TEST(BoundaryRecall, LineWithOneBoundary)
{
  // GT boundary between x = 0.9 and x = 1.0 (points 9 and 10); r = 0.15 m.
  const Labels gt = runs({{1, 10}, {2, 10}});
  auto r = recall(runs({{5, 10}, {6, 10}}), gt, 0.0);
  EXPECT_EQ(r.gt_boundary_points, 2u);
  EXPECT_EQ(r.predicted_boundary_points, 2u);
  EXPECT_EQ(r.matched_points, 2u);
  EXPECT_DOUBLE_EQ(r.recall, 1.0);
  // Predicted boundary two points late (points 11 and 12, x = 1.1 and 1.2).
  const Labels late = runs({{5, 12}, {6, 8}});
  r = recall(late, gt, 0.15);
  EXPECT_EQ(r.matched_points, 1u); // 1.0 -> 1.1; 0.9 is 0.2 away
  EXPECT_DOUBLE_EQ(r.recall, 0.5);
  EXPECT_DOUBLE_EQ(recall(late, gt, 0.25).recall, 1.0);
  // No predicted boundary.
  r = recall(runs({{5, 20}}), gt, 1.0);
  EXPECT_EQ(r.predicted_boundary_points, 0u);
  EXPECT_DOUBLE_EQ(r.recall, 0.0);
}

TEST(BoundaryRecall, UnlabeledPointsEndRegionsButAreNotBoundaries)
{
  const Labels gt = runs({{1, 10}, {2, 10}});
  // Point 10 unlabeled: points 9 and 11 are predicted boundary points, 10 is not.
  auto r = recall(runs({{5, 10}, {0, 1}, {6, 9}}), gt, 0.11);
  EXPECT_EQ(r.predicted_boundary_points, 2u);
  EXPECT_EQ(r.matched_points, 2u); // 9 itself; 10 is 0.1 m from 9 and from 11
  EXPECT_EQ(recall(runs({{5, 10}, {0, 1}, {6, 9}}), gt, 0.05).matched_points, 1u);
  // An empty prediction recalls nothing.
  r = recall(Labels(20, 0), gt, 1.0);
  EXPECT_EQ(r.predicted_boundary_points, 0u);
  EXPECT_DOUBLE_EQ(r.recall, 0.0);
}

TEST(BoundaryRecall, InvalidPointsMakeNoBoundary)
{
  // Point 10 is GT-invalid and not finite in the second case: no GT boundary at all.
  const Labels gt = runs({{1, 10}, {0, 1}, {1, 9}});
  auto r = recall(runs({{5, 10}, {6, 10}}), gt, 0.1);
  EXPECT_EQ(r.gt_boundary_points, 0u);
  EXPECT_EQ(r.predicted_boundary_points, 0u); // 9 and 11 are 0.2 m apart
  EXPECT_TRUE(std::isnan(r.recall));
  auto cloud = line(20);
  cloud[5].x = std::numeric_limits<float>::quiet_NaN();
  r = recall(runs({{5, 20}}), runs({{1, 10}, {2, 10}}), 0.1, cloud);
  EXPECT_EQ(r.gt_boundary_points, 2u);
}

TEST(BoundaryRecall, RejectsBadInput)
{
  const auto cloud = line(3);
  metrics::BoundaryRecall r;
  r.matched_points = 7;
  EXPECT_FALSE(metrics::boundaryRecall(cloud, {1, 1}, {1, 1, 1}, 0.15, 0.1, r));
  EXPECT_EQ(r.matched_points, 0u);
  EXPECT_FALSE(metrics::boundaryRecall(cloud, {1, 1, 1}, {1, 1}, 0.15, 0.1, r));
  EXPECT_FALSE(metrics::boundaryRecall(cloud, {1, 1, 1}, {1, 1, 1}, 0.0, 0.1, r));
  EXPECT_FALSE(metrics::boundaryRecall(cloud, {1, 1, 1}, {1, 1, 1}, 0.15, -0.1, r));
}

// The boundary flags come from cells grouped by label (a search of the whole ball per
// point was quadratic in a dense cloud): the same counts as a pass over every pair,
// with pcl::search::KdTree's rule (squared float differences summed x, y, z, strictly
// below the squared radius), on random points with random labels, unlabeled ones
// among the predictions, and points exactly one radius apart on a grid.
TEST(BoundaryRecall, SameFlagsAsEveryPair)
{
  std::mt19937 engine(3);
  std::uniform_real_distribution<float> at(0.0f, 0.05f);
  std::uniform_int_distribution<std::uint32_t> label(0, 3);
  for (const bool grid : {false, true}) {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    Labels gt, predicted;
    for (int i = 0; i < 1500; ++i) {
      cloud.push_back(grid ? pcl::PointXYZ(0.01f * (i % 12),
                                           0.01f * (i / 12 % 12),
                                           1.0f + 0.01f * (i / 144))
                           : pcl::PointXYZ(at(engine), at(engine), 1.0f + at(engine)));
      gt.push_back(1 + label(engine) % 3);
      predicted.push_back(label(engine));
    }
    const double radius = 0.01;
    const auto r2 = static_cast<float>(radius * radius);
    std::size_t gt_count = 0, predicted_count = 0;
    for (std::size_t k = 0; k < cloud.size(); ++k) {
      bool g = false, p = false;
      for (std::size_t j = 0; j < cloud.size(); ++j) {
        float sum = 0.0f;
        const float dx = cloud[k].x - cloud[j].x, dy = cloud[k].y - cloud[j].y,
                    dz = cloud[k].z - cloud[j].z;
        sum += dx * dx;
        sum += dy * dy;
        sum += dz * dz;
        if (!(sum < r2))
          continue;
        g = g || gt[j] != gt[k];
        p = p || (predicted[k] != 0 && predicted[j] != predicted[k]);
      }
      gt_count += g;
      predicted_count += p;
    }
    metrics::BoundaryRecall r;
    ASSERT_TRUE(metrics::boundaryRecall(cloud, predicted, gt, radius, 0.0, r));
    EXPECT_EQ(r.gt_boundary_points, gt_count) << (grid ? "grid" : "random");
    EXPECT_EQ(r.predicted_boundary_points, predicted_count)
        << (grid ? "grid" : "random");
    EXPECT_GT(gt_count, 100u);
  }
  // 20,000 points inside one radius, two halves: every point is a GT boundary point,
  // and the one predicted segment has none.
  pcl::PointCloud<pcl::PointXYZ> dense;
  Labels halves, one;
  for (int i = 0; i < 20000; ++i) {
    dense.push_back(pcl::PointXYZ(at(engine) * 0.1f, at(engine) * 0.1f, 1.0f));
    halves.push_back(dense.back().x < 0.0025f ? 1 : 2);
    one.push_back(1);
  }
  metrics::BoundaryRecall r;
  ASSERT_TRUE(metrics::boundaryRecall(dense, one, halves, 0.02, 0.02, r));
  EXPECT_EQ(r.gt_boundary_points, dense.size());
  EXPECT_EQ(r.predicted_boundary_points, 0u);
}

TEST(ObjectMetrics, CombinesEveryScore)
{
  const auto cloud = line(20);
  const Labels gt = runs({{1, 10}, {2, 10}});
  const Labels predicted = runs({{5, 12}, {0, 2}, {6, 6}});
  metrics::ObjectMetricsParams params;
  params.boundary_radius = 0.15;
  params.boundary_match_distance = 0.15;
  metrics::ObjectScores s;
  ASSERT_TRUE(metrics::objectMetrics(cloud, predicted, gt, params, s));
  EXPECT_EQ(s.num_gt_regions, 2u);
  EXPECT_EQ(s.num_predicted_regions, 2u);
  EXPECT_DOUBLE_EQ(s.unlabeled_fraction, 0.1);
  EXPECT_DOUBLE_EQ(s.under_segmentation.error, 0.1); // 2 points of B in region 5
  EXPECT_EQ(s.boundary.gt_boundary_points, 2u);
  EXPECT_EQ(s.boundary.predicted_boundary_points, 2u); // points 11 and 14
  EXPECT_DOUBLE_EQ(s.boundary.recall, 0.5);
  EXPECT_EQ(s.coverage.segments, 2u); // 12 + 6 = 18 of 20 points: exactly 90 %
  EXPECT_TRUE(s.coverage.reached);
  EXPECT_EQ(s.parts.recoverable_parts, 1u); // A: 10/10; B: 6/10
}

TEST(ObjectMetrics, RejectsBadParameters)
{
  const auto cloud = line(4);
  const Labels labels = {1, 1, 2, 2};
  metrics::ObjectScores s;
  metrics::ObjectMetricsParams params;
  params.min_purity = 0.0;
  EXPECT_FALSE(metrics::objectMetrics(cloud, labels, labels, params, s));
  params = metrics::ObjectMetricsParams{};
  params.coverage_fraction = 1.5;
  EXPECT_FALSE(metrics::objectMetrics(cloud, labels, labels, params, s));
  params = metrics::ObjectMetricsParams{};
  params.boundary_radius = -1.0;
  EXPECT_FALSE(metrics::objectMetrics(cloud, labels, labels, params, s));
  EXPECT_FALSE(metrics::objectMetrics(cloud, labels, {1, 1, 2}, {}, s));
  EXPECT_TRUE(metrics::objectMetrics(cloud, labels, labels, {}, s));
  EXPECT_DOUBLE_EQ(s.under_segmentation.error, 0.0);
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
