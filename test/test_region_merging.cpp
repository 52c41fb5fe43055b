/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 *
 *  Unit tests of the seed merging and triangle classes (paper, Sec. III.D, eq. 6-10).
 */

#include <pcl_selective_seg/region_merging.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <tuple>
#include <vector>

using pcl::selective_seg::classifyTriangles;
using pcl::selective_seg::Incidence;
using pcl::selective_seg::MergeInput;
using pcl::selective_seg::MergeReplay;
using pcl::selective_seg::mergeSeedSegments;
using pcl::selective_seg::seedOrder;
using pcl::selective_seg::Triangle;
using pcl::selective_seg::TriangleClass;
using pcl::selective_seg::Vector3fVector;
using pcl::selective_seg::vertexTriangles;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kThreshold = 25.0 * kDeg; // eq. 8 and 9

/** A unit normal facing the sensor, tilted by \a degrees about the y axis. */
Eigen::Vector3f
tilted(double degrees)
{
  return Eigen::Vector3d(std::sin(degrees * kDeg), 0.0, -std::cos(degrees * kDeg))
      .cast<float>();
}

double
angleDeg(const Eigen::Vector3f& a, const Eigen::Vector3f& b)
{
  const double c = a.cast<double>().normalized().dot(b.cast<double>().normalized());
  return std::acos(std::max(-1.0, std::min(1.0, c))) / kDeg;
}

/** Seeds and a mesh as mergeSeedSegments() takes them. */
struct SeededMesh {
  Vector3fVector leaf_normals;
  std::vector<double> leaf_areas;
  std::vector<pcl::index_t> vertex_leaf;
  std::vector<Triangle> triangles;
  Vector3fVector triangle_normals;
  std::vector<std::uint8_t> edge_on;

  MergeInput input(int threads = 1) const
  {
    MergeInput in;
    in.leaf_normals = &leaf_normals;
    in.leaf_areas = &leaf_areas;
    in.vertex_leaf = &vertex_leaf;
    in.triangles = &triangles;
    in.triangle_normals = &triangle_normals;
    in.triangle_edge_on = &edge_on;
    in.max_merge_angle = kThreshold;
    in.max_edge_triangle_angle = kThreshold;
    in.num_threads = threads;
    return in;
  }
};

/** A strip of 2 x n vertices. Column c holds vertices 2c and 2c + 1; triangles
 * (2c, 2c + 1, 2c + 2) and (2c + 1, 2c + 3, 2c + 2), numbered 2c and 2c + 1, join it to
 * column c + 1. Each column belongs to one leaf (-1: none). A triangle within one leaf
 * gets the leaf's normal, a triangle between two leaves the normal half way between. */
struct Strip : SeededMesh {
  Strip(const std::vector<pcl::index_t>& column_leaf,
        const std::vector<double>& leaf_degrees,
        const std::vector<double>& areas)
  {
    leaf_areas = areas;
    for (const double d : leaf_degrees)
      leaf_normals.push_back(tilted(d));
    for (const auto leaf : column_leaf) {
      vertex_leaf.push_back(leaf);
      vertex_leaf.push_back(leaf);
    }
    for (pcl::index_t c = 0; c + 1 < static_cast<pcl::index_t>(column_leaf.size());
         ++c) {
      triangles.push_back({2 * c, 2 * c + 1, 2 * c + 2});
      triangles.push_back({2 * c + 1, 2 * c + 3, 2 * c + 2});
      const auto a = column_leaf[c], b = column_leaf[c + 1];
      double degrees = 0.0;
      if (a >= 0 && b >= 0)
        degrees = 0.5 * (leaf_degrees[a] + leaf_degrees[b]);
      else if (a >= 0 || b >= 0)
        degrees = leaf_degrees[std::max(a, b)];
      triangle_normals.push_back(tilted(degrees));
      triangle_normals.push_back(tilted(degrees));
    }
    edge_on.assign(triangles.size(), 0);
  }

  /** Set the normal of the two triangles between columns c and c + 1. */
  void setJoinNormal(std::size_t c, const Eigen::Vector3f& normal)
  {
    triangle_normals[2 * c] = normal;
    triangle_normals[2 * c + 1] = normal;
  }

};

struct Merged {
  std::vector<pcl::index_t> leaf_segment;
  Vector3fVector segment_normals;
};

Merged
merge(const MergeInput& in)
{
  Merged m;
  mergeSeedSegments(in, m.leaf_segment, m.segment_normals);
  EXPECT_EQ(m.leaf_segment.size(), in.leaf_normals->size());
  for (const auto s : m.leaf_segment) {
    EXPECT_GE(s, 0);
    EXPECT_LT(s, static_cast<pcl::index_t>(m.segment_normals.size()));
  }
  for (const auto& n : m.segment_normals)
    EXPECT_NEAR(n.norm(), 1.0f, 1e-5f);
  return m;
}

using Segments = std::vector<pcl::index_t>;

} // namespace

TEST(Incidence, Build)
{
  // Items 0..5 in groups {2, none, 0, 2, 1, 0}, 4 groups (group 3 empty).
  const Incidence inc = Incidence::build({2, -1, 0, 2, 1, 0}, 4);
  EXPECT_EQ(inc.offsets, (std::vector<std::size_t>{0, 2, 3, 5, 5}));
  EXPECT_EQ(inc.items, (std::vector<pcl::index_t>{2, 5, 4, 0, 3}));

  const Incidence empty = Incidence::build({-1, -1}, 2);
  EXPECT_EQ(empty.offsets, (std::vector<std::size_t>{0, 0, 0}));
  EXPECT_TRUE(empty.items.empty());
}

