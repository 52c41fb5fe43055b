/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/regions_of_interest.h>

#include <string>
#include <vector>

namespace selseg_apps {

/** \brief The regions of interest as JSON: the parameters that matter for the budget,
 * the counts, the sensor pose the windows refer to (when given: "sensor_pose", its
 * origin and its orientation as a quaternion w, x, y, z, sensor to cloud frame), and
 * per region its angular window (sensor frame, rad, to the last bit), 3-D box (cloud
 * frame, m), priority, steps, reasons and point estimates. */
bool writeRegionsJson(const std::string& path,
                      const std::string& input,
                      const pcl::selective_seg::RegionOfInterestParameters& params,
                      const pcl::selective_seg::RegionOfInterestStats& stats,
                      const std::vector<pcl::selective_seg::RegionOfInterest>& regions,
                      pcl::selective_seg::ViewProjection projection =
                          pcl::selective_seg::ViewProjection::Forward,
                      const Eigen::Affine3f* sensor_pose = nullptr);

/** \brief Read the regions back from a file written by writeRegionsJson() (windows,
 * boxes, priority, steps, reasons and counts, and the projection: forward when the
 * file does not name it; other keys are ignored).
 * \param[out] error what is wrong, naming the file */
bool readRegionsJson(const std::string& path,
                     std::vector<pcl::selective_seg::RegionOfInterest>& regions,
                     std::string& error);

/** \brief The same, and the sensor pose the windows refer to.
 * \param[out] has_pose whether the file records it (files written before it did, or
 *             without a pose, do not; \a sensor_pose is then the identity) */
bool readRegionsJson(const std::string& path,
                     std::vector<pcl::selective_seg::RegionOfInterest>& regions,
                     Eigen::Affine3f& sensor_pose,
                     bool& has_pose,
                     std::string& error);

} // namespace selseg_apps
