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

/** \brief The flags of the region-of-interest parameters (each takes a value). */
const std::vector<std::string>& regionFlags();

/** \brief Print their help lines, with units and defaults. */
void printRegionHelp();

/** \brief Read those flags into \a params (degrees on the command line, radians in the
 * struct) and validate the result.
 * \return false, after printing what is wrong, on a bad value */
bool parseRegionOptions(int argc,
                        char** argv,
                        pcl::selective_seg::RegionOfInterestParameters& params);

} // namespace selseg_apps