TEST(Incidence, VertexTriangles)
{
  // Vertex 5 is isolated.
  const std::vector<Triangle> triangles{{0, 1, 2}, {2, 1, 3}, {3, 4, 2}};
  const Incidence inc = vertexTriangles(triangles, 6);
  EXPECT_EQ(inc.offsets, (std::vector<std::size_t>{0, 1, 3, 6, 8, 9, 9}));
  EXPECT_EQ(inc.items, (std::vector<pcl::index_t>{0, 0, 1, 0, 1, 2, 1, 2, 2}));
}

TEST(ClustersFromLabels, PointsOfEachLabelInIncreasingOrder)
{
  using pcl::selective_seg::clustersFromLabels;
  // Small by hand: label 0 and labels above the count are left out.
  std::vector<pcl::PointIndices> clusters;
  clustersFromLabels({2, 0, 1, 2, 5, 1, 2}, 3, clusters);
  ASSERT_EQ(clusters.size(), 3u);
  EXPECT_EQ(clusters[0].indices, (pcl::Indices{2, 5}));
  EXPECT_EQ(clusters[1].indices, (pcl::Indices{0, 3, 6}));
  EXPECT_TRUE(clusters[2].indices.empty());
  // Large enough for one run per thread: the same lists for 1 to 3 threads.
  std::vector<std::uint32_t> labels(100000);
  for (std::size_t i = 0; i < labels.size(); ++i)
    labels[i] = static_cast<std::uint32_t>((i * 7919) % 13);
  std::vector<pcl::PointIndices> expected(12);
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] > 0)
      expected[labels[i] - 1].indices.push_back(static_cast<pcl::index_t>(i));
  for (const int threads : {1, 2, 3}) {
    clustersFromLabels(labels, 12, clusters, threads);
    ASSERT_EQ(clusters.size(), 12u);
    for (std::size_t l = 0; l < 12; ++l)
      EXPECT_EQ(clusters[l].indices, expected[l].indices) << threads << " threads";
  }
}

TEST(MergeSeedSegments, SimilarSeedsMergeAcrossValidEdge)
{
  // Seeds 10 degrees apart with equal areas; the joining triangles at 5 degrees.
  const Strip strip({0, 0, 1, 1}, {0.0, 10.0}, {1.0, 1.0});
  const Merged m = merge(strip.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 0}));
  ASSERT_EQ(m.segment_normals.size(), 1u);
  // Equal weights: the normalized sum of the two is the bisector, 5 degrees.
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(5.0)), 0.0, 1e-3);
}

TEST(MergeSeedSegments, MissingOrMismatchedArraysGiveEmptyOutputs)
{
  const Strip strip({0, 0, 1, 1}, {0.0, 10.0}, {1.0, 1.0});
  const MergeInput good = strip.input();
  Vector3fVector one_normal(1, Eigen::Vector3f(0.f, 0.f, -1.f));
  std::vector<std::uint8_t> short_flags(1, 0);
  std::vector<pcl::index_t> far_leaf = *good.vertex_leaf;
  far_leaf.back() = 100000000;
  std::vector<Triangle> far_vertex = *good.triangles;
  far_vertex.back()[2] = 100000000;
  std::vector<MergeInput> bad(11, good);
  bad[9].vertex_leaf = &far_leaf;
  bad[10].triangles = &far_vertex;
  bad[0].vertex_leaf = nullptr;
  bad[1].triangles = nullptr;
  bad[2].leaf_areas = nullptr;
  bad[3].triangle_normals = &one_normal;
  bad[4].triangle_edge_on = &short_flags;
  // Angles outside [0, pi]: NaN compared false and merged every reachable seed.
  bad[5].max_merge_angle = std::numeric_limits<double>::quiet_NaN();
  bad[6].max_merge_angle = -0.1;
  bad[7].max_edge_triangle_angle = std::numeric_limits<double>::quiet_NaN();
  bad[8].max_edge_triangle_angle = 4.0;
  for (std::size_t k = 0; k < bad.size(); ++k) {
    SCOPED_TRACE(k);
    std::vector<pcl::index_t> leaf_segment{7};
    Vector3fVector segment_normals(3);
    mergeSeedSegments(bad[k], leaf_segment, segment_normals);
    EXPECT_TRUE(leaf_segment.empty());
    EXPECT_TRUE(segment_normals.empty());
  }
  EXPECT_EQ(merge(good).leaf_segment, (Segments{0, 0}));
}

TEST(MergeSeedSegments, DissimilarSeedsStaySeparate)
{
  // eq. 9: 30 degrees > 25. The joining triangles (15 degrees) are valid for both.
  const Strip strip({0, 0, 1, 1}, {0.0, 30.0}, {1.0, 1.0});
  const Merged m = merge(strip.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 1}));
  ASSERT_EQ(m.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(0.0)), 0.0, 1e-3);
  EXPECT_NEAR(angleDeg(m.segment_normals[1], tilted(30.0)), 0.0, 1e-3);
}

