/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 *
 *  Unit tests of the triangle and point normals (paper, Sec. III.B, eq. 2-3).
 */

#include <pcl_selective_seg/delaunay_2d.h>
#include <pcl_selective_seg/mesh_normals.h>
#include <pcl_selective_seg/parameters.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

using pcl::selective_seg::computeTriangleNormals;
using pcl::selective_seg::computeVertexNormals;
using pcl::selective_seg::markEdgeOnTriangles;
using pcl::selective_seg::medianEdgeLength;
using pcl::selective_seg::Triangle;
using pcl::selective_seg::Vector3fVector;

namespace {

constexpr double kDeg = M_PI / 180.0;
const float kNaN = std::numeric_limits<float>::quiet_NaN();

void
expectVectorNear(const Eigen::Vector3f& actual,
                 const Eigen::Vector3f& expected,
                 float tolerance = 1e-6f)
{
  EXPECT_NEAR(actual.x(), expected.x(), tolerance);
  EXPECT_NEAR(actual.y(), expected.y(), tolerance);
  EXPECT_NEAR(actual.z(), expected.z(), tolerance);
}

/** Three vertices around \a centre in the plane through it with unit normal \a normal,
 * at distance \a radius, 120 degrees apart: their centroid is \a centre. */
Vector3fVector
equilateralAround(const Eigen::Vector3d& centre,
                  const Eigen::Vector3d& normal,
                  double radius)
{
  const Eigen::Vector3d u = normal.unitOrthogonal();
  const Eigen::Vector3d w = normal.cross(u);
  Vector3fVector vertices;
  for (int k = 0; k < 3; ++k) {
    const double a = k * 2.0 * M_PI / 3.0;
    vertices.push_back(
        (centre + radius * (std::cos(a) * u + std::sin(a) * w)).cast<float>());
  }
  return vertices;
}

} // namespace

TEST(MeshNormals, RightTriangleNormalAndArea)
{
  // Legs 3 and 4 in the plane z = 5: area 3 * 4 / 2 = 6, normal -z toward the origin.
  const Vector3fVector positions{{0.f, 0.f, 5.f}, {3.f, 0.f, 5.f}, {0.f, 4.f, 5.f}};
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 2, 1}, {2, 1, 0}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  ASSERT_EQ(normals.size(), 3u);
  ASSERT_EQ(areas.size(), 3u);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    SCOPED_TRACE(t);
    EXPECT_NEAR(areas[t], 6.0, 1e-12);
    expectVectorNear(normals[t], Eigen::Vector3f(0.f, 0.f, -1.f));
  }
}

TEST(MeshNormals, TiltedRightTriangle)
{
  // Legs 3 along x and 4 along (0, 1, 1) / sqrt 2 from a = (1, 1, 5). The plane's
  // normal is x cross (0, 1, 1) / sqrt 2 = (0, -1, 1) / sqrt 2; the centroid is at
  // z > 5 and y > 1 with z - y > 0, so the normal facing the origin is (0, 1, -1) /
  // sqrt 2.
  const float h = static_cast<float>(4.0 / std::sqrt(2.0));
  const Vector3fVector positions{
      {1.f, 1.f, 5.f}, {4.f, 1.f, 5.f}, {1.f, 1.f + h, 5.f + h}};
  const std::vector<Triangle> triangles{{0, 1, 2}, {1, 0, 2}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  const float s = static_cast<float>(1.0 / std::sqrt(2.0));
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    SCOPED_TRACE(t);
    EXPECT_NEAR(areas[t], 6.0, 1e-5);
    expectVectorNear(normals[t], Eigen::Vector3f(0.f, s, -s));
  }
}

TEST(MeshNormals, OrientedTowardViewpoint)
{
  // The same triangle seen from either side: the normal follows the viewpoint.
  const Vector3fVector positions{{0.f, 0.f, 5.f}, {3.f, 0.f, 5.f}, {0.f, 4.f, 5.f}};
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 2, 1}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(
      positions, triangles, Eigen::Vector3f(1.f, 1.f, 10.f), normals, areas);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    SCOPED_TRACE(t);
    expectVectorNear(normals[t], Eigen::Vector3f(0.f, 0.f, 1.f));
    EXPECT_NEAR(areas[t], 6.0, 1e-12);
  }
  // Seen from the side at x = -10, the plane x = 0 faces -x.
  const Vector3fVector wall{{0.f, 0.f, 1.f}, {0.f, 2.f, 1.f}, {0.f, 0.f, 3.f}};
  computeTriangleNormals(
      wall, triangles, Eigen::Vector3f(-10.f, 0.f, 0.f), normals, areas);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    SCOPED_TRACE(t);
    expectVectorNear(normals[t], Eigen::Vector3f(-1.f, 0.f, 0.f));
    EXPECT_NEAR(areas[t], 2.0, 1e-12);
  }
}

TEST(MeshNormals, DegenerateTriangles)
{
  const Vector3fVector positions{
      {0.f, 0.f, 1.f}, {1.f, 1.f, 1.f}, {2.f, 2.f, 1.f}, {0.f, 1.f, 1.f}};
  // Collinear vertices; a repeated vertex; a proper triangle as control.
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 0, 3}, {0, 1, 3}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  for (std::size_t t = 0; t < 2; ++t) {
    SCOPED_TRACE(t);
    EXPECT_TRUE(std::isnan(normals[t].x()));
    EXPECT_TRUE(std::isnan(normals[t].y()));
    EXPECT_TRUE(std::isnan(normals[t].z()));
    EXPECT_EQ(areas[t], 0.0);
  }
  EXPECT_NEAR(areas[2], 0.5, 1e-12);
  expectVectorNear(normals[2], Eigen::Vector3f(0.f, 0.f, -1.f));
}

TEST(MeshNormals, FlatnessBoundIsTwiceFloatRoundingOfTheLargestCorner)
{
  // The documented bound: a triangle whose height on its longest edge is at most
  // 2 FLT_EPSILON max |corner| has no normal. Corners (0, 0, 2), (0.25, h, 2) and
  // (0.5, 0, 2): the longest edge lies on the x axis, so the height is h exactly, and
  // max |corner| = |(0.5, 0, 2)|. h = 1.5 of the unit: degenerate; 2.5: a normal.
  const double unit = std::numeric_limits<float>::epsilon() * std::sqrt(0.25 + 4.0);
  for (const double k : {1.5, 2.5}) {
    const Vector3fVector positions{
        {0.f, 0.f, 2.f}, {0.25f, static_cast<float>(k * unit), 2.f}, {0.5f, 0.f, 2.f}};
    Vector3fVector normals;
    std::vector<double> areas;
    std::vector<std::uint8_t> edge_on;
    pcl::selective_seg::computeTriangleNormalsAndEdgeOn(positions,
                                                        {{0, 1, 2}},
                                                        Eigen::Vector3f::Zero(),
                                                        M_PI / 2.0,
                                                        normals,
                                                        areas,
                                                        edge_on);
    ASSERT_EQ(normals.size(), 1u);
    EXPECT_EQ(normals[0].allFinite(), k > 2.0) << k << " units high";
    EXPECT_NEAR(areas[0], 0.5 * 0.5 * static_cast<float>(k * unit), 1e-20);
  }
}

