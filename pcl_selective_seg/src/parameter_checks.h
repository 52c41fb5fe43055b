/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

/* Internal header: the message every parameter check gives. Not installed. */

#pragma once

#include <sstream>
#include <string>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Sets *why (when not null) to "parameter NAME = VALUE is invalid: valid range
 * RANGE" and returns false. */
inline bool
rejectParameter(std::string* why, const char* name, double value, const char* range)
{
  if (why) {
    std::ostringstream s;
    s << "parameter " << name << " = " << value << " is invalid: valid range " << range;
    *why = s.str();
  }
  return false;
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
