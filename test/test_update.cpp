/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// SelectiveSegmentation::update(): folding a finer scan into an existing result must
// give exactly the result of a from-scratch run on the union of the points (with the
// finest voxel size of the run being updated), while recomputing the mesh and its
// normals only where the new points fall.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <cube_scene.h>

using pcl::selective_seg::SelectiveSegmentation;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Seg = SelectiveSegmentation<pcl::PointXYZ>;

namespace {

Cloud::Ptr
toXYZ(const pcl::PointCloud<pcl::PointXYZL>& in)
{
  auto out = pcl::make_shared<Cloud>();
  for (const auto& p : in)
    out->push_back(pcl::PointXYZ(p.x, p.y, p.z));
  return out;
}

Cloud::Ptr
slice(const Cloud& in, std::size_t begin, std::size_t end)
{
  auto out = pcl::make_shared<Cloud>();
  out->points.assign(in.begin() + begin, in.begin() + end);
  out->width = static_cast<std::uint32_t>(out->size());
  out->height = 1;
  return out;
}

/** Points of \a scan whose viewing direction lies in the window (sensor at origin). */
Cloud::Ptr
window(const Cloud& scan, double theta0, double theta1, double phi0, double phi1)
{
  auto out = pcl::make_shared<Cloud>();
  for (const auto& p : scan) {
    const double theta = std::atan2(p.x, p.z), phi = std::atan2(p.y, p.z);
    if (theta >= theta0 && theta <= theta1 && phi >= phi0 && phi <= phi1)
      out->push_back(p);
  }
  return out;
}

bool
sameFloat(float a, float b)
{
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

/** Every output of \a seg equals the reference run's, bit for bit. */
void
expectSameResult(const Seg& seg, const Seg& ref)
{
  const auto& a = seg.getResult();
  const auto& b = ref.getResult();
  EXPECT_EQ(a.labels, b.labels);
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (std::size_t s = 0; s < a.segments.size(); ++s) {
    EXPECT_EQ(a.segments[s].num_points, b.segments[s].num_points);
    EXPECT_EQ(a.segments[s].normal, b.segments[s].normal);
    EXPECT_EQ(a.segments[s].area, b.segments[s].area);
  }
  ASSERT_EQ(a.leaves.size(), b.leaves.size());
  for (std::size_t l = 0; l < a.leaves.size(); ++l) {
    EXPECT_EQ(a.leaves[l].centre, b.leaves[l].centre);
    EXPECT_EQ(a.leaves[l].label, b.leaves[l].label);
    EXPECT_EQ(a.leaves[l].area, b.leaves[l].area);
  }
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.mesh.neighbours, b.mesh.neighbours);
  EXPECT_EQ(a.mesh.labels, b.mesh.labels);
  EXPECT_EQ(a.mesh.classes, b.mesh.classes);
  EXPECT_EQ(a.mesh.areas, b.mesh.areas);
  ASSERT_EQ(a.mesh.normals.size(), b.mesh.normals.size());
  std::size_t different_normals = 0;
  for (std::size_t t = 0; t < a.mesh.normals.size(); ++t)
    for (int k = 0; k < 3; ++k)
      different_normals += !sameFloat(a.mesh.normals[t][k], b.mesh.normals[t][k]);
  EXPECT_EQ(different_normals, 0u);
  EXPECT_EQ(a.num_vertices, b.num_vertices);
  EXPECT_EQ(a.median_spacing, b.median_spacing);
  EXPECT_EQ(a.min_voxel_size, b.min_voxel_size);
  EXPECT_EQ(a.counts.labeled, b.counts.labeled);
  EXPECT_EQ(a.counts.non_finite, b.counts.non_finite);
  EXPECT_EQ(a.counts.behind_sensor, b.counts.behind_sensor);
  EXPECT_EQ(a.counts.outside_indices, b.counts.outside_indices);
  EXPECT_EQ(a.counts.shared_vertex, b.counts.shared_vertex);
  const auto& ta = seg.getTriangulation();
  const auto& tb = ref.getTriangulation();
  EXPECT_EQ(ta.point_vertex, tb.point_vertex);
  EXPECT_EQ(ta.vertex_point, tb.vertex_point);
  const auto na = seg.getPointNormals();
  const auto nb = ref.getPointNormals();
  ASSERT_TRUE(na && nb);
  ASSERT_EQ(na->size(), nb->size());
  std::size_t different = 0;
  for (std::size_t i = 0; i < na->size(); ++i)
    for (int k = 0; k < 3; ++k)
      different += !sameFloat((*na)[i].normal[k], (*nb)[i].normal[k]);
  EXPECT_EQ(different, 0u);
}

/** A from-scratch run on the union with the same finest voxel. */
void
reference(const Cloud::Ptr& all, double voxel, Seg& ref)
{
  ref.setInputCloud(all);
  ref.setMinVoxelSize(voxel);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(ref.extract(clusters));
}

/** The first run; returns its finest voxel (the one update() keeps). */
double
extractFirst(Seg& seg, const Cloud::Ptr& cloud)
{
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  EXPECT_TRUE(seg.extract(clusters));
  return seg.getResult().min_voxel_size;
}

Cloud::Ptr
concat(const Cloud& a, const Cloud& b)
{
  auto out = pcl::make_shared<Cloud>(a);
  *out += b;
  return out;
}

/** The points of \a fine in a window over a fifth of the width and height of
 * \a coarse's view, off centre. */
Cloud::Ptr
offCentreWindow(const Cloud& coarse, const Cloud& fine)
{
  double t0 = 1e9, t1 = -1e9, p0 = 1e9, p1 = -1e9;
  for (const auto& p : coarse) {
    t0 = std::min(t0, std::atan2(double(p.x), double(p.z)));
    t1 = std::max(t1, std::atan2(double(p.x), double(p.z)));
    p0 = std::min(p0, std::atan2(double(p.y), double(p.z)));
    p1 = std::max(p1, std::atan2(double(p.y), double(p.z)));
  }
  return window(fine,
                t0 + 0.45 * (t1 - t0),
                t0 + 0.65 * (t1 - t0),
                p0 + 0.35 * (p1 - p0),
                p0 + 0.55 * (p1 - p0));
}

/** The points of a finer cube scan in an off-centre window, strictly inside the box of
 * \a coarse: the octree keeps its box, so leaves away from them can be kept. */
Cloud
interiorWindow(const Cloud& coarse)
{
  Eigen::Array3f lo = Eigen::Array3f::Constant(1e9f), hi = -lo;
  for (const auto& p : coarse) {
    lo = lo.min(p.getArray3fMap());
    hi = hi.max(p.getArray3fMap());
  }
  const auto window_points =
      offCentreWindow(coarse, *toXYZ(*selseg_test::cubeScan(40000, 12)));
  Cloud fine;
  for (const auto& p : *window_points)
    if ((p.getArray3fMap() > lo + 0.02f).all() &&
        (p.getArray3fMap() < hi - 0.02f).all())
      fine.push_back(p);
  return fine;
}

/** \a coarse extracted with the parameters \a first, then updated with the interior
 * window of a finer scan under \a then; the result must be extract()'s on the union
 * under \a then. \a seg holds the result and the update's statistics. */
void
updateWithInteriorWindow(
    const Cloud::Ptr& coarse,
    const pcl::selective_seg::SelectiveSegmentationParameters& first,
    const pcl::selective_seg::SelectiveSegmentationParameters& then,
    Seg& seg)
{
  const Cloud fine = interiorWindow(*coarse);
  ASSERT_GT(fine.size(), 500u);
  seg.setParameters(first);
  const double voxel = extractFirst(seg, coarse);
  seg.setParameters(then);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.update(fine, clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  Seg ref;
  ref.setParameters(then);
  reference(concat(*coarse, fine), voxel, ref);
  expectSameResult(seg, ref);
}

} // namespace

TEST(SelectiveSegmentationUpdate, RandomFifthOfTheScanEqualsExtractOnTheUnion)
{
  auto scan = toXYZ(*selseg_test::cubeScan(6000, 7));
  std::mt19937 rng(1);
  std::shuffle(scan->begin(), scan->end(), rng);
  const std::size_t split = scan->size() * 4 / 5;
  Seg seg;
  const double voxel = extractFirst(seg, slice(*scan, 0, split));
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.update(*slice(*scan, split, scan->size()), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getUpdateStatistics().new_points, scan->size() - split);
  EXPECT_EQ(seg.getResult().labels.size(), scan->size());
  EXPECT_EQ(seg.getResult().min_voxel_size, voxel);
  Seg ref;
  reference(concat(*slice(*scan, 0, split), *slice(*scan, split, scan->size())),
            voxel,
            ref);
  expectSameResult(seg, ref);
  std::vector<pcl::PointIndices> ref_clusters;
  EXPECT_EQ(clusters.size(), ref.getResult().segments.size());
}

TEST(SelectiveSegmentationUpdate, FinerScanOfAWindowChangesOnlyItsRegion)
{
  const auto coarse = toXYZ(*selseg_test::cubeScan(5000, 11));
  const auto fine = offCentreWindow(*coarse, *toXYZ(*selseg_test::cubeScan(40000, 12)));
  ASSERT_GT(fine->size(), 500u);
  Seg seg;
  seg.setInputCloud(coarse);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.extract(clusters));
  const std::size_t old_triangles = seg.getResult().mesh.triangles.size();
  const double voxel = seg.getResult().min_voxel_size;
  ASSERT_TRUE(seg.update(*fine, clusters));
  const auto& stats = seg.getUpdateStatistics();
  EXPECT_TRUE(stats.incremental);
  EXPECT_EQ(stats.new_vertices, fine->size());
  EXPECT_LT(stats.replaced_triangles, old_triangles / 4);
  EXPECT_GT(stats.new_triangles, 2 * fine->size());
  Seg ref;
  reference(concat(*coarse, *fine), voxel, ref);
  expectSameResult(seg, ref);
}