TEST(MeshNormals, TrianglesFlatAtFloatPrecisionAreDegenerate)
{
  // Three points of a line in 3-D, rounded to float: a triangle of non-zero area whose
  // height (about 1.2e-7 m, under FLT_EPSILON * |p| = 2.4e-7 m) is rounding alone, so
  // its normal is noise. It gets no normal, is edge-on, and leaves eq. 2 to the
  // triangle that has one; its area is kept. Lifting the middle point by 8 ulps (h
  // about 8 FLT_EPSILON * |p|) gives a triangle whose normal is determined.
  const Eigen::Vector3d start(0.3, 0.2, 2.0), step(0.01, 0.003, 0.002);
  Vector3fVector positions;
  for (int i = 0; i < 3; ++i)
    positions.push_back((start + i * step).cast<float>());
  positions.push_back(Eigen::Vector3f(0.31f, 0.25f, 2.0f));
  Eigen::Vector3f lifted = positions[1];
  for (int i = 0; i < 8; ++i)
    lifted.z() = std::nextafter(lifted.z(), 3.f);
  positions.push_back(lifted);
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 1, 3}, {0, 4, 2}};
  Vector3fVector normals;
  std::vector<double> areas;
  std::vector<std::uint8_t> edge_on;
  pcl::selective_seg::computeTriangleNormalsAndEdgeOn(positions,
                                                      triangles,
                                                      Eigen::Vector3f::Zero(),
                                                      85.0 * kDeg,
                                                      normals,
                                                      areas,
                                                      edge_on);
  ASSERT_GT(areas[0], 0.0); // not collinear in float
  const double longest = (positions[2] - positions[0]).cast<double>().norm();
  EXPECT_LT(2.0 * areas[0] / longest,
            std::numeric_limits<float>::epsilon() * positions[2].norm());
  EXPECT_FALSE(normals[0].allFinite());
  EXPECT_EQ(edge_on[0], 1);
  ASSERT_TRUE(normals[1].allFinite());
  EXPECT_TRUE(normals[2].allFinite());
  Vector3fVector vertex_normals;
  std::vector<double> vertex_areas;
  const std::vector<Triangle> star{triangles[0], triangles[1]};
  const Vector3fVector star_normals{normals[0], normals[1]};
  const std::vector<double> star_areas{areas[0], areas[1]};
  computeVertexNormals(5, star, star_normals, star_areas, vertex_normals, vertex_areas);
  expectVectorNear(vertex_normals[0], normals[1]);
  EXPECT_EQ(vertex_areas[0], areas[0] + areas[1]);
  EXPECT_FALSE(vertex_normals[2].allFinite()); // only on the flat triangle
  // computeTriangleNormals() agrees.
  Vector3fVector normals_alone;
  std::vector<double> areas_alone;
  computeTriangleNormals(
      positions, triangles, Eigen::Vector3f::Zero(), normals_alone, areas_alone);
  EXPECT_FALSE(normals_alone[0].allFinite());
  EXPECT_EQ(areas_alone[0], areas[0]);
}

TEST(MeshNormals, HugeCoordinatesGiveFiniteArea)
{
  // Legs of 1e30: the area 5e59 overflows a float (max 3.4e38) but not a double.
  const float big = 1e30f;
  const Vector3fVector positions{{0.f, 0.f, big}, {big, 0.f, big}, {0.f, big, big}};
  const std::vector<Triangle> triangles{{0, 1, 2}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  const double leg = static_cast<double>(big);
  ASSERT_TRUE(std::isfinite(areas[0]));
  EXPECT_NEAR(areas[0] / (0.5 * leg * leg), 1.0, 1e-12);
  ASSERT_TRUE(normals[0].allFinite());
  expectVectorNear(normals[0], Eigen::Vector3f(0.f, 0.f, -1.f));
}

TEST(MeshNormals, VertexNormalIsInverseAreaWeightedMean)
{
  // Vertex 0 is shared by t0 (normal -z, area 1) and t1 (normal (0.6, 0, -0.8), area
  // 4). Eq. 2: N' = (0, 0, -1) / 1 + (0.6, 0, -0.8) / 4 = (0.15, 0, -1.2), |N'| =
  // sqrt(0.0225 + 1.44) = sqrt(1.4625). Eq. 3: A_0 = 1 + 4 = 5.
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 3, 4}};
  const Vector3fVector normals{{0.f, 0.f, -1.f}, {0.6f, 0.f, -0.8f}};
  const std::vector<double> areas{1.0, 4.0};
  Vector3fVector vertex_normals;
  std::vector<double> vertex_areas;
  computeVertexNormals(5, triangles, normals, areas, vertex_normals, vertex_areas);
  ASSERT_EQ(vertex_normals.size(), 5u);
  ASSERT_EQ(vertex_areas.size(), 5u);

  const double norm = std::sqrt(1.4625);
  expectVectorNear(vertex_normals[0],
                   Eigen::Vector3f(static_cast<float>(0.15 / norm),
                                   0.f,
                                   static_cast<float>(-1.2 / norm)));
  EXPECT_NEAR(vertex_areas[0], 5.0, 1e-12);
  // The 1/A weighting pulls the normal toward the small triangle's: about 7.1 degrees
  // from -z, whereas an unweighted mean would sit at 18.4 degrees.
  EXPECT_NEAR(std::acos(-vertex_normals[0].z()), std::atan2(0.15, 1.2), 1e-6);

  for (const int v : {1, 2}) {
    expectVectorNear(vertex_normals[v], Eigen::Vector3f(0.f, 0.f, -1.f));
    EXPECT_NEAR(vertex_areas[v], 1.0, 1e-12);
  }
  for (const int v : {3, 4}) {
    expectVectorNear(vertex_normals[v], Eigen::Vector3f(0.6f, 0.f, -0.8f));
    EXPECT_NEAR(vertex_areas[v], 4.0, 1e-12);
  }
}

TEST(MeshNormals, VertexNormalsFromGeometry)
{
  // Vertex 0 at (0, 0, 2), seen from the origin, lies on t0 in the plane z = 2 (legs 1
  // and 1: area 0.5, normal -z) and on t1 in the plane z = 2 + y (legs sqrt 2 along
  // (0, -1, -1) and 2 along x: area sqrt 2, normal (0, 1, -1) / sqrt 2 facing the
  // origin).
  const Vector3fVector positions{{0.f, 0.f, 2.f},
                                 {1.f, 0.f, 2.f},
                                 {0.f, 1.f, 2.f},
                                 {0.f, -1.f, 1.f},
                                 {2.f, 0.f, 2.f}};
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 3, 4}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  EXPECT_NEAR(areas[0], 0.5, 1e-12);
  EXPECT_NEAR(areas[1], std::sqrt(2.0), 1e-6);
  const double s = 1.0 / std::sqrt(2.0);
  expectVectorNear(normals[1], Eigen::Vector3f(0.f, s, -s));

  Vector3fVector vertex_normals;
  std::vector<double> vertex_areas;
  computeVertexNormals(5, triangles, normals, areas, vertex_normals, vertex_areas);
  // N' = (0, 0, -1) / 0.5 + (0, s, -s) / sqrt 2 = (0, 0.5, -2.5).
  const Eigen::Vector3d expected = Eigen::Vector3d(0.0, 0.5, -2.5).normalized();
  expectVectorNear(vertex_normals[0], expected.cast<float>());
  EXPECT_NEAR(vertex_areas[0], 0.5 + std::sqrt(2.0), 1e-6);
}