TEST(MergeSeedSegments, MergeAngleThreshold)
{
  EXPECT_EQ(merge(Strip({0, 0, 1, 1}, {0.0, 24.0}, {1.0, 1.0}).input()).leaf_segment,
            (Segments{0, 0}));
  EXPECT_EQ(merge(Strip({0, 0, 1, 1}, {0.0, 26.0}, {1.0, 1.0}).input()).leaf_segment,
            (Segments{0, 1}));
  // A larger threshold merges the 30-degree pair of the previous test.
  Strip strip({0, 0, 1, 1}, {0.0, 30.0}, {1.0, 1.0});
  MergeInput in = strip.input();
  in.max_merge_angle = 35.0 * kDeg;
  EXPECT_EQ(merge(in).leaf_segment, (Segments{0, 0}));
}

TEST(MergeSeedSegments, InvalidEdgeTriangleBlocks)
{
  // eq. 8: seeds 10 degrees apart, but the only triangles joining them are 40 degrees
  // from the first (and 30 from the second).
  Strip strip({0, 0, 1, 1}, {0.0, 10.0}, {1.0, 1.0});
  strip.setJoinNormal(1, tilted(40.0));
  Merged m = merge(strip.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 1}));
  EXPECT_EQ(m.segment_normals.size(), 2u);

  // 20 degrees: within 25 of the first seed's normal, a valid edge.
  strip.setJoinNormal(1, tilted(20.0));
  EXPECT_EQ(merge(strip.input()).leaf_segment, (Segments{0, 0}));

  // One valid triangle among the joining ones suffices.
  strip.setJoinNormal(1, tilted(40.0));
  strip.triangle_normals[3] = tilted(5.0);
  EXPECT_EQ(merge(strip.input()).leaf_segment, (Segments{0, 0}));

  // A degenerate (NaN) joining triangle is never valid.
  strip.setJoinNormal(
      1, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_EQ(merge(strip.input()).leaf_segment, (Segments{0, 1}));
}

TEST(MergeSeedSegments, EdgeOnTriangleBlocks)
{
  Strip strip({0, 0, 1, 1}, {0.0, 10.0}, {1.0, 1.0});
  strip.edge_on[2] = strip.edge_on[3] = 1;
  EXPECT_EQ(merge(strip.input()).leaf_segment, (Segments{0, 1}));
  // Without the flags (or without the optional array) they merge.
  MergeInput in = strip.input();
  in.triangle_edge_on = nullptr;
  EXPECT_EQ(merge(in).leaf_segment, (Segments{0, 0}));
  strip.edge_on[2] = 0;
  EXPECT_EQ(merge(strip.input()).leaf_segment, (Segments{0, 0}));
}

TEST(MergeSeedSegments, LargestSeedStartsFirstSegment)
{
  // Leaf 1 holds 8 vertices, leaf 0 two: leaf 1 starts segment 0.
  Merged m = merge(Strip({0, 1, 1, 1, 1}, {0.0, 30.0}, {1.0, 1.0}).input());
  EXPECT_EQ(m.leaf_segment, (Segments{1, 0}));
  ASSERT_EQ(m.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(30.0)), 0.0, 1e-3);

  // Equal sizes: the smaller leaf index first, wherever it lies in the mesh.
  m = merge(Strip({1, 1, 0, 0}, {0.0, 30.0}, {1.0, 1.0}).input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 1}));
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(0.0)), 0.0, 1e-3);
}

TEST(MergeSeedSegments, OrderDecidesTheChain)
{
  // Seeds A = 0, B = 20, C = 40 degrees, joined A-B-C, equal areas.
  // B largest: B's normal is 20 degrees from both A and C; A is met first (its columns
  // come first), giving N = bisector of 0 and 20 = 10 degrees, 30 from C: {A, B}, {C}.
  Merged m = merge(
      Strip({0, 0, 1, 1, 1, 1, 2, 2}, {0.0, 20.0, 40.0}, {1.0, 1.0, 1.0}).input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 0, 1}));
  // C largest: C takes B (20 degrees), N = 30 degrees, 30 from A: {B, C}, {A}.
  m = merge(
      Strip({0, 0, 1, 1, 2, 2, 2, 2}, {0.0, 20.0, 40.0}, {1.0, 1.0, 1.0}).input());
  EXPECT_EQ(m.leaf_segment, (Segments{1, 0, 0}));
  ASSERT_EQ(m.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(30.0)), 0.0, 1e-3);
  EXPECT_NEAR(angleDeg(m.segment_normals[1], tilted(0.0)), 0.0, 1e-3);
}

