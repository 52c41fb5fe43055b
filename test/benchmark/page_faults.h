/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// The benchmarks' page-fault counter: memory the process maps afresh costs a fault per
// page on first touch (microseconds each on a virtual machine), which the timings of
// 1M points and more show (docs/performance.md).

#pragma once

#include <sys/resource.h>

namespace selseg_bench {

/** \brief The minor page faults of this process so far (getrusage). */
inline double
minorFaults()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_minflt);
}

} // namespace selseg_bench