TEST(MeshNormals, DegenerateTrianglesSkipped)
{
  // t1 is degenerate (area 0, NaN normal), t2 has a non-finite area: neither may
  // contribute to vertex 0's normal, and both must leave its area finite.
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 1, 3}, {0, 2, 3}};
  const Vector3fVector normals{
      {0.f, 0.f, -1.f}, Eigen::Vector3f::Constant(kNaN), {1.f, 0.f, 0.f}};
  const std::vector<double> areas{2.0, 0.0, std::numeric_limits<double>::infinity()};
  Vector3fVector vertex_normals;
  std::vector<double> vertex_areas;
  computeVertexNormals(4, triangles, normals, areas, vertex_normals, vertex_areas);
  expectVectorNear(vertex_normals[0], Eigen::Vector3f(0.f, 0.f, -1.f));
  EXPECT_NEAR(vertex_areas[0], 2.0, 1e-12);
  // Vertex 3 lies only on the skipped triangles.
  EXPECT_FALSE(vertex_normals[3].allFinite());
  EXPECT_TRUE(std::isfinite(vertex_areas[3]));
  EXPECT_EQ(vertex_areas[3], 0.0);
}

TEST(MeshNormals, IsolatedVertexAndCancellingNormals)
{
  // Vertex 3 is in no triangle. Vertex 0 sees two opposite normals with equal areas:
  // the weighted sum is zero and there is no normal.
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 2, 1}};
  const Vector3fVector normals{{0.f, 0.f, -1.f}, {0.f, 0.f, 1.f}};
  const std::vector<double> areas{1.0, 1.0};
  Vector3fVector vertex_normals;
  std::vector<double> vertex_areas;
  computeVertexNormals(4, triangles, normals, areas, vertex_normals, vertex_areas);
  EXPECT_TRUE(std::isnan(vertex_normals[3].x()));
  EXPECT_TRUE(std::isnan(vertex_normals[3].y()));
  EXPECT_TRUE(std::isnan(vertex_normals[3].z()));
  EXPECT_EQ(vertex_areas[3], 0.0);
  EXPECT_FALSE(vertex_normals[0].allFinite());
  EXPECT_NEAR(vertex_areas[0], 2.0, 1e-12);
}

TEST(MeshNormals, EdgeOnHeadOnAndGrazing)
{
  // t0 faces the origin head-on (its centroid on the z axis); t1 lies in the plane
  // y = 0, which contains the line of sight to its centroid (0, 0, 16/3).
  const Vector3fVector positions{{-1.f, -1.f, 5.f},
                                 {2.f, -1.f, 5.f},
                                 {-1.f, 2.f, 5.f},
                                 {0.f, 0.f, 4.f},
                                 {1.f, 0.f, 6.f},
                                 {-1.f, 0.f, 6.f}};
  const std::vector<Triangle> triangles{{0, 1, 2}, {3, 4, 5}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  std::vector<std::uint8_t> edge_on;
  for (const double max_incidence : {1.0 * kDeg, 45.0 * kDeg, 89.0 * kDeg}) {
    SCOPED_TRACE(max_incidence);
    markEdgeOnTriangles(
        positions, triangles, normals, Eigen::Vector3f::Zero(), max_incidence, edge_on);
    ASSERT_EQ(edge_on.size(), 2u);
    EXPECT_EQ(edge_on[0], 0);
    EXPECT_EQ(edge_on[1], 1);
  }
  // From far along +x the head-on triangle is seen at grazing incidence.
  markEdgeOnTriangles(positions,
                      triangles,
                      normals,
                      Eigen::Vector3f(1000.f, 0.f, 5.f),
                      80.0 * kDeg,
                      edge_on);
  EXPECT_EQ(edge_on[0], 1);
}

// Ring counts below 1 and incidence angles that are NaN or negative are refused with
// a message: empty outputs, in-place arrays as they were (rings 0 gave NaN normals,
// a NaN angle flagged nothing, a negative one acted as its absolute value).
TEST(MeshNormals, UnusableRingsOrIncidenceAreRefused)
{
  using namespace pcl::selective_seg;
  const std::vector<Triangle> tris{{0, 1, 2}, {1, 3, 2}};
  const Vector3fVector n{Eigen::Vector3f(0, 0, -1), Eigen::Vector3f(0, 0, -1)};
  const std::vector<double> areas{1.0, 1.0};
  Vector3fVector ring_normals(3);
  computeVertexNormalsOverRings(4, tris, n, areas, 0, ring_normals);
  EXPECT_TRUE(ring_normals.empty());
  computeVertexNormalsOverRings(4, tris, n, areas, 1, ring_normals);
  ASSERT_EQ(ring_normals.size(), 4u);
  Vector3fVector missing(4, Eigen::Vector3f::Constant(NAN));
  EXPECT_EQ(fillMissingVertexNormals(tris, n, areas, 0, missing), 0u);
  EXPECT_FALSE(missing[0].allFinite());
  EXPECT_EQ(fillMissingVertexNormals(tris, n, areas, 1, missing), 4u);

  const Vector3fVector positions{Eigen::Vector3f(0, 0, 5),
                                 Eigen::Vector3f(1, 0, 5),
                                 Eigen::Vector3f(0, 1, 5),
                                 Eigen::Vector3f(1, 1, 5)};
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), -0.5}) {
    SCOPED_TRACE(bad);
    std::vector<std::uint8_t> edge_on{1, 1, 1};
    markEdgeOnTriangles(positions, tris, n, Eigen::Vector3f::Zero(), bad, edge_on);
    EXPECT_TRUE(edge_on.empty());
    Vector3fVector normals(5);
    std::vector<double> tri_areas(5);
    std::vector<std::uint8_t> flags(5);
    computeTriangleNormalsAndEdgeOn(
        positions, tris, Eigen::Vector3f::Zero(), bad, normals, tri_areas, flags);
    EXPECT_TRUE(normals.empty() && tri_areas.empty() && flags.empty());
  }
  std::vector<std::uint8_t> edge_on;
  markEdgeOnTriangles(positions, tris, n, Eigen::Vector3f::Zero(), 0.5, edge_on);
  EXPECT_EQ(edge_on.size(), 2u);
}