// A segment that has grown meets a later one at a valid edge triangle of the later one
// (eq. 8), with the two normals within 25 degrees (eq. 9). Strip A A A C B B, leaf
// normals A = 0, C = 20, B = 40 degrees, A_v = 1, 0.01, 1; triangles A|C at 26 and C|B
// at 35 degrees. A (6 vertices) grows first: A|C is 26 degrees from N_A, invalid, so
// A stays alone. B grows next: C|B is 5 degrees from N_B, valid, and C (20 degrees from
// B) joins: N_BC = n(40) / 1 + n(20) / 0.01 = (34.8448, 0, -94.7353), 20.194 degrees.
// Now A|C is 5.8 degrees from N_BC, valid, and A, 20.194 degrees from it, is a
// neighbouring segment within 25 degrees: MergeWith::Segments absorbs it, N =
// (34.8448, 0, -95.7353), 20.000 degrees; MergeWith::Seeds (the default) leaves it.
TEST(MergeSeedSegments, GrowingSegmentAbsorbsAGrownOneWhenAsked)
{
  Strip strip({0, 0, 0, 1, 2, 2}, {0.0, 20.0, 40.0}, {1.0, 0.01, 1.0});
  strip.setJoinNormal(2, tilted(26.0));
  strip.setJoinNormal(3, tilted(35.0));
  Merged seeds = merge(strip.input());
  EXPECT_EQ(seeds.leaf_segment, (Segments{0, 1, 1}));
  ASSERT_EQ(seeds.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(seeds.segment_normals[1], tilted(20.194138)), 0.0, 1e-3);

  for (const int threads : {1, 3}) {
    MergeInput in = strip.input(threads);
    in.merge_with = pcl::selective_seg::MergeWith::Segments;
    const Merged m = merge(in);
    EXPECT_EQ(m.leaf_segment, (Segments{0, 0, 0}));
    ASSERT_EQ(m.segment_normals.size(), 1u);
    EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(20.0)), 0.0, 1e-3);
  }

  // A at -6 degrees: 26.19 degrees from N_BC, beyond eq. 9's 25: not absorbed.
  Strip apart({0, 0, 0, 1, 2, 2}, {-6.0, 20.0, 40.0}, {1.0, 0.01, 1.0});
  apart.setJoinNormal(2, tilted(26.0));
  apart.setJoinNormal(3, tilted(35.0));
  MergeInput in = apart.input();
  in.merge_with = pcl::selective_seg::MergeWith::Segments;
  const Merged m = merge(in);
  EXPECT_EQ(m.leaf_segment, (Segments{0, 1, 1}));
  ASSERT_EQ(m.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(m.segment_normals[1], tilted(20.194138)), 0.0, 1e-3);
}

TEST(MergeSeedSegments, SegmentNormalIsInverseAreaWeightedMean)
{
  // eq. 7: seeds at 0 degrees (A_v = 1) and 20 degrees (A_v = 4).
  // N' = (0, 0, -1) / 1 + (sin 20, 0, -cos 20) / 4 = (0.0855050, 0, -1.2349232):
  // 3.96 degrees from the first seed (an unweighted mean would give 10, an
  // area-weighted one 16).
  const Strip strip({0, 0, 1, 1}, {0.0, 20.0}, {1.0, 4.0});
  const Merged m = merge(strip.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 0}));
  ASSERT_EQ(m.segment_normals.size(), 1u);
  const Eigen::Vector3f expected =
      Eigen::Vector3f(0.0855050f, 0.0f, -1.2349232f).normalized();
  EXPECT_NEAR(m.segment_normals[0].x(), expected.x(), 1e-5f);
  EXPECT_NEAR(m.segment_normals[0].y(), expected.y(), 1e-5f);
  EXPECT_NEAR(m.segment_normals[0].z(), expected.z(), 1e-5f);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(0.0)), 3.961, 1e-2);
}

TEST(MergeSeedSegments, SegmentNormalWeightedByAreaWhenAsked)
{
  // The seeds of SegmentNormalIsInverseAreaWeightedMean with SegmentNormalWeight::Area:
  // N' = (0, 0, -1) x 1 + (sin 20, 0, -cos 20) x 4 = (1.3680806, 0, -4.7587705),
  // 16.04 degrees from the first seed.
  const Strip strip({0, 0, 1, 1}, {0.0, 20.0}, {1.0, 4.0});
  MergeInput in = strip.input();
  in.segment_normal_weight = pcl::selective_seg::SegmentNormalWeight::Area;
  const Merged m = merge(in);
  EXPECT_EQ(m.leaf_segment, (Segments{0, 0}));
  ASSERT_EQ(m.segment_normals.size(), 1u);
  const Eigen::Vector3f expected =
      Eigen::Vector3f(1.3680806f, 0.0f, -4.7587705f).normalized();
  EXPECT_NEAR((m.segment_normals[0] - expected).norm(), 0.f, 1e-5f);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(0.0)), 16.04, 1e-2);
}

TEST(MergeSeedSegments, RunningSegmentNormal)
{
  // A chain of seeds at 0, 15, 30 and 45 degrees, equal areas; the first is the
  // largest. Seed 1 (15 from N = 0) joins: N = bisector = 7.5. Seed 2 is 22.5 from 7.5
  // and joins: N = normalize(n0 + n15 + n30) = 15 by symmetry. Seed 3 is 30 from 15: it
  // stays out, although it is within 25 degrees of its neighbour seed 2.
  const Strip strip(
      {0, 0, 0, 0, 1, 1, 2, 2, 3, 3}, {0.0, 15.0, 30.0, 45.0}, {1, 1, 1, 1});
  const Merged m = merge(strip.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 0, 0, 1}));
  ASSERT_EQ(m.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(15.0)), 0.0, 1e-3);
  EXPECT_NEAR(angleDeg(m.segment_normals[1], tilted(45.0)), 0.0, 1e-3);
}

TEST(MergeSeedSegments, SeedsWithoutSharedTrianglesStaySeparate)
{
  // Identical normals, but an unassigned column lies between the two seeds: no triangle
  // has vertices in both.
  const Strip strip({0, 0, -1, 1, 1}, {0.0, 0.0}, {1.0, 1.0});
  const Merged m = merge(strip.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 1}));
}

