/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Window scans of the simulator and a small run of the simulated coarse-to-fine loop:
// with ground truth, a refinement round must improve the boundary accuracy.

#include <pcl_selective_seg/selective_loop.h>
#include <pcl_selective_seg/sensor_simulator.h>

#include <gtest/gtest.h>

#include <cmath>

namespace sim = pcl::selective_seg::simulation;

namespace {

sim::ScanWindow
window(double theta_min, double theta_max, double phi_min, double phi_max, double step)
{
  sim::ScanWindow w;
  w.theta_min = theta_min;
  w.theta_max = theta_max;
  w.phi_min = phi_min;
  w.phi_max = phi_max;
  w.step = step;
  return w;
}

sim::SimulationSetup
cube()
{
  auto setup = sim::makeCubeScene();
  setup.sensor.range_noise = 0.0005;
  return setup;
}

} // namespace

TEST(SimulateWindow, PointsLieInTheWindowAndFollowTheStep)
{
  const auto setup = cube();
  sim::SensorSimulator simulator;
  ASSERT_TRUE(simulator.setParameters(setup.sensor));
  pcl::PointCloud<pcl::PointXYZL> coarse, fine, again, other;
  sim::SimulationDetails details;
  const auto w = window(-0.1, 0.1, 0.4, 0.6, 0.004);
  ASSERT_TRUE(simulator.simulateWindow(setup.scene, w, coarse, &details));
  EXPECT_EQ(details.candidates, 50u * 50u);
  EXPECT_EQ(details.exact_ranges.size(), coarse.size());
  ASSERT_GT(coarse.size(), 500u);
  for (const auto& p : coarse) {
    const double theta = std::atan2(p.x, p.z), phi = std::atan2(p.y, p.z);
    EXPECT_GE(theta, w.theta_min - 1e-6);
    EXPECT_LE(theta, w.theta_max + 1e-6);
    EXPECT_GE(phi, w.phi_min - 1e-6);
    EXPECT_LE(phi, w.phi_max + 1e-6);
    EXPECT_GE(p.label, 1u);
  }
  // Half the step: four times the rays, about four times the points.
  auto half = w;
  half.step = 0.002;
  ASSERT_TRUE(simulator.simulateWindow(setup.scene, half, fine));
  const double ratio = double(fine.size()) / double(coarse.size());
  EXPECT_GT(ratio, 3.5);
  EXPECT_LT(ratio, 4.5);
  // Same window and id: the same cloud; another id: other rays.
  ASSERT_TRUE(simulator.simulateWindow(setup.scene, w, again));
  ASSERT_EQ(again.size(), coarse.size());
  for (std::size_t i = 0; i < coarse.size(); ++i)
    EXPECT_EQ(again[i].getVector3fMap(), coarse[i].getVector3fMap());
  auto w2 = w;
  w2.scan_id = 7;
  ASSERT_TRUE(simulator.simulateWindow(setup.scene, w2, other));
  EXPECT_NE(other[0].getVector3fMap(), coarse[0].getVector3fMap());
}

TEST(SimulateWindow, BadWindowsAreRejected)
{
  const auto setup = cube();
  sim::SensorSimulator simulator;
  pcl::PointCloud<pcl::PointXYZL> cloud;
  cloud.push_back(pcl::PointXYZL());
  std::string why;
  auto w = window(0.2, 0.1, 0.0, 0.1, 0.01);
  EXPECT_FALSE(w.validate(&why));
  EXPECT_NE(why.find("theta_min"), std::string::npos) << why;
  EXPECT_FALSE(simulator.simulateWindow(setup.scene, w, cloud));
  EXPECT_TRUE(cloud.empty());
  w = window(0.0, 0.1, 0.0, 1.6, 0.01);
  EXPECT_FALSE(w.validate(&why));
  EXPECT_NE(why.find("phi"), std::string::npos) << why;
  w = window(0.0, 0.1, 0.0, 0.1, 0.0);
  EXPECT_FALSE(w.validate(&why));
  EXPECT_NE(why.find("step"), std::string::npos) << why;
  w = window(-1.0, 1.0, -1.0, 1.0, 1e-6); // 4e12 cells
  EXPECT_FALSE(w.validate(&why));
  EXPECT_NE(why.find("1e8"), std::string::npos) << why;
}