// A triangle naming a vertex beyond the arrays (or triangle ids beyond the mesh) is
// refused with a message, not read out of bounds: empty outputs, in-place arrays as
// they were.
TEST(MeshNormals, IdsBeyondTheArraysAreRefused)
{
  using namespace pcl::selective_seg;
  const Vector3fVector positions{Eigen::Vector3f(0, 0, 5),
                                 Eigen::Vector3f(1, 0, 5),
                                 Eigen::Vector3f(0, 1, 5),
                                 Eigen::Vector3f(1, 1, 5)};
  const std::vector<Triangle> good{{0, 1, 2}, {1, 3, 2}};
  for (const pcl::index_t bad_id :
       {pcl::index_t{4}, pcl::index_t{100000000}, pcl::index_t{-1}}) {
    SCOPED_TRACE(bad_id);
    const std::vector<Triangle> bad{{0, 1, 2}, {1, bad_id, 2}};
    Vector3fVector normals(7);
    std::vector<double> areas(7);
    std::vector<std::uint8_t> edge_on(7);
    computeTriangleNormals(positions, bad, Eigen::Vector3f::Zero(), normals, areas);
    EXPECT_TRUE(normals.empty() && areas.empty());
    computeTriangleNormalsAndEdgeOn(
        positions, bad, Eigen::Vector3f::Zero(), 1.4, normals, areas, edge_on);
    EXPECT_TRUE(normals.empty() && areas.empty() && edge_on.empty());
    const Vector3fVector n(2, Eigen::Vector3f(0, 0, -1));
    const std::vector<double> a(2, 0.5);
    edge_on.assign(3, 1);
    markEdgeOnTriangles(positions, bad, n, Eigen::Vector3f::Zero(), 1.4, edge_on);
    EXPECT_TRUE(edge_on.empty());
    Vector3fVector vertex_normals(3);
    std::vector<double> vertex_areas(3);
    computeVertexNormals(4, bad, n, a, vertex_normals, vertex_areas);
    EXPECT_TRUE(vertex_normals.empty() && vertex_areas.empty());
    vertex_normals.assign(3, Eigen::Vector3f::Zero());
    computeVertexNormalsOverRings(4, bad, n, a, 2, vertex_normals);
    EXPECT_TRUE(vertex_normals.empty());
    Vector3fVector missing(4, Eigen::Vector3f::Constant(NAN));
    EXPECT_EQ(fillMissingVertexNormals(bad, n, a, 1, missing), 0u);
    Vector3fVector from_vertices(5);
    computeTriangleNormalsFromVertices(bad, missing, from_vertices);
    EXPECT_TRUE(from_vertices.empty());
    EXPECT_TRUE(std::isnan(medianEdgeLength(positions, bad)));
    // In place: the arrays stay as they were.
    Vector3fVector kept(4, Eigen::Vector3f(0, 0, -1));
    std::vector<double> kept_areas(4, 1.0);
    const std::vector<Triangle> no_neighbours(2, Triangle{-1, -1, -1});
    updateVertexNormals(bad, no_neighbours, n, a, {1}, kept, kept_areas);
    updateVertexNormalsOverRings(bad, no_neighbours, n, a, 2, {1}, kept);
    EXPECT_EQ(kept, Vector3fVector(4, Eigen::Vector3f(0, 0, -1)));
    EXPECT_EQ(kept_areas, std::vector<double>(4, 1.0));
  }
  // Triangle ids beyond the mesh in the update functions' lists.
  const Vector3fVector n(2, Eigen::Vector3f(0, 0, -1));
  const std::vector<double> a(2, 0.5);
  Vector3fVector kept(4, Eigen::Vector3f(0, 0, -1));
  std::vector<double> kept_areas(4, 1.0);
  const std::vector<Triangle> no_neighbours(2, Triangle{-1, -1, -1});
  updateVertexNormals(good, no_neighbours, n, a, {7}, kept, kept_areas);
  updateVertexNormals(good, {{-1, -1, 9}, {-1, -1, -1}}, n, a, {1}, kept, kept_areas);
  EXPECT_EQ(kept, Vector3fVector(4, Eigen::Vector3f(0, 0, -1)));
  Vector3fVector old_normals(2, Eigen::Vector3f(0, 0, -1));
  std::vector<double> old_areas(2, 0.5);
  std::vector<std::uint8_t> old_flags(2, 0);
  updateTriangleNormalsAndEdgeOn(positions,
                                 good,
                                 Eigen::Vector3f::Zero(),
                                 1.4,
                                 {0, 5},
                                 {1},
                                 old_normals,
                                 old_areas,
                                 old_flags);
  EXPECT_EQ(old_normals.size(), 2u);
  EXPECT_EQ(old_areas, std::vector<double>(2, 0.5));
  // The same calls on the good mesh do their work.
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, good, Eigen::Vector3f::Zero(), normals, areas);
  EXPECT_EQ(normals.size(), 2u);
  EXPECT_NEAR(medianEdgeLength(positions, good), 1.0, 1e-6);
}

// The pipeline's scope that skips the id checks (its meshes meet them by
// construction) lives on its thread only, nests, and ends with the run.
TEST(MeshNormals, TrustedMeshScopeIsThreadLocalAndNests)
{
  using namespace pcl::selective_seg;
  EXPECT_FALSE(detail::meshTrusted());
  {
    const detail::TrustedMeshScope outer;
    EXPECT_TRUE(detail::meshTrusted());
    {
      const detail::TrustedMeshScope inner;
      EXPECT_TRUE(detail::meshTrusted());
    }
    EXPECT_TRUE(detail::meshTrusted());
    bool other_thread = true;
    std::thread([&] { other_thread = detail::meshTrusted(); }).join();
    EXPECT_FALSE(other_thread);
  }
  EXPECT_FALSE(detail::meshTrusted());
  // Outside the scope a broken mesh is refused (IdsBeyondTheArraysAreRefused).
  std::vector<Triangle> neighbours{{0, 0, 0}};
  computeTriangleNeighbours({{0, 1, 7}}, 3, neighbours);
  EXPECT_TRUE(neighbours.empty());
}