TEST(MergeSeedSegments, TriangleOverThreeSeeds)
{
  // One triangle whose vertices lie in three one-vertex seeds; a fourth seed has no
  // vertex at all and still gets a segment of its own.
  SeededMesh mesh;
  mesh.leaf_normals = {tilted(0.0), tilted(10.0), tilted(-10.0), tilted(0.0)};
  mesh.leaf_areas = {1.0, 1.0, 1.0, 1.0};
  mesh.vertex_leaf = {0, 1, 2};
  mesh.triangles = {{0, 1, 2}};
  mesh.triangle_normals = {tilted(0.0)};
  mesh.edge_on = {0};
  const Merged m = merge(mesh.input());
  EXPECT_EQ(m.leaf_segment, (Segments{0, 0, 0, 1}));
  ASSERT_EQ(m.segment_normals.size(), 2u);
  EXPECT_NEAR(angleDeg(m.segment_normals[0], tilted(0.0)), 0.0, 1e-3);
}

/** A grid of n x n vertices, two triangles per cell, with b x b vertex blocks as leaves
 * (numbered row by row, or in a shuffled order), leaf normals from a smooth field with
 * noise (segments of many sizes, some across the whole grid), triangle normals from
 * their leaves with noise, a few degenerate (NaN) and edge-on triangles, and some
 * vertices in no leaf. */
struct NoisyGrid : SeededMesh {
  NoisyGrid(int n, int b, bool shuffle_leaves, unsigned seed)
  {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int blocks = (n + b - 1) / b;
    std::vector<pcl::index_t> block_leaf(static_cast<std::size_t>(blocks * blocks));
    std::iota(block_leaf.begin(), block_leaf.end(), 0);
    if (shuffle_leaves)
      std::shuffle(block_leaf.begin(), block_leaf.end(), rng);
    leaf_normals.resize(block_leaf.size());
    for (int by = 0; by < blocks; ++by)
      for (int bx = 0; bx < blocks; ++bx) {
        // Four tilted tiles, a ridge and noise: flat regions, sharp and soft edges.
        const double x = static_cast<double>(bx) / blocks,
                     y = static_cast<double>(by) / blocks;
        const double tilt_x = (x < 0.5 ? -20.0 : 20.0) + 15.0 * std::sin(7.0 * y) +
                              14.0 * noise(rng),
                     tilt_y = (y < 0.5 ? -15.0 : 15.0) + 14.0 * noise(rng);
        const Eigen::Vector3d normal =
            Eigen::Vector3d(std::sin(tilt_x * kDeg), std::sin(tilt_y * kDeg), -1.0)
                .normalized();
        leaf_normals[block_leaf[by * blocks + bx]] = normal.cast<float>();
      }
    for (std::size_t l = 0; l < leaf_normals.size(); ++l)
      leaf_areas.push_back(0.5 + unit(rng));
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        vertex_leaf.push_back(unit(rng) < 0.02 ? -1
                                               : block_leaf[(y / b) * blocks + x / b]);
    const auto id = [n](int x, int y) { return static_cast<pcl::index_t>(y * n + x); };
    for (int y = 0; y + 1 < n; ++y)
      for (int x = 0; x + 1 < n; ++x) {
        triangles.push_back({id(x, y), id(x + 1, y), id(x, y + 1)});
        triangles.push_back({id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)});
      }
    for (const auto& t : triangles) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const auto v : t)
        if (vertex_leaf[v] >= 0)
          sum += leaf_normals[vertex_leaf[v]].cast<double>();
      sum += 0.3 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      Eigen::Vector3f normal = sum.normalized().cast<float>();
      if (unit(rng) < 0.01)
        normal.setConstant(std::numeric_limits<float>::quiet_NaN());
      triangle_normals.push_back(normal);
      edge_on.push_back(unit(rng) < 0.02 ? 1 : 0);
    }
  }

};

// The growth of many seeds runs on several threads, each growing the seeds of its part
// of the leaves ahead of their turn; the result must be the one-thread run's, bit for
// bit: the same segment of every leaf, in the same numbering, and the same normals.
// Shuffled leaf numbers make every part a scattered set, so that many grown segments
// meet others and must grow again; over 4,096 seeds run in several windows.
TEST(MergeSeedSegments, SameResultForAnyThreadCount)
{
  const std::vector<std::tuple<int, int, bool>> grids{
      {70, 2, false}, {70, 2, true}, {150, 2, false}, {150, 2, true}, {150, 3, true}};
  for (const auto& [n, b, shuffle] : grids) {
    SCOPED_TRACE(::testing::Message() << n << " " << b << " " << shuffle);
    const NoisyGrid grid(n, b, shuffle, static_cast<unsigned>(n + b));
    ASSERT_GE(grid.leaf_normals.size(), 1024u); // the size that runs on threads
    Merged one;
    mergeSeedSegments(grid.input(1), one.leaf_segment, one.segment_normals);
    // Segments of one leaf and of many: the growth has work to do.
    ASSERT_GT(one.segment_normals.size(), 20u);
    ASSERT_LT(one.segment_normals.size(), grid.leaf_normals.size() / 2);
    for (const int threads : {2, 3, 4}) {
      SCOPED_TRACE(threads);
      Merged many;
      mergeSeedSegments(grid.input(threads), many.leaf_segment, many.segment_normals);
      EXPECT_EQ(many.leaf_segment, one.leaf_segment);
      ASSERT_EQ(many.segment_normals.size(), one.segment_normals.size());
      for (std::size_t s = 0; s < one.segment_normals.size(); ++s)
        ASSERT_EQ(many.segment_normals[s], one.segment_normals[s]) << s;
    }
  }
}