// New points inside the extent of the old ones leave the octree's box as it was: the
// leaves away from them are kept (most of them), the others made again, and the result
// is still extract()'s on the union. (New points beyond the old extent move the box,
// which is fitted to the points, and every leaf is made again.)
TEST(SelectiveSegmentationUpdate, LeavesAwayFromTheNewPointsAreKept)
{
  Seg seg;
  const auto params = seg.getParameters();
  ASSERT_NO_FATAL_FAILURE(updateWithInteriorWindow(
      toXYZ(*selseg_test::cubeScan(5000, 11)), params, params, seg));
  const auto& stats = seg.getUpdateStatistics();
  const std::size_t leaves = seg.getResult().leaves.size();
  EXPECT_GT(stats.kept_leaves, leaves / 2) << leaves;
  EXPECT_LT(stats.kept_leaves, leaves);
  // Most segments away from the window are taken over from the previous merge.
  const std::size_t segments = seg.getResult().segments.size();
  EXPECT_GT(stats.replayed_segments, segments / 2) << segments;
  EXPECT_LT(stats.replayed_segments, segments);
}

// Over 1,024 leaves the merge grows and takes over segments ahead of their turn on
// several threads (checked at commit): the same result as extract() on the union.
TEST(SelectiveSegmentationUpdate, SegmentsTakenOverAheadOfTheirTurnOnThreads)
{
  Seg seg;
  auto params = seg.getParameters();
  params.num_threads = 3;
  ASSERT_NO_FATAL_FAILURE(updateWithInteriorWindow(
      toXYZ(*selseg_test::cubeScan(40000, 15)), params, params, seg));
  EXPECT_GE(seg.getResult().leaves.size(), 1024u); // the size that runs on threads
  EXPECT_GT(seg.getUpdateStatistics().replayed_segments,
            seg.getResult().segments.size() / 2);
}