TEST(MeshNormals, EdgeOnThreshold)
{
  // A triangle centred on the optical axis at z = 5 whose normal makes 60 degrees with
  // the line of sight (0, 0, 1).
  const double incidence = 60.0 * kDeg;
  const Eigen::Vector3d normal(std::sin(incidence), 0.0, -std::cos(incidence));
  const Vector3fVector positions =
      equilateralAround(Eigen::Vector3d(0.0, 0.0, 5.0), normal, 1.0);
  const std::vector<Triangle> triangles{{0, 1, 2}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  expectVectorNear(normals[0], normal.cast<float>(), 1e-5f);

  std::vector<std::uint8_t> edge_on;
  markEdgeOnTriangles(positions,
                      triangles,
                      normals,
                      Eigen::Vector3f::Zero(),
                      incidence + 0.5 * kDeg,
                      edge_on);
  EXPECT_EQ(edge_on[0], 0);
  markEdgeOnTriangles(positions,
                      triangles,
                      normals,
                      Eigen::Vector3f::Zero(),
                      incidence - 0.5 * kDeg,
                      edge_on);
  EXPECT_EQ(edge_on[0], 1);
  // The test uses |cos|: a normal facing away from the viewer is judged the same way.
  const Vector3fVector reversed{-normals[0]};
  markEdgeOnTriangles(positions,
                      triangles,
                      reversed,
                      Eigen::Vector3f::Zero(),
                      incidence + 0.5 * kDeg,
                      edge_on);
  EXPECT_EQ(edge_on[0], 0);
}

TEST(MeshNormals, EdgeOnRightAngleFlagsOnlyDegenerate)
{
  // The plane y = 0 contains the line of sight; a degenerate triangle has no normal.
  const Vector3fVector positions{{0.f, 0.f, 4.f},
                                 {1.f, 0.f, 6.f},
                                 {-1.f, 0.f, 6.f},
                                 {0.f, 0.f, 1.f},
                                 {1.f, 1.f, 1.f},
                                 {2.f, 2.f, 1.f}};
  const std::vector<Triangle> triangles{{0, 1, 2}, {3, 4, 5}};
  Vector3fVector normals;
  std::vector<double> areas;
  computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
  ASSERT_TRUE(normals[0].allFinite());
  ASSERT_FALSE(normals[1].allFinite());
  std::vector<std::uint8_t> edge_on;
  for (const double max_incidence : {M_PI / 2.0, M_PI}) {
    SCOPED_TRACE(max_incidence);
    markEdgeOnTriangles(
        positions, triangles, normals, Eigen::Vector3f::Zero(), max_incidence, edge_on);
    EXPECT_EQ(edge_on[0], 0);
    EXPECT_EQ(edge_on[1], 1);
  }
}

// The one-pass function gives exactly the two passes' normals, areas and flags.
TEST(MeshNormals, NormalsAndEdgeOnInOnePassMatchTwoPasses)
{
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coordinate(-1.f, 1.f);
  Vector3fVector positions;
  for (int k = 0; k < 300; ++k)
    positions.emplace_back(coordinate(rng), coordinate(rng), 2.f + coordinate(rng));
  positions.push_back(positions[0]); // a degenerate triangle below
  std::vector<Triangle> triangles;
  for (int k = 0; k + 2 < 300; ++k)
    triangles.push_back({k, k + 1, k + 2});
  triangles.push_back({0, 300, 5});
  const Eigen::Vector3f eye(0.1f, -0.2f, 0.f);
  for (const double max_incidence : {60.0 * kDeg, 85.0 * kDeg, M_PI / 2.0}) {
    SCOPED_TRACE(max_incidence);
    Vector3fVector normals, fused_normals;
    std::vector<double> areas, fused_areas;
    std::vector<std::uint8_t> edge_on, fused_edge_on;
    computeTriangleNormals(positions, triangles, eye, normals, areas, 2);
    markEdgeOnTriangles(positions, triangles, normals, eye, max_incidence, edge_on, 2);
    pcl::selective_seg::computeTriangleNormalsAndEdgeOn(positions,
                                                        triangles,
                                                        eye,
                                                        max_incidence,
                                                        fused_normals,
                                                        fused_areas,
                                                        fused_edge_on,
                                                        2);
    ASSERT_EQ(fused_normals.size(), normals.size());
    for (std::size_t t = 0; t < normals.size(); ++t) {
      SCOPED_TRACE(t);
      EXPECT_EQ(normals[t].allFinite(), fused_normals[t].allFinite());
      if (normals[t].allFinite())
        EXPECT_TRUE(normals[t] == fused_normals[t]);
    }
    EXPECT_EQ(areas, fused_areas);
    EXPECT_EQ(edge_on, fused_edge_on);
    EXPECT_EQ(edge_on.back(), 1);
  }
}

// A strip of four triangles along x: 0-1-2, 1-3-2, 2-3-4, 3-5-4 (vertices 0, 2, 4 at
// y = 0 and 1, 3, 5 at y = 1). Triangle normals are given directly; areas all 1 except
// the last (area 4).
TEST(MeshNormals, RingNeighbourhoodsWidenEqTwo)
{
  using namespace pcl::selective_seg;
  const std::vector<Triangle> tris{{0, 1, 2}, {1, 3, 2}, {2, 3, 4}, {3, 5, 4}};
  const Vector3fVector n{Eigen::Vector3f(0, 0, -1),
                         Eigen::Vector3f(0, 0, -1),
                         Eigen::Vector3f(1, 0, 0),
                         Eigen::Vector3f(0, 1, 0)};
  const std::vector<double> areas{1.0, 1.0, 1.0, 4.0};
  Vector3fVector one_ring, rings1, rings2;
  std::vector<double> vertex_areas;
  computeVertexNormals(6, tris, n, areas, one_ring, vertex_areas);
  computeVertexNormalsOverRings(6, tris, n, areas, 1, rings1);
  computeVertexNormalsOverRings(6, tris, n, areas, 2, rings2);
  // rings = 1 is eq. 2 exactly.
  for (int v = 0; v < 6; ++v)
    EXPECT_TRUE(rings1[v].isApprox(one_ring[v], 1e-6f)) << v;
  // Vertex 0: one ring = triangle 0 only; two rings add the triangles at vertices 1
  // and 2 (triangles 1 and 2), so the sum is 2 (0,0,-1) + (1,0,0).
  EXPECT_TRUE(one_ring[0].isApprox(Eigen::Vector3f(0, 0, -1), 1e-6f));
  EXPECT_TRUE(rings2[0].isApprox(Eigen::Vector3f(1, 0, -2).normalized(), 1e-6f));
  // Vertex 5: one ring = triangle 3 (weight 1/4); two rings add triangles 1 and 2 (at
  // vertices 3 and 4): (0, 1/4, 0) + (0, 0, -1) + (1, 0, 0).
  EXPECT_TRUE(rings2[5].isApprox(Eigen::Vector3f(1, 0.25f, -1).normalized(), 1e-6f));
  // A triangle two rings away is not counted twice: vertex 2 sees all four.
  EXPECT_TRUE(rings2[2].isApprox(Eigen::Vector3f(1, 0.25f, -2).normalized(), 1e-6f));
}

TEST(MeshNormals, EdgeOnTrianglesLeftOutOfEqTwoWhereOthersRemain)
{
  // PointNormalTriangles::NotEdgeOn. Vertex 0 is shared by t0 (normal -z, area 1) and
  // the edge-on t1 (normal +x, area 0.25, which eq. 2's 1 / A weights four times
  // more); vertices 3 and 4 have t1 only.
  using namespace pcl::selective_seg;
  const std::vector<Triangle> triangles{{0, 1, 2}, {0, 3, 4}};
  const Vector3fVector normals{{0.f, 0.f, -1.f}, {1.f, 0.f, 0.f}};
  const std::vector<double> areas{1.0, 0.25};
  const std::vector<std::uint8_t> edge_on{0, 1};
  Vector3fVector masked, paper, vertex_normals;
  std::vector<double> paper_areas, vertex_areas;
  maskEdgeOnNormals(normals, edge_on, masked);
  ASSERT_EQ(masked.size(), 2u);
  EXPECT_EQ(masked[0], normals[0]);
  EXPECT_FALSE(masked[1].allFinite());
  computeVertexNormals(5, triangles, normals, areas, paper, paper_areas);
  computeVertexNormals(5, triangles, masked, areas, vertex_normals, vertex_areas);
  // The paper: (0, 0, -1) + 4 (1, 0, 0), 76 degrees from the facing triangle's.
  expectVectorNear(paper[0], Eigen::Vector3f(4.f, 0.f, -1.f).normalized());
  // Without t1: t0's normal alone. A_p (eq. 3) still counts t1.
  expectVectorNear(vertex_normals[0], Eigen::Vector3f(0.f, 0.f, -1.f));
  EXPECT_EQ(vertex_areas, paper_areas);
  EXPECT_NEAR(vertex_areas[0], 1.25, 1e-12);
  EXPECT_FALSE(vertex_normals[3].allFinite());
  // Vertices 3 and 4, all of whose triangles are edge-on, get the paper's normal.
  EXPECT_EQ(fillMissingVertexNormals(triangles, normals, areas, 1, vertex_normals), 2u);
  for (const int v : {3, 4})
    EXPECT_EQ(vertex_normals[v], paper[v]) << v;
  for (const int v : {0, 1, 2})
    expectVectorNear(vertex_normals[v], Eigen::Vector3f(0.f, 0.f, -1.f));
  // Nothing left to fill: nothing changes.
  const Vector3fVector filled = vertex_normals;
  EXPECT_EQ(fillMissingVertexNormals(triangles, normals, areas, 1, vertex_normals), 0u);
  EXPECT_EQ(vertex_normals, filled);
}

TEST(MeshNormals, FilledNormalsAreThePapersToTheBit)
{
  // On a random mesh with a third of its triangles flagged, every vertex the masked
  // sums leave without a normal gets exactly the paper's one- or k-ring normal, for any
  // thread count; a vertex with no valid triangle at all stays NaN.
  using namespace pcl::selective_seg;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_int_distribution<int> pick(0, 199);
  std::vector<Triangle> triangles;
  Vector3fVector normals;
  std::vector<double> areas;
  std::vector<std::uint8_t> edge_on;
  for (int t = 0; t < 300; ++t) {
    triangles.push_back({pick(rng), pick(rng), pick(rng)});
    normals.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized());
    areas.push_back(0.1 + 0.5 * (1.0 + u(rng)));
    edge_on.push_back(rng() % 3 == 0);
  }
  const std::size_t num_vertices = 210; // the last ten in no triangle
  Vector3fVector masked;
  maskEdgeOnNormals(normals, edge_on, masked);
  for (const int rings : {1, 3}) {
    SCOPED_TRACE(rings);
    Vector3fVector paper, reference;
    std::vector<double> paper_areas;
    computeVertexNormals(num_vertices, triangles, normals, areas, paper, paper_areas);
    if (rings > 1)
      computeVertexNormalsOverRings(
          num_vertices, triangles, normals, areas, rings, paper);
    std::size_t missing = 0;
    for (const int threads : {1, 2, 3}) {
      Vector3fVector vertex_normals;
      std::vector<double> vertex_areas;
      computeVertexNormals(num_vertices,
                           triangles,
                           masked,
                           areas,
                           vertex_normals,
                           vertex_areas,
                           threads);
      if (rings > 1)
        computeVertexNormalsOverRings(
            num_vertices, triangles, masked, areas, rings, vertex_normals);
      const Vector3fVector before = vertex_normals;
      const std::size_t filled = fillMissingVertexNormals(
          triangles, normals, areas, rings, vertex_normals, threads);
      missing = 0;
      for (std::size_t v = 0; v < num_vertices; ++v) {
        if (before[v].allFinite()) {
          ASSERT_EQ(std::memcmp(&vertex_normals[v], &before[v], sizeof before[v]), 0);
          continue;
        }
        ++missing;
        ASSERT_EQ(paper[v].allFinite(), vertex_normals[v].allFinite()) << v;
        if (paper[v].allFinite())
          ASSERT_EQ(std::memcmp(&vertex_normals[v], &paper[v], sizeof paper[v]), 0)
              << v;
      }
      EXPECT_EQ(filled, missing - 10); // the unused vertices stay NaN
      if (threads == 1)
        reference = vertex_normals;
      else
        EXPECT_EQ(std::memcmp(reference.data(),
                              vertex_normals.data(),
                              sizeof(Eigen::Vector3f) * num_vertices),
                  0);
    }
    if (rings == 1)
      EXPECT_GT(missing, 20u); // not only the unused vertices
  }
}