// The octree's leaves can be given in place of the normal and area arrays.
TEST(MergeSeedSegments, LeavesInPlaceOfArrays)
{
  const NoisyGrid grid(70, 2, true, 5);
  std::vector<pcl::selective_seg::AdaptiveLeaf> leaves(grid.leaf_normals.size());
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    leaves[l].normal = grid.leaf_normals[l];
    leaves[l].area = grid.leaf_areas[l];
  }
  for (const int threads : {1, 2}) {
    MergeInput arrays = grid.input(threads);
    MergeInput in_place = arrays;
    in_place.leaf_normals = nullptr;
    in_place.leaf_areas = nullptr;
    in_place.leaves = &leaves;
    Merged a, b;
    mergeSeedSegments(arrays, a.leaf_segment, a.segment_normals);
    mergeSeedSegments(in_place, b.leaf_segment, b.segment_normals);
    EXPECT_EQ(a.leaf_segment, b.leaf_segment);
    EXPECT_EQ(a.segment_normals, b.segment_normals);
  }
}

/** A merge's output with its seeds, and the replay of it for a later merge in which the
 * leaves flagged in \a changed are changed (their segments cannot be taken over). */
struct Replayable {
  Merged merged;
  std::vector<pcl::index_t> seeds;
  std::vector<pcl::index_t> leaf_segment, segment_seed;
  MergeReplay replay;

  explicit Replayable(const MergeInput& in)
  {
    mergeSeedSegments(in, merged.leaf_segment, merged.segment_normals);
    // Segment s grew from its first leaf in the seed order.
    seeds.assign(merged.segment_normals.size(), -1);
    for (const auto l : seedOrder(*in.vertex_leaf, in.leaf_normals->size()))
      if (seeds[merged.leaf_segment[l]] < 0)
        seeds[merged.leaf_segment[l]] = l;
  }

  MergeReplay* forChanged(const std::vector<bool>& changed)
  {
    leaf_segment = merged.leaf_segment;
    segment_seed = seeds;
    for (std::size_t l = 0; l < changed.size(); ++l)
      if (changed[l]) {
        segment_seed[leaf_segment[l]] = -1;
        leaf_segment[l] = -1;
      }
    replay = MergeReplay();
    replay.leaf_segment = &leaf_segment;
    replay.segment_seed = &segment_seed;
    replay.segment_normals = &merged.segment_normals;
    return &replay;
  }
};

// The seed order: most vertices first, ties by leaf index; segments are numbered in
// the order their first leaf in it comes.
TEST(MergeSeedSegments, SeedOrder)
{
  const Strip strip({0, 0, 1, 1, 2, 2, 2, 2}, {0.0, 20.0, 40.0}, {1.0, 1.0, 1.0});
  EXPECT_EQ(seedOrder(strip.vertex_leaf, 3), (Segments{2, 0, 1}));
  EXPECT_EQ(seedOrder({-1, 1, 0, 2, 1, -1}, 4), (Segments{1, 0, 2, 3}));
  const Replayable r(strip.input());
  EXPECT_EQ(r.merged.leaf_segment, (Segments{1, 0, 0})); // C took B; then A
  EXPECT_EQ(r.seeds, (Segments{2, 0}));
  const NoisyGrid grid(70, 2, true, 3);
  Merged m = merge(grid.input(2));
  pcl::index_t next = 0;
  for (const auto l : seedOrder(grid.vertex_leaf, grid.leaf_normals.size())) {
    ASSERT_LE(m.leaf_segment[l], next);
    next = std::max(next, m.leaf_segment[l] + 1);
  }
  EXPECT_EQ(next, static_cast<pcl::index_t>(m.segment_normals.size()));
}

// A previous segment next to a changed leaf that is free at its turn is grown again:
// here the changed leaf now joins it. Taken over, it would have stayed alone.
TEST(MergeSeedSegments, ReplayGrowsAgainNextToAFreeChangedLeaf)
{
  // Before: A = 0 degrees (large), B = 40: two segments.
  Replayable before(Strip({0, 0, 0, 0, 1, 1}, {0.0, 40.0}, {1.0, 1.0}).input());
  ASSERT_EQ(before.merged.leaf_segment, (Segments{0, 1}));
  // Now B is at 10 degrees: A's growth takes it.
  const Strip now({0, 0, 0, 0, 1, 1}, {0.0, 10.0}, {1.0, 1.0});
  for (const int threads : {1, 2}) {
    MergeInput in = now.input(threads);
    in.replay = before.forChanged({false, true});
    Merged m;
    mergeSeedSegments(in, m.leaf_segment, m.segment_normals);
    EXPECT_EQ(m.leaf_segment, (Segments{0, 0}));
    EXPECT_EQ(m.segment_normals, merge(now.input()).segment_normals);
    EXPECT_EQ(in.replay->num_replayed, 0u);
  }
  // Unchanged, A is taken over, and B with it.
  const Strip same({0, 0, 0, 0, 1, 1}, {0.0, 40.0}, {1.0, 1.0});
  MergeInput in = same.input();
  in.replay = before.forChanged({false, false});
  Merged m;
  mergeSeedSegments(in, m.leaf_segment, m.segment_normals);
  EXPECT_EQ(m.leaf_segment, before.merged.leaf_segment);
  EXPECT_EQ(m.segment_normals, before.merged.segment_normals);
  EXPECT_EQ(in.replay->num_replayed, 2u);
}