// Segments are taken over only from a merge with the same parameters and the facet
// normals in the edge test: a changed merge angle, or vertex-mean edge normals (which
// change with the neighbours' vertex normals), keep the leaves but grow every segment.
TEST(SelectiveSegmentationUpdate, ChangedMergeParametersReplayNoSegment)
{
  const auto coarse = toXYZ(*selseg_test::cubeScan(5000, 11));
  for (const bool vertex_mean : {false, true}) {
    SCOPED_TRACE(vertex_mean);
    Seg seg;
    auto first = seg.getParameters();
    if (vertex_mean)
      first.edge_triangle_normal = pcl::selective_seg::EdgeTriangleNormal::VertexMean;
    auto then = first;
    if (!vertex_mean)
      then.max_merge_angle = 20.0 * M_PI / 180.0;
    ASSERT_NO_FATAL_FAILURE(updateWithInteriorWindow(coarse, first, then, seg));
    EXPECT_GT(seg.getUpdateStatistics().kept_leaves, 0u);
    EXPECT_EQ(seg.getUpdateStatistics().replayed_segments, 0u);
  }
}

// With MergeWith::Segments a grown segment can still be absorbed by a later one: none
// is taken over, before or after the option changes, and the result is still
// extract()'s on the union.
TEST(SelectiveSegmentationUpdate, MergingGrownSegmentsReplaysNoSegment)
{
  const auto coarse = toXYZ(*selseg_test::cubeScan(5000, 11));
  using pcl::selective_seg::MergeWith;
  for (const auto [before, after] :
       {std::pair{MergeWith::Segments, MergeWith::Segments},
        std::pair{MergeWith::Seeds, MergeWith::Segments},
        std::pair{MergeWith::Segments, MergeWith::Seeds}}) {
    SCOPED_TRACE(static_cast<int>(before) * 10 + static_cast<int>(after));
    Seg seg;
    auto first = seg.getParameters();
    first.merge_with = before;
    auto then = first;
    then.merge_with = after;
    ASSERT_NO_FATAL_FAILURE(updateWithInteriorWindow(coarse, first, then, seg));
    EXPECT_GT(seg.getUpdateStatistics().kept_leaves, 0u);
    EXPECT_EQ(seg.getUpdateStatistics().replayed_segments, 0u);
  }
}