TEST(MeshNormals, TriangleNormalsFromVertexNormals)
{
  using namespace pcl::selective_seg;
  const std::vector<Triangle> tris{{0, 1, 2}, {1, 2, 3}};
  const Vector3fVector vertex_normals{Eigen::Vector3f(0, 0, -1),
                                      Eigen::Vector3f(1, 0, 0),
                                      Eigen::Vector3f(0, 1, 0),
                                      Eigen::Vector3f::Constant(kNaN)};
  Vector3fVector n;
  computeTriangleNormalsFromVertices(tris, vertex_normals, n);
  ASSERT_EQ(n.size(), 2u);
  expectVectorNear(n[0], Eigen::Vector3f(1, 1, -1).normalized());
  EXPECT_FALSE(n[1].allFinite()); // a vertex without a normal
}

TEST(MeshNormals, MedianEdgeLength)
{
  // t0 has edges 1, 2 and sqrt 5; alone its median is 2.
  const Vector3fVector positions{
      {0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 2.f, 0.f}, {0.f, 0.f, 7.f}};
  EXPECT_NEAR(medianEdgeLength(positions, {{0, 1, 2}}), 2.0, 1e-12);
  // With t1 (edges 1, sqrt 50, 7): 1, 1, 2, sqrt 5, 7, sqrt 50. The two middle values
  // are 2 and sqrt 5; accept either (an even count has no single median).
  const double both = medianEdgeLength(positions, {{0, 1, 2}, {0, 1, 3}});
  EXPECT_TRUE(std::abs(both - 2.0) < 1e-12 || std::abs(both - std::sqrt(5.0)) < 1e-6)
      << both;
  // t2 adds 2, sqrt 53, 7: 1, 1, 2, 2, sqrt 5, 7, 7, sqrt 50, sqrt 53 -> sqrt 5.
  EXPECT_NEAR(medianEdgeLength(positions, {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}}),
              std::sqrt(5.0),
              1e-6);
  EXPECT_EQ(medianEdgeLength(positions, {}), 0.0);
}

