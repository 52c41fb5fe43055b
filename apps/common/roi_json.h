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
 * the counts, and per region its angular window (sensor frame, rad), 3-D box (cloud
 * frame, m), priority, steps, reasons and point estimates. */
bool writeRegionsJson(const std::string& path,
                      const std::string& input,
                      const pcl::selective_seg::RegionOfInterestParameters& params,
                      const pcl::selective_seg::RegionOfInterestStats& stats,
                      const std::vector<pcl::selective_seg::RegionOfInterest>& regions,
                      pcl::selective_seg::ViewProjection projection =
                          pcl::selective_seg::ViewProjection::Forward);

/** \brief Read the regions back from a file written by writeRegionsJson() (windows,
 * boxes, priority, steps, reasons and counts, and the projection: forward when the
 * file does not name it; other keys are ignored).
 * \param[out] error what is wrong, naming the file */
bool readRegionsJson(const std::string& path,
                     std::vector<pcl::selective_seg::RegionOfInterest>& regions,
                     std::string& error);

} // namespace selseg_apps