TEST(SelectiveLoop, RefinementImprovesTheBoundaryAccuracy)
{
  const auto setup = cube();
  const double fine = 0.0045;
  sim::ReferenceBoundary reference;
  ASSERT_TRUE(sim::makeReferenceBoundary(setup, 0.5 * fine, reference));
  ASSERT_GT(reference.points.size(), 500u);

  sim::ScanScore coarse_uniform, dense;
  ASSERT_TRUE(sim::runUniformScan(setup, 3.0 * fine, {}, reference, coarse_uniform));
  ASSERT_TRUE(sim::runUniformScan(setup, fine, {}, reference, dense));
  // Finer uniform scans find the edges more accurately.
  EXPECT_LT(dense.accuracy.mean, 0.8 * coarse_uniform.accuracy.mean);

  sim::SelectiveLoopParameters params;
  params.fine_step = fine;
  params.iterations = 2;
  params.point_budget = dense.points * 3 / 10;
  std::vector<sim::ScanScore> rounds;
  int calls = 0;
  ASSERT_TRUE(sim::runSelectiveLoop(
      setup, params, reference, rounds, [&](const sim::LoopRound& r) {
        EXPECT_EQ(r.iteration, calls++);
        EXPECT_EQ(r.cloud->size(), r.result->labels.size());
      }));
  ASSERT_EQ(rounds.size(), 3u);
  EXPECT_EQ(calls, 3);
  EXPECT_LT(rounds[0].points, rounds[1].points);
  EXPECT_LT(rounds[1].points, rounds[2].points);
  EXPECT_LE(rounds.back().points, params.point_budget * 105 / 100);
  // The refinement rounds bring the boundaries closer to the truth.
  EXPECT_LT(rounds.back().accuracy.mean, 0.8 * rounds[0].accuracy.mean);
}

TEST(SelectiveLoop, BadParametersAreRejected)
{
  sim::ReferenceBoundary reference;
  std::vector<sim::ScanScore> rounds(1);
  sim::SelectiveLoopParameters params;
  params.fine_step = 0.0;
  EXPECT_FALSE(sim::runSelectiveLoop(cube(), params, reference, rounds));
  EXPECT_TRUE(rounds.empty());
  params = sim::SelectiveLoopParameters();
  params.point_budget = 0;
  EXPECT_FALSE(sim::runSelectiveLoop(cube(), params, reference, rounds));
  params = sim::SelectiveLoopParameters();
  params.iterations = 2001;
  EXPECT_FALSE(sim::runSelectiveLoop(cube(), params, reference, rounds));
}

TEST(SelectiveLoop, BudgetBelowTheCoarseScanFails)
{
  // The budget includes the coarse scan: one that cannot hold it is refused, not
  // silently overrun.
  const auto setup = cube();
  sim::ReferenceBoundary reference;
  ASSERT_TRUE(sim::makeReferenceBoundary(setup, 0.01, reference));
  sim::SelectiveLoopParameters params;
  params.fine_step = 0.0045;
  params.point_budget = 100;
  std::vector<sim::ScanScore> rounds;
  EXPECT_FALSE(sim::runSelectiveLoop(setup, params, reference, rounds));
  EXPECT_TRUE(rounds.empty());
}

TEST(SelectiveLoop, WindowsStayInTheViewAndTheBudgetIsUsed)
{
  // Many rounds with a small budget: each round's share is small, and windows at the
  // view's border have margins that reach past it.
  const auto setup = cube();
  const double fine = 0.0045;
  sim::ReferenceBoundary reference;
  ASSERT_TRUE(sim::makeReferenceBoundary(setup, 0.5 * fine, reference));
  sim::SelectiveLoopParameters params;
  params.fine_step = fine;
  params.iterations = 30;
  params.point_budget = 4000;
  std::vector<sim::ScanScore> rounds;
  pcl::PointCloud<pcl::PointXYZL> last; // a copy: the loop's clouds end with it
  std::size_t windows = 0;
  std::vector<std::size_t> scanned; // windows scanned in each round
  ASSERT_TRUE(sim::runSelectiveLoop(
      setup, params, reference, rounds, [&](const sim::LoopRound& r) {
        last = *r.cloud;
        scanned.push_back(r.regions->size());
        for (const auto& w : *r.regions) {
          ++windows;
          EXPECT_GE(w.theta_min, setup.sensor.theta_min);
          EXPECT_LE(w.theta_max, setup.sensor.theta_max);
          EXPECT_GE(w.phi_min, setup.sensor.phi_min);
          EXPECT_LE(w.phi_max, setup.sensor.phi_max);
        }
      }));
  ASSERT_EQ(last.size(), rounds.back().points);
  EXPECT_GT(windows, 0u);
  // Each score counts the windows of the step that led to it: the coarse scan is one
  // window (the whole view), then the windows the round before scanned.
  ASSERT_EQ(scanned.size(), rounds.size());
  EXPECT_EQ(rounds.front().windows, 1u);
  for (std::size_t k = 1; k < rounds.size(); ++k)
    EXPECT_EQ(rounds[k].windows, scanned[k - 1]) << "round " << k;
  // Every point acquired lies in the view (up to the float rounding of its angles).
  std::size_t outside = 0;
  for (const auto& p : last) {
    const double theta = std::atan2(p.x, p.z);
    const double phi = std::atan2(p.y, p.z);
    if (theta < setup.sensor.theta_min - 1e-6 ||
        theta > setup.sensor.theta_max + 1e-6 || phi < setup.sensor.phi_min - 1e-6 ||
        phi > setup.sensor.phi_max + 1e-6)
      ++outside;
  }
  EXPECT_EQ(outside, 0u);
  // A round whose share fits no window leaves it to the next: the loop goes on until
  // the budget is nearly used, and overruns it by one window's error at most.
  EXPECT_GE(rounds.back().points, params.point_budget * 9 / 10);
  EXPECT_LE(rounds.back().points, params.point_budget * 105 / 100);
}