TEST(MeshNormals, MedianEdgeLengthIsTheSampledEdgesMedianForAnyThreadCount)
{
  // The selection must give, to the bit, the middle element of the sorted lengths of
  // the sampled edges (every stride-th triangle over 100,000 triangles), with ties and
  // lengths spread over many binades.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-1.f, 1.f);
  std::uniform_int_distribution<int> scale(-20, 20);
  for (const std::size_t num_triangles : {1u, 2u, 5u, 999u, 20000u, 100000u, 250001u}) {
    Vector3fVector positions(600);
    for (auto& p : positions)
      p = Eigen::Vector3f(coordinate(rng), coordinate(rng), coordinate(rng)) *
          std::ldexp(1.f, scale(rng));
    positions[1] = positions[0]; // zero-length edges
    std::uniform_int_distribution<pcl::index_t> vertex(0, 599);
    std::vector<pcl::selective_seg::Triangle> triangles(num_triangles);
    for (auto& t : triangles)
      t = {vertex(rng), vertex(rng), vertex(rng)};
    const std::size_t stride = std::max<std::size_t>(1, num_triangles / 100000);
    std::vector<double> lengths;
    for (std::size_t k = 0; k < num_triangles; k += stride)
      for (int i = 0; i < 3; ++i)
        lengths.push_back((positions[triangles[k][i]].cast<double>() -
                           positions[triangles[k][(i + 1) % 3]].cast<double>())
                              .norm());
    std::sort(lengths.begin(), lengths.end());
    const double expected = lengths[lengths.size() / 2];
    for (const int threads : {1, 2, 3})
      EXPECT_EQ(medianEdgeLength(positions, triangles, threads), expected)
          << num_triangles << " triangles, " << threads << " threads";
  }
}

