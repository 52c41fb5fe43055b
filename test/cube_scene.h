/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/sensor_simulator.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace selseg_test {

/** \brief The paper's cube scene (Fig. 4: a cube on a table in front of a wall) scanned
 * by the simulated stereo-like sensor: jittered rays whose density varies tenfold across
 * the view, small range noise (sigma = 0.0005 r^2), no dropouts or holes. Labels: 1
 * wall, 2 table, 3 cube top, 4 and 5 the two visible cube sides.
 * \param[in] rays about this many points
 * \param[in] seed the simulator's seed */
inline pcl::PointCloud<pcl::PointXYZL>::Ptr
cubeScan(std::size_t rays, unsigned seed = 42)
{
  namespace sim = pcl::selective_seg::simulation;
  sim::SimulationSetup setup = sim::makeCubeScene(
      static_cast<double>(rays) /
      static_cast<double>(sim::getPaperPointCount(sim::PaperScene::Cube)));
  setup.sensor.density_ratio = 10.0;
  setup.sensor.range_noise = 0.0005;
  setup.sensor.dropout = 0.0;
  setup.sensor.num_holes = 0;
  setup.sensor.seed = seed;
  sim::SensorSimulator simulator;
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZL>>();
  if (!simulator.setParameters(setup.sensor) || !simulator.simulate(setup.scene, *cloud))
    cloud->clear();
  return cloud;
}

} // namespace selseg_test