// Taking segments over gives the merge's own result, bit for bit, for any thread count:
// with nothing changed (every segment taken over), and with a random tenth of the
// leaves changed (a new normal; their segments grow again, and so do the unchanged
// segments whose neighbourhood is not in the state it was).
TEST(MergeSeedSegments, ReplayGivesTheMergesOwnResult)
{
  for (const auto& [n, shuffle] :
       std::vector<std::pair<int, bool>>{{70, false}, {150, true}}) {
    SCOPED_TRACE(::testing::Message() << n << " " << shuffle);
    const NoisyGrid grid(n, 2, shuffle, static_cast<unsigned>(n));
    Replayable before(grid.input(1));
    const std::size_t num_segments = before.merged.segment_normals.size();
    ASSERT_GT(num_segments, 20u);
    NoisyGrid changed_grid = grid;
    std::vector<bool> changed(grid.leaf_normals.size(), false);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (std::size_t l = 0; l < changed.size(); ++l)
      if (unit(rng) < 0.1) {
        changed[l] = true;
        changed_grid.leaf_normals[l] =
            Eigen::Vector3f(static_cast<float>(unit(rng) - 0.5), 0.2f, -1.0f)
                .normalized();
      }
    for (const int threads : {1, 2, 3}) {
      SCOPED_TRACE(threads);
      MergeInput in = grid.input(threads);
      in.replay = before.forChanged(std::vector<bool>(changed.size(), false));
      Merged same;
      mergeSeedSegments(in, same.leaf_segment, same.segment_normals);
      EXPECT_EQ(same.leaf_segment, before.merged.leaf_segment);
      EXPECT_EQ(same.segment_normals, before.merged.segment_normals);
      EXPECT_EQ(in.replay->num_replayed, num_segments);

      const Merged expected = merge(changed_grid.input(threads));
      in = changed_grid.input(threads);
      in.replay = before.forChanged(changed);
      Merged m;
      mergeSeedSegments(in, m.leaf_segment, m.segment_normals);
      EXPECT_EQ(m.leaf_segment, expected.leaf_segment);
      EXPECT_EQ(m.segment_normals, expected.segment_normals);
      EXPECT_GT(in.replay->num_replayed, 0u);
      EXPECT_LT(in.replay->num_replayed, expected.segment_normals.size());
    }
  }
}

TEST(ClassifyTriangles, Classes)
{
  // Label 1: normal 0 degrees; label 2: 40 degrees; label 3: -60 degrees.
  const Vector3fVector label_normals{tilted(0.0), tilted(40.0), tilted(-60.0)};
  const std::vector<std::uint32_t> vertex_labels{1, 1, 1, 2, 2, 0, 0, 3};
  const std::vector<Triangle> triangles{
      {0, 1, 2}, // interior of 1
      {0, 1, 3}, // 1 and 2, normal 30: 10 from label 2 -> valid edge of 2
      {0, 3, 4}, // 1 and 2, normal 5: 5 from label 1 -> valid edge of 1
      {1, 2, 3}, // 1 and 2, normal -30: 30 from 1, 70 from 2 -> invalid, label 1
      {0, 3, 1}, // 1 and 2, normal 38 but seen edge-on -> invalid, label 2
      {5, 6, 5}, // no label
      {5, 6, 7}, // only label 3, normal -55 -> valid edge of 3
      {3, 4, 5}, // 2 and unlabeled, normal 40: not interior, valid edge of 2
      {2, 3, 7}, // 1, 2 and 3, normal 100 -> invalid; closest is 2 (60 degrees)
  };
  const Vector3fVector normals{tilted(0.0),
                               tilted(30.0),
                               tilted(5.0),
                               tilted(-30.0),
                               tilted(38.0),
                               tilted(0.0),
                               tilted(-55.0),
                               tilted(40.0),
                               tilted(100.0)};
  std::vector<std::uint8_t> edge_on(triangles.size(), 0);
  edge_on[4] = 1;
  std::vector<std::uint32_t> labels;
  std::vector<TriangleClass> classes;
  classifyTriangles(triangles,
                    normals,
                    &edge_on,
                    vertex_labels,
                    label_normals,
                    kThreshold,
                    labels,
                    classes);
  const std::vector<std::uint32_t> expected_labels{1, 2, 1, 1, 2, 0, 3, 2, 2};
  const std::vector<TriangleClass> expected_classes{TriangleClass::Interior,
                                                    TriangleClass::ValidEdge,
                                                    TriangleClass::ValidEdge,
                                                    TriangleClass::InvalidEdge,
                                                    TriangleClass::InvalidEdge,
                                                    TriangleClass::InvalidEdge,
                                                    TriangleClass::ValidEdge,
                                                    TriangleClass::ValidEdge,
                                                    TriangleClass::InvalidEdge};
  EXPECT_EQ(labels, expected_labels);
  EXPECT_EQ(classes, expected_classes);

  // Without the edge-on array triangle 4 is a valid edge of 2 (2 degrees).
  classifyTriangles(triangles,
                    normals,
                    nullptr,
                    vertex_labels,
                    label_normals,
                    kThreshold,
                    labels,
                    classes);
  EXPECT_EQ(labels[4], 2u);
  EXPECT_EQ(classes[4], TriangleClass::ValidEdge);
}