TEST(MeshNormals, VertexSumsEqualTheGatheredOnesToTheBit)
{
  // computeVertexNormals() adds each triangle's terms to its vertices: with the
  // adjacency and delaunay2d()'s canonical order in runs split among threads (vertices
  // reached by two runs redone over their stars), else in one sequential pass or, for
  // large meshes, through vertex -> triangle lists. Every path must give the sums
  // gathered per vertex in increasing triangle order, to the bit.
  std::mt19937 rng(11);
  for (const int n : {50, 3000, 12000, 60000}) {
    std::vector<pcl::selective_seg::QuantizedPoint> angles;
    std::uniform_int_distribution<std::int32_t> coordinate(0, 4 * n);
    while (angles.size() < static_cast<std::size_t>(n))
      angles.push_back({coordinate(rng), coordinate(rng)});
    std::sort(angles.begin(), angles.end());
    angles.erase(std::unique(angles.begin(), angles.end()), angles.end());
    Vector3fVector positions;
    std::normal_distribution<float> noise(0.f, 0.2f);
    for (const auto& a : angles)
      positions.emplace_back(a[0] * 1e-3f, a[1] * 1e-3f, 1.f + noise(rng));
    for (std::size_t i = 7; i < positions.size(); i += 97)
      positions[i] = positions[i - 1]; // zero-area triangles
    std::vector<Triangle> triangles, neighbours;
    ASSERT_TRUE(pcl::selective_seg::delaunay2d(angles,
                                               pcl::selective_seg::DelaunayBackend::Sweep,
                                               triangles,
                                               neighbours));
    Vector3fVector normals;
    std::vector<double> areas;
    computeTriangleNormals(positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
    // Reference: eq. 2-3 gathered per vertex over its triangles in increasing order.
    const auto gather = [&](const std::vector<Triangle>& tris,
                            const Vector3fVector& tri_normals,
                            const std::vector<double>& tri_areas,
                            Vector3fVector& vertex_normals,
                            std::vector<double>& vertex_areas) {
      std::vector<std::vector<std::size_t>> incident(positions.size());
      for (std::size_t t = 0; t < tris.size(); ++t)
        for (const auto v : tris[t])
          incident[v].push_back(t);
      vertex_normals.resize(positions.size());
      vertex_areas.assign(positions.size(), 0.0);
      for (std::size_t v = 0; v < positions.size(); ++v) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (const auto t : incident[v]) {
          if (std::isfinite(tri_areas[t]))
            vertex_areas[v] += tri_areas[t];
          const double weight = 1.0 / tri_areas[t];
          if (std::isfinite(tri_areas[t]) && tri_areas[t] > 0.0 && std::isfinite(weight) &&
              tri_normals[t].allFinite())
            sum += weight * tri_normals[t].cast<double>();
        }
        const double norm = sum.norm();
        vertex_normals[v] =
            norm > 0.0 && std::isfinite(norm)
                ? Eigen::Vector3f((sum / norm).cast<float>())
                : Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
      }
    };
    // The same mesh with its triangles shuffled: not canonical, so a large one is
    // gathered even with its adjacency.
    std::vector<std::size_t> order(triangles.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<Triangle> shuffled;
    Vector3fVector shuffled_normals;
    std::vector<double> shuffled_areas;
    for (const auto t : order) {
      shuffled.push_back(triangles[t]);
      shuffled_normals.push_back(normals[t]);
      shuffled_areas.push_back(areas[t]);
    }
    std::vector<Triangle> shuffled_neighbours;
    pcl::selective_seg::computeTriangleNeighbours(
        shuffled, positions.size(), shuffled_neighbours);
    for (const bool reverse : {false, true}) {
      const auto& tris = reverse ? shuffled : triangles;
      const auto& tri_normals = reverse ? shuffled_normals : normals;
      const auto& tri_areas = reverse ? shuffled_areas : areas;
      Vector3fVector expected;
      std::vector<double> expected_areas;
      gather(tris, tri_normals, tri_areas, expected, expected_areas);
      for (const bool with_adjacency : {true, false}) {
        for (const int threads : {1, 2, 3}) {
          Vector3fVector computed;
          std::vector<double> computed_areas;
          computeVertexNormals(positions.size(),
                               tris,
                               tri_normals,
                               tri_areas,
                               computed,
                               computed_areas,
                               threads,
                               with_adjacency ? (reverse ? &shuffled_neighbours
                                                         : &neighbours)
                                              : nullptr);
          ASSERT_EQ(computed.size(), expected.size());
          EXPECT_EQ(std::memcmp(computed.data(),
                                expected.data(),
                                expected.size() * sizeof(Eigen::Vector3f)),
                    0)
              << n << " points, shuffled " << reverse << ", adjacency "
              << with_adjacency << ", " << threads << " threads";
          EXPECT_EQ(computed_areas, expected_areas)
              << n << " points, shuffled " << reverse << ", adjacency "
              << with_adjacency << ", " << threads << " threads";
        }
      }
    }
  }
}

TEST(MeshNormals, EmptyMeshes)
{
  // A mesh without triangles is a valid result (delaunay2d() on fewer than three or
  // collinear points, SphericalDelaunay on a single row): every vertex gets the values
  // of a vertex without a valid triangle, NaN normal and zero area, and every per
  // triangle output is empty.
  using namespace pcl::selective_seg;
  const std::vector<Triangle> none;
  const Vector3fVector no_normals;
  const std::vector<double> no_areas;
  for (const std::size_t num_vertices : {0u, 1u, 10u}) {
    const Vector3fVector positions(num_vertices, Eigen::Vector3f(0.f, 0.f, 1.f));
    for (const int threads : {1, 2}) {
      for (const bool with_adjacency : {false, true}) {
        Vector3fVector vertex_normals{Eigen::Vector3f::Zero()};
        std::vector<double> vertex_areas{1.0};
        computeVertexNormals(num_vertices,
                             none,
                             no_normals,
                             no_areas,
                             vertex_normals,
                             vertex_areas,
                             threads,
                             with_adjacency ? &none : nullptr);
        ASSERT_EQ(vertex_normals.size(), num_vertices);
        ASSERT_EQ(vertex_areas.size(), num_vertices);
        for (std::size_t v = 0; v < num_vertices; ++v) {
          EXPECT_TRUE(vertex_normals[v].array().isNaN().all()) << v;
          EXPECT_EQ(vertex_areas[v], 0.0) << v;
        }
      }
      Vector3fVector normals{Eigen::Vector3f::Zero()};
      std::vector<double> areas{1.0};
      std::vector<std::uint8_t> edge_on{1};
      computeTriangleNormals(
          positions, none, Eigen::Vector3f::Zero(), normals, areas, threads);
      EXPECT_TRUE(normals.empty());
      EXPECT_TRUE(areas.empty());
      computeTriangleNormalsAndEdgeOn(positions,
                                      none,
                                      Eigen::Vector3f::Zero(),
                                      1.0,
                                      normals,
                                      areas,
                                      edge_on,
                                      threads);
      EXPECT_TRUE(normals.empty());
      EXPECT_TRUE(edge_on.empty());
      markEdgeOnTriangles(
          positions, none, no_normals, Eigen::Vector3f::Zero(), 1.0, edge_on, threads);
      EXPECT_TRUE(edge_on.empty());
      updateTriangleNormalsAndEdgeOn(positions,
                                     none,
                                     Eigen::Vector3f::Zero(),
                                     1.0,
                                     {},
                                     {},
                                     normals,
                                     areas,
                                     edge_on,
                                     threads);
      EXPECT_TRUE(normals.empty());
      EXPECT_TRUE(areas.empty());
      EXPECT_TRUE(edge_on.empty());
      EXPECT_EQ(medianEdgeLength(positions, none, threads), 0.0);
    }
    Vector3fVector ring_normals;
    computeVertexNormalsOverRings(
        num_vertices, none, no_normals, no_areas, 2, ring_normals);
    ASSERT_EQ(ring_normals.size(), num_vertices);
    for (const auto& n : ring_normals)
      EXPECT_TRUE(n.array().isNaN().all());
    Vector3fVector from_vertices{Eigen::Vector3f::Zero()};
    computeTriangleNormalsFromVertices(none, ring_normals, from_vertices);
    EXPECT_TRUE(from_vertices.empty());
    // Nothing changed: the vertex values stay as they are.
    Vector3fVector kept(num_vertices, Eigen::Vector3f(0.f, 0.f, -1.f));
    std::vector<double> kept_areas(num_vertices, 2.0);
    updateVertexNormals(none, none, no_normals, no_areas, {}, kept, kept_areas);
    updateVertexNormalsOverRings(none, none, no_normals, no_areas, 2, {}, kept);
    EXPECT_EQ(kept, Vector3fVector(num_vertices, Eigen::Vector3f(0.f, 0.f, -1.f)));
    EXPECT_EQ(kept_areas, std::vector<double>(num_vertices, 2.0));
  }
}

TEST(MeshNormals, NonManifoldVertexSameForAnyThreadCount)
{
  // Two Delaunay patches glued at one vertex (a bow-tie: two separate fans of
  // triangles around it), in canonical order and large enough to be split among
  // threads. Walking the adjacency around the glued vertex covers one fan only; its
  // normal and area must still sum both fans, as on one thread.
  using namespace pcl::selective_seg;
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::int32_t> coordinate(0, 99999);
  std::vector<QuantizedPoint> angles;
  while (angles.size() < 5000) {
    angles.push_back({coordinate(rng), coordinate(rng)});
    std::sort(angles.begin(), angles.end());
    angles.erase(std::unique(angles.begin(), angles.end()), angles.end());
  }
  std::vector<Triangle> patch;
  ASSERT_TRUE(delaunay2d(angles, DelaunayBackend::Sweep, patch));
  const auto n = static_cast<pcl::index_t>(angles.size());
  for (const pcl::index_t glued : {n / 2, n - 1}) {
    // The second patch has its vertex 0 replaced by vertex `glued` of the first (its
    // own vertex 0, id n, is left without triangles).
    std::vector<Triangle> triangles = patch;
    for (auto t : patch) {
      for (auto& v : t)
        v = v == 0 ? glued : v + n;
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      triangles.push_back(t);
    }
    std::sort(triangles.begin(), triangles.end());
    ASSERT_GE(triangles.size(), 2 * detail::kMinParallelItems);
    Vector3fVector positions(2 * angles.size());
    for (pcl::index_t i = 0; i < 2 * n; ++i) {
      const auto& a = angles[i % n];
      positions[i] =
          Eigen::Vector3f(a[0] * 1e-5f, a[1] * 1e-5f, i < n ? 2.f : 2.f + a[0] * 1e-5f);
    }
    std::vector<Triangle> neighbours;
    computeTriangleNeighbours(triangles, positions.size(), neighbours);
    Vector3fVector normals;
    std::vector<double> areas;
    computeTriangleNormals(
        positions, triangles, Eigen::Vector3f::Zero(), normals, areas);
    // One thread: every vertex's triangles summed in increasing order.
    Vector3fVector expected;
    std::vector<double> expected_areas;
    computeVertexNormals(positions.size(),
                         triangles,
                         normals,
                         areas,
                         expected,
                         expected_areas,
                         1,
                         &neighbours);
    double fans_area = 0.0;
    for (std::size_t t = 0; t < triangles.size(); ++t)
      if (std::count(triangles[t].begin(), triangles[t].end(), glued))
        fans_area += areas[t];
    EXPECT_NEAR(expected_areas[glued], fans_area, 1e-12 * fans_area);
    for (const int threads : {2, 3, 4}) {
      Vector3fVector computed;
      std::vector<double> computed_areas;
      computeVertexNormals(positions.size(),
                           triangles,
                           normals,
                           areas,
                           computed,
                           computed_areas,
                           threads,
                           &neighbours);
      ASSERT_EQ(computed.size(), expected.size());
      EXPECT_EQ(std::memcmp(computed.data(),
                            expected.data(),
                            expected.size() * sizeof(Eigen::Vector3f)),
                0)
          << "glued vertex " << glued << ", " << threads
          << " threads: " << computed[glued].transpose() << " instead of "
          << expected[glued].transpose();
      EXPECT_EQ(computed_areas, expected_areas)
          << "glued vertex " << glued << ", " << threads
          << " threads: " << computed_areas[glued] << " instead of "
          << expected_areas[glued];
    }
  }
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