TEST(SelectiveSegmentationUpdate, RepeatedUpdatesAndAnyOrderOfTheNewPoints)
{
  auto scan = toXYZ(*selseg_test::cubeScan(8000, 21));
  const std::size_t n = scan->size();
  Seg seg;
  const double voxel = extractFirst(seg, slice(*scan, 0, n / 2));
  std::vector<pcl::PointIndices> clusters;
  auto part = slice(*scan, n / 2, 3 * n / 4);
  std::mt19937 rng(5);
  std::shuffle(part->begin(), part->end(), rng);
  ASSERT_TRUE(seg.update(*part, clusters));
  ASSERT_TRUE(seg.update(*slice(*scan, 3 * n / 4, n), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  auto all = concat(*slice(*scan, 0, n / 2), *part);
  *all += *slice(*scan, 3 * n / 4, n);
  Seg ref;
  reference(all, voxel, ref);
  expectSameResult(seg, ref);
}

TEST(SelectiveSegmentationUpdate, NearerPointOnAnOldRayTakesOverItsVertex)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(4000, 3));
  Seg seg;
  const double voxel = extractFirst(seg, scan);
  std::vector<pcl::PointIndices> clusters;
  // Same directions, 1% nearer (a re-scan of the same rays), plus bad points.
  Cloud extra;
  for (std::size_t i = 0; i < scan->size(); i += 37) {
    const auto& p = (*scan)[i];
    extra.push_back(pcl::PointXYZ(0.99f * p.x, 0.99f * p.y, 0.99f * p.z));
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  extra.push_back(pcl::PointXYZ(nan, 0.0f, 1.0f));
  extra.push_back(pcl::PointXYZ(0.0f, 0.0f, -1.0f));
  ASSERT_TRUE(seg.update(extra, clusters));
  const auto& stats = seg.getUpdateStatistics();
  EXPECT_TRUE(stats.incremental);
  // Float rounding moves a few of the scaled points to a neighbouring direction.
  EXPECT_LT(stats.new_vertices, extra.size() / 4);
  EXPECT_GT(stats.moved_vertices, 0u);
  EXPECT_EQ(seg.getResult().counts.non_finite, 1u);
  EXPECT_EQ(seg.getResult().counts.behind_sensor, 1u);
  Seg ref;
  reference(concat(*scan, extra), voxel, ref);
  expectSameResult(seg, ref);
}

TEST(SelectiveSegmentationUpdate, IndicesAreExtendedByTheNewPoints)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(5000, 4));
  const std::size_t n = scan->size();
  auto old_part = slice(*scan, 0, n / 2);
  auto indices = pcl::make_shared<pcl::Indices>();
  for (std::size_t i = 0; i < old_part->size(); i += 2)
    indices->push_back(static_cast<pcl::index_t>(i));
  Seg seg;
  seg.setInputCloud(old_part);
  seg.setIndices(indices);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.extract(clusters));
  const double voxel = seg.getResult().min_voxel_size;
  ASSERT_TRUE(seg.update(*slice(*scan, n / 2, n), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getResult().counts.outside_indices, old_part->size() - indices->size());

  Seg ref;
  auto all_indices = pcl::make_shared<pcl::Indices>(*indices);
  for (std::size_t i = n / 2; i < n; ++i)
    all_indices->push_back(static_cast<pcl::index_t>(i));
  ref.setIndices(all_indices);
  reference(concat(*old_part, *slice(*scan, n / 2, n)), voxel, ref);
  expectSameResult(seg, ref);
}

