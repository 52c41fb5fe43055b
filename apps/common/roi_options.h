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

/** \brief The region flags whose values the selective loop sets itself (the budgets,
 * the yield and the step): it refuses them. */
const std::vector<std::string>& loopSetRegionFlags();

/** \brief Print their help lines, with units and defaults; \a for_loop leaves out
 * loopSetRegionFlags(). */
void printRegionHelp(bool for_loop = false);

/** \brief Read those flags into \a params (degrees on the command line, radians in the
 * struct) and validate the result.
 * \return false, after printing what is wrong, on a bad value */
bool parseRegionOptions(int argc,
                        char** argv,
                        pcl::selective_seg::RegionOfInterestParameters& params);

} // namespace selseg_apps
