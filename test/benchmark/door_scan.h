/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// The benchmarks' cloud: the simulated door scene (the paper's largest, Fig. 6).

#pragma once

#include <pcl_selective_seg/sensor_simulator.h>

#include <pcl/common/io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <optional>

namespace selseg_bench {

/** \brief The door scene scanned with about \a n points, density varying tenfold
 * across the view, with the simulator's default seed or \a seed. */
inline pcl::PointCloud<pcl::PointXYZ>::Ptr
doorScan(std::size_t n, std::optional<unsigned> seed = std::nullopt)
{
  namespace sim = pcl::selective_seg::simulation;
  auto setup = sim::makeDoorScene(static_cast<double>(n) /
                                  sim::getPaperPointCount(sim::PaperScene::Door));
  setup.sensor.density_ratio = 10.0;
  if (seed)
    setup.sensor.seed = *seed;
  sim::SensorSimulator simulator;
  simulator.setParameters(setup.sensor);
  pcl::PointCloud<pcl::PointXYZL> labeled;
  simulator.simulate(setup.scene, labeled);
  auto xyz = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::copyPointCloud(labeled, *xyz);
  return xyz;
}

} // namespace selseg_bench