TEST(SelectiveSegmentationUpdate, ChangedParametersRunFromScratch)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(5000, 8));
  const std::size_t n = scan->size();
  Seg seg;
  const double voxel = extractFirst(seg, slice(*scan, 0, n / 2));
  std::vector<pcl::PointIndices> clusters;
  seg.setMaxViewIncidenceAngle(80.0 * M_PI / 180.0);
  ASSERT_TRUE(seg.update(*slice(*scan, n / 2, n), clusters));
  EXPECT_FALSE(seg.getUpdateStatistics().incremental);
  Seg ref;
  ref.setMaxViewIncidenceAngle(80.0 * M_PI / 180.0);
  reference(scan, voxel, ref);
  expectSameResult(seg, ref);
}

// The octree's thresholds changed since the result (the mesh is still updated in
// place): no leaf of the previous result is kept, and the result is extract()'s.
TEST(SelectiveSegmentationUpdate, ChangedSplitThresholdKeepsNoLeaf)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(5000, 13));
  const std::size_t n = scan->size();
  Seg seg;
  const double voxel = extractFirst(seg, slice(*scan, 0, n * 3 / 4));
  std::vector<pcl::PointIndices> clusters;
  seg.setMaxNormalStdDev(4.0 * M_PI / 180.0);
  ASSERT_TRUE(seg.update(*slice(*scan, n * 3 / 4, n), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getUpdateStatistics().kept_leaves, 0u);
  Seg ref;
  ref.setMaxNormalStdDev(4.0 * M_PI / 180.0);
  reference(scan, voxel, ref);
  expectSameResult(seg, ref);
}

// A positive finest voxel set before update() replaces the kept one: the result is
// extract()'s on the union with that voxel (in place, no leaf kept: the voxels
// changed).
TEST(SelectiveSegmentationUpdate, VoxelSetBeforeTheUpdateIsUsed)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(5000, 15));
  const std::size_t n = scan->size();
  Seg seg;
  const double voxel = extractFirst(seg, slice(*scan, 0, n * 3 / 4));
  const double larger = 3.0 * voxel;
  seg.setMinVoxelSize(larger);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.update(*slice(*scan, n * 3 / 4, n), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getUpdateStatistics().kept_leaves, 0u);
  EXPECT_EQ(seg.getResult().min_voxel_size, larger);
  Seg ref;
  reference(scan, larger, ref);
  expectSameResult(seg, ref);
}

// The result belongs to the input and indices it was made from: set again since,
// update() segments the union of the current input and the new points from scratch
// (it must not fold the new points into a mesh of other points).
TEST(SelectiveSegmentationUpdate, InputOrIndicesSetAgainRunFromScratch)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(5000, 11));
  const std::size_t n = scan->size();
  const auto old_part = slice(*scan, 0, n / 2);
  const auto new_part = slice(*scan, n / 2, n);
  std::vector<pcl::PointIndices> clusters;
  {
    // Indices set after extract(): every other old point, then the new ones.
    Seg seg;
    const double voxel = extractFirst(seg, old_part);
    auto indices = pcl::make_shared<pcl::Indices>();
    for (std::size_t i = 0; i < old_part->size(); i += 2)
      indices->push_back(static_cast<pcl::index_t>(i));
    seg.setIndices(indices);
    ASSERT_TRUE(seg.update(*new_part, clusters));
    EXPECT_FALSE(seg.getUpdateStatistics().incremental);
    EXPECT_EQ(seg.getResult().counts.outside_indices,
              old_part->size() - indices->size());
    Seg ref;
    auto all_indices = pcl::make_shared<pcl::Indices>(*indices);
    for (std::size_t i = n / 2; i < n; ++i)
      all_indices->push_back(static_cast<pcl::index_t>(i));
    ref.setIndices(all_indices);
    reference(scan, voxel, ref);
    expectSameResult(seg, ref);
    // The same indices again (another vector with the same contents): in place.
    seg.setIndices(pcl::make_shared<pcl::Indices>(*all_indices));
    ASSERT_TRUE(seg.update(Cloud(), clusters));
    EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  }
  {
    // Another cloud of the same size.
    const auto other = toXYZ(*selseg_test::cubeScan(5000, 12));
    const auto other_part = slice(*other, 0, old_part->size());
    Seg seg;
    const double voxel = extractFirst(seg, old_part);
    seg.setInputCloud(other_part);
    ASSERT_TRUE(seg.update(*new_part, clusters));
    EXPECT_FALSE(seg.getUpdateStatistics().incremental);
    Seg ref;
    reference(concat(*other_part, *new_part), voxel, ref);
    expectSameResult(seg, ref);
  }
}