TEST(ClassifyTriangles, MismatchedArraysOrAnglesGiveEmptyOutputs)
{
  const Vector3fVector label_normals{tilted(0.0), tilted(40.0)};
  const std::vector<std::uint32_t> vertex_labels{1, 1, 1, 2};
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 1, 3}};
  const Vector3fVector normals{tilted(0.0), tilted(30.0)};
  const Vector3fVector one_normal{tilted(0.0)};
  const std::vector<std::uint8_t> one_flag{0};
  const auto classify = [&](const Vector3fVector& n,
                            const std::vector<std::uint8_t>* flags,
                            double angle) {
    std::vector<std::uint32_t> labels{9};
    std::vector<TriangleClass> classes{TriangleClass::Interior};
    classifyTriangles(
        triangles, n, flags, vertex_labels, label_normals, angle, labels, classes);
    EXPECT_EQ(labels.size(), classes.size());
    return labels.size();
  };
  EXPECT_EQ(classify(normals, nullptr, 25.0 * kDeg), 2u);
  EXPECT_EQ(classify(one_normal, nullptr, 25.0 * kDeg), 0u);
  EXPECT_EQ(classify(normals, &one_flag, 25.0 * kDeg), 0u);
  EXPECT_EQ(classify(normals, nullptr, std::numeric_limits<double>::quiet_NaN()), 0u);
  EXPECT_EQ(classify(normals, nullptr, -1.0), 0u);
}

// Ids beyond the arrays they index are refused with a message, not read out of
// bounds: a triangle's vertex beyond vertex_labels / vertex_leaf, a leaf beyond the
// leaves, a label without a normal, a group beyond the groups.
TEST(ClassifyTriangles, IdsBeyondTheArraysAreRefused)
{
  const Vector3fVector label_normals{tilted(0.0), tilted(40.0)};
  const Vector3fVector normals{tilted(0.0), tilted(30.0)};
  std::vector<std::uint32_t> labels{9};
  std::vector<TriangleClass> classes{TriangleClass::Interior};
  classifyTriangles({{0, 1, 2}, {0, 1, 100000000}},
                    normals,
                    nullptr,
                    {1, 1, 1, 2},
                    label_normals,
                    25.0 * kDeg,
                    labels,
                    classes);
  EXPECT_TRUE(labels.empty() && classes.empty());
  classifyTriangles({{0, 1, 2}, {0, 1, 3}},
                    normals,
                    nullptr,
                    {1, 1, 1, 3}, // label 3 has no normal
                    label_normals,
                    25.0 * kDeg,
                    labels,
                    classes);
  EXPECT_TRUE(labels.empty() && classes.empty());
  EXPECT_TRUE(seedOrder({0, 1, 100000000}, 2).empty());
  EXPECT_EQ(seedOrder({0, 1, 1, -1}, 2), (std::vector<pcl::index_t>{1, 0}));
  const Incidence bad = vertexTriangles({{0, 1, 5}}, 3);
  EXPECT_EQ(bad.offsets, (std::vector<std::size_t>(4, 0)));
  EXPECT_TRUE(bad.items.empty());
  const Incidence groups = Incidence::build({0, 7, -1}, 2);
  EXPECT_EQ(groups.offsets, (std::vector<std::size_t>(3, 0)));
  EXPECT_TRUE(groups.items.empty());
}

TEST(ClassifyTriangles, InteriorIgnoresNormal)
{
  // Interior triangles keep their label whatever their normal, even a NaN one.
  const Vector3fVector label_normals{tilted(0.0)};
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 2, 1}};
  const Vector3fVector normals{
      tilted(90.0), Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN())};
  std::vector<std::uint32_t> labels;
  std::vector<TriangleClass> classes;
  classifyTriangles(triangles,
                    normals,
                    nullptr,
                    {1, 1, 1},
                    label_normals,
                    kThreshold,
                    labels,
                    classes);
  EXPECT_EQ(labels, (std::vector<std::uint32_t>{1, 1}));
  EXPECT_EQ(classes[0], TriangleClass::Interior);
  EXPECT_EQ(classes[1], TriangleClass::Interior);
}

TEST(ClassifyTriangles, DegenerateEdgeTriangleIsInvalid)
{
  const Vector3fVector label_normals{tilted(0.0), tilted(0.0)};
  const std::vector<Triangle> triangles{{0, 1, 2}};
  const Vector3fVector normals{
      Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN())};
  std::vector<std::uint32_t> labels;
  std::vector<TriangleClass> classes;
  classifyTriangles(triangles,
                    normals,
                    nullptr,
                    {1, 2, 2},
                    label_normals,
                    kThreshold,
                    labels,
                    classes);
  ASSERT_EQ(labels.size(), 1u);
  // Every label scores alike: the tie goes to the smallest.
  EXPECT_EQ(labels[0], 1u);
  EXPECT_EQ(classes[0], TriangleClass::InvalidEdge);
}

TEST(ClassifyTriangles, EquallyCloseLabelsTieOnTheSmallest)
{
  // Two segments with bitwise-equal normals (parallel planes) and a triangle 10 deg
  // from both: the smaller label, whichever corner carries it, and a valid edge.
  const Vector3fVector label_normals{tilted(0.0), tilted(0.0)};
  std::vector<std::uint32_t> labels;
  std::vector<TriangleClass> classes;
  for (const std::vector<std::uint32_t>& corners :
       {std::vector<std::uint32_t>{2, 1, 2}, std::vector<std::uint32_t>{1, 2, 2}}) {
    classifyTriangles({{0, 1, 2}},
                      {tilted(10.0)},
                      nullptr,
                      corners,
                      label_normals,
                      kThreshold,
                      labels,
                      classes);
    ASSERT_EQ(labels.size(), 1u);
    EXPECT_EQ(labels[0], 1u);
    EXPECT_EQ(classes[0], TriangleClass::ValidEdge);
  }
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