// A draw of the cube's sensor (seed 6) whose coarse segmentation merges the cube's top
// face with the floor behind it (parallel normals, one coarse octree leaf): no edge
// triangle marks that occluding edge. Edge-on triangles (the depth jump) do, and the
// loop refines it in its first round. Without them, and with windows that may overlap,
// the edge stays at the coarse scan's error to the end; with disjoint windows (the
// default) the budget, spent once, reaches it in the later rounds.
TEST(SelectiveLoop, DepthJumpsInsideASegmentAreRefined)
{
  auto setup = cube();
  setup.sensor.seed = 6;
  const double fine = 0.0036;
  sim::ReferenceBoundary reference;
  ASSERT_TRUE(sim::makeReferenceBoundary(setup, 0.5 * fine, reference));
  sim::SelectiveLoopParameters params;
  params.fine_step = fine;
  params.point_budget = 6700; // 30% of the uniform scan at the fine step
  const auto run = [&](bool edge_on, bool disjoint) {
    sim::SelectiveLoopParameters p = params;
    p.regions.disjoint_windows = disjoint;
    if (!edge_on) {
      p.regions.use_edge_on = false;
      p.regions.use_valid_edges = false;
      p.regions.min_side_angle = 0.0;
    }
    std::vector<sim::ScanScore> rounds;
    EXPECT_TRUE(sim::runSelectiveLoop(setup, p, reference, rounds));
    EXPECT_EQ(rounds.size(), 4u);
    return rounds;
  };
  for (const bool disjoint : {false, true}) {
    SCOPED_TRACE(disjoint ? "disjoint windows" : "overlapping windows");
    const auto with = run(true, disjoint);
    const auto without = run(false, disjoint);
    ASSERT_EQ(with.size(), 4u);
    ASSERT_EQ(without.size(), 4u);
    // The coarse scans are the same; the refined results are not.
    EXPECT_EQ(with[0].accuracy.mean, without[0].accuracy.mean);
    EXPECT_GT(with[0].accuracy.mean, 0.025);
    EXPECT_LT(with[1].accuracy.mean, 0.6 * without[1].accuracy.mean);
    if (!disjoint) {
      EXPECT_LT(with.back().accuracy.mean, 0.5 * without.back().accuracy.mean);
      EXPECT_LT(with.back().accuracy.p90, 0.5 * without.back().accuracy.p90);
      EXPECT_GT(without.back().accuracy.mean, 0.015);
    } else {
      EXPECT_LT(with.back().accuracy.mean, 0.008);
      EXPECT_LT(without.back().accuracy.mean, 0.010);
    }
  }
}

TEST(SelectiveLoop, ReferenceBoundaryTellsJumpsAndCreasesApart)
{
  // The cube scene: box faces, table and wall meet at right angles, and the box and
  // the table occlude the wall: depth jumps and 90 deg creases only.
  sim::ReferenceBoundary cube_reference;
  ASSERT_TRUE(sim::makeReferenceBoundary(cube(), 0.003, cube_reference));
  ASSERT_EQ(cube_reference.kinds.size(), cube_reference.points.size());
  std::size_t jumps = 0, right = 0, other = 0;
  for (const auto& k : cube_reference.kinds)
    if (k.depth_jump)
      ++jumps;
    else if (!std::isnan(k.crease_angle))
      ++(std::abs(k.crease_angle * 180.0 / M_PI - 90.0) < 1.5 ? right : other);
  EXPECT_GT(jumps, 100u);
  EXPECT_GT(right, 500u);
  EXPECT_EQ(other, 0u);

  // The door (docs/selective_sensing.md): the panel, the shoulder and the ding are one
  // smooth skin (borders of 0 deg, measured up to about 10 deg where the one-ring
  // side normals see the skin's curvature), the skin meets the window frame in a
  // crease of 25 deg (measured 25-30 deg), and the frame's edges are depth jumps.
  const auto door = sim::makeDoorScene();
  sim::ReferenceBoundary door_reference;
  ASSERT_TRUE(sim::makeReferenceBoundary(door, 0.0016, door_reference));
  ASSERT_EQ(door_reference.kinds.size(), door_reference.points.size());
  std::size_t door_jumps = 0, smooth = 0, crease25 = 0;
  for (const auto& k : door_reference.kinds) {
    const double deg = k.crease_angle * 180.0 / M_PI;
    door_jumps += k.depth_jump;
    smooth += !k.depth_jump && deg < 12.0;
    crease25 += !k.depth_jump && deg >= 24.0 && deg < 31.0;
  }
  EXPECT_GT(door_jumps, door_reference.points.size() / 2);
  EXPECT_GT(smooth, 300u);
  EXPECT_GT(crease25, 200u);
}