// A failed update() leaves the input and indices as they were; with invalid
// parameters nothing ran, the result is kept and a later update() works.
TEST(SelectiveSegmentationUpdate, FailedUpdateLeavesTheInputAsItWas)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(5000, 14));
  const std::size_t n = scan->size();
  const auto old_part = slice(*scan, 0, n / 2);
  Seg seg;
  const double voxel = extractFirst(seg, old_part);
  const auto labels = seg.getResult().labels;
  std::vector<pcl::PointIndices> clusters;
  seg.setMaxMergeAngle(-1.0);
  EXPECT_FALSE(seg.update(*slice(*scan, n / 2, n), clusters));
  EXPECT_EQ(seg.getInputCloud(), old_part);
  EXPECT_EQ(seg.getResult().labels, labels);
  seg.setMaxMergeAngle(25.0 * M_PI / 180.0);
  ASSERT_TRUE(seg.update(*slice(*scan, n / 2, n), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getUpdateStatistics().new_points, n - n / 2);
  // Refused for its parameters: the statistics are not the call's before it.
  seg.setMaxMergeAngle(-1.0);
  EXPECT_FALSE(seg.update(*slice(*scan, 0, 10), clusters));
  EXPECT_EQ(seg.getUpdateStatistics().new_points, 0u);
  EXPECT_FALSE(seg.getUpdateStatistics().incremental);
  seg.setMaxMergeAngle(25.0 * M_PI / 180.0);
  Seg ref;
  reference(scan, voxel, ref);
  expectSameResult(seg, ref);
  // A stage fails (an index beyond the union): the input and the indices are those
  // before the call.
  const auto input = seg.getInputCloud();
  const auto bad = pcl::make_shared<pcl::Indices>(
      pcl::Indices{0, 1, static_cast<pcl::index_t>(10 * n)});
  seg.setIndices(bad);
  EXPECT_FALSE(seg.update(*slice(*scan, 0, 10), clusters));
  EXPECT_EQ(seg.getInputCloud(), input);
  EXPECT_EQ(seg.getIndices(), bad);
  // A refused call leaves no statistics of the update before it.
  EXPECT_FALSE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getUpdateStatistics().new_points, 0u);
  EXPECT_EQ(seg.getUpdateStatistics().kept_leaves, 0u);
}

TEST(SelectiveSegmentationUpdate, NeedsAResultToUpdate)
{
  Seg seg;
  std::vector<pcl::PointIndices> clusters;
  EXPECT_FALSE(seg.update(Cloud(), clusters));
  EXPECT_TRUE(clusters.empty());
}

TEST(SelectiveSegmentationUpdate, NothingNewChangesNothing)
{
  const auto scan = toXYZ(*selseg_test::cubeScan(3000, 9));
  Seg seg;
  seg.setInputCloud(scan);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.extract(clusters));
  const auto labels = seg.getResult().labels;
  ASSERT_TRUE(seg.update(Cloud(), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  EXPECT_EQ(seg.getUpdateStatistics().new_triangles, 0u);
  EXPECT_EQ(seg.getResult().labels, labels);
  // Every leaf kept: no voxel changed; every segment taken over.
  EXPECT_EQ(seg.getUpdateStatistics().kept_leaves, seg.getResult().leaves.size());
  EXPECT_EQ(seg.getUpdateStatistics().replayed_segments,
            seg.getResult().segments.size());
}

TEST(SelectiveSegmentationUpdate, RingNormalsAndVertexMeanEdgeTestAreUpdatedInPlace)
{
  // The options for noisy scans (docs/evaluation.md): 2- and 3-ring normals.
  for (const int rings : {2, 3}) {
    auto scan = toXYZ(*selseg_test::cubeScan(6000, 30 + rings));
    std::mt19937 rng(rings);
    std::shuffle(scan->begin(), scan->end(), rng);
    const std::size_t split = scan->size() * 9 / 10;
    Seg seg;
    seg.setNormalRings(rings);
    auto params = seg.getParameters();
    params.edge_triangle_normal = pcl::selective_seg::EdgeTriangleNormal::VertexMean;
    seg.setParameters(params);
    const double voxel = extractFirst(seg, slice(*scan, 0, split));
    std::vector<pcl::PointIndices> clusters;
    ASSERT_TRUE(seg.update(*slice(*scan, split, scan->size()), clusters));
    EXPECT_TRUE(seg.getUpdateStatistics().incremental);
    // k-ring normals change beyond the changed triangles: no leaf is kept.
    EXPECT_EQ(seg.getUpdateStatistics().kept_leaves, 0u);
    Seg ref;
    ref.setParameters(params);
    reference(scan, voxel, ref);
    expectSameResult(seg, ref);
  }
}

TEST(SelectiveSegmentationUpdate, NormalsWithoutEdgeOnTrianglesAreUpdatedInPlace)
{
  // PointNormalTriangles::NotEdgeOn: a point normal still depends on its own
  // triangles only (its k-ring's), with the fallback to all of them where every one is
  // edge-on, so an update recomputes it where triangles changed and keeps the leaves
  // elsewhere (one ring).
  for (const int rings : {1, 2}) {
    SCOPED_TRACE(rings);
    Seg seg;
    auto params = seg.getParameters();
    params.point_normal_triangles = pcl::selective_seg::PointNormalTriangles::NotEdgeOn;
    params.normal_rings = rings;
    const auto coarse = toXYZ(*selseg_test::cubeScan(5000, 11));
    ASSERT_NO_FATAL_FAILURE(updateWithInteriorWindow(coarse, params, params, seg));
    if (rings == 1)
      EXPECT_GT(seg.getUpdateStatistics().kept_leaves,
                seg.getResult().leaves.size() / 2);
    // The option is not a no-op on this scan: some point normals differ from the
    // paper's eq. 2 over the same union.
    Seg paper;
    auto paper_params = params;
    paper_params.point_normal_triangles = pcl::selective_seg::PointNormalTriangles::All;
    paper.setParameters(paper_params);
    reference(concat(*coarse, interiorWindow(*coarse)),
              seg.getResult().min_voxel_size,
              paper);
    const auto a = seg.getPointNormals(), b = paper.getPointNormals();
    ASSERT_EQ(a->size(), b->size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a->size(); ++i)
      differ += (*a)[i].getNormalVector3fMap() != (*b)[i].getNormalVector3fMap();
    EXPECT_GT(differ, 0u);
  }
}

TEST(SelectiveSegmentationUpdate, RotatedAndMovedSensorGivesTheSameResultAsExtract)
{
  // The same scan with the sensor posed in the world: normals and leaves are reported
  // in the cloud frame, the mesh and its normals kept in the sensor frame.
  auto scan = toXYZ(*selseg_test::cubeScan(5000, 17));
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  pose.translate(Eigen::Vector3f(1.0f, -2.0f, 0.5f));
  pose.rotate(Eigen::AngleAxisf(0.7f, Eigen::Vector3f(0.3f, 1.0f, -0.2f).normalized()));
  for (auto& p : *scan)
    p.getVector3fMap() = pose * p.getVector3fMap();
  scan->sensor_origin_ << pose.translation(), 0.0f;
  scan->sensor_orientation_ = Eigen::Quaternionf(pose.rotation());
  const std::size_t split = scan->size() * 3 / 4;
  auto first = slice(*scan, 0, split);
  first->sensor_origin_ = scan->sensor_origin_;
  first->sensor_orientation_ = scan->sensor_orientation_;
  Seg seg;
  const double voxel = extractFirst(seg, first);
  std::vector<pcl::PointIndices> clusters;
  ASSERT_TRUE(seg.update(*slice(*scan, split, scan->size()), clusters));
  EXPECT_TRUE(seg.getUpdateStatistics().incremental);
  Seg ref;
  reference(scan, voxel, ref);
  expectSameResult(seg, ref);
}
