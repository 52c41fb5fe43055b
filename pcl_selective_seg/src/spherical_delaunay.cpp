/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <pcl_selective_seg/impl/spherical_delaunay.hpp>
#include <pcl_selective_seg/point_types.h>

#include <pcl/impl/instantiate.hpp>

#include <array>
#include <cmath>

namespace pcl {
namespace selective_seg {
namespace detail {

long
quantizedAngle(double y, double x, double step)
{
  // atan(r), r = min(|y|, x) / max(|y|, x) in [0, 1], as atan(c) + atan(u) with c the
  // nearest multiple of 1/8 and u = (r - c) / (1 + r c), |u| <= 1/16 (r - c is exact,
  // Sterbenz). The series of atan(u) stops at u^11: the rest is below
  // u^13 / 13 < 2e-17.
  // With the roundings (a few 1e-16), the fast angle is within 1e-15 rad of the true
  // one, and std::atan2 within one ulp of it.
  static const std::array<double, 9> kAtanOfEighths = [] {
    std::array<double, 9> table{};
    for (int i = 0; i < 9; ++i)
      table[i] = std::atan(i / 8.0);
    return table;
  }();
  const double a = std::fabs(y);
  const bool steep = a > x;
  const double r = steep ? x / a : a / x;
  const int i = static_cast<int>(r * 8.0 + 0.5);
  const double c = 0.125 * i;
  const double u = (r - c) / (1.0 + r * c);
  const double u2 = u * u;
  const double tail =
      1.0 / 5.0 + u2 * (-1.0 / 7.0 + u2 * (1.0 / 9.0 - u2 * (1.0 / 11.0)));
  const double series = u + u * u2 * (-1.0 / 3.0 + u2 * tail);
  double angle = kAtanOfEighths[i] + series;
  if (steep)
    angle = M_PI_2 - angle;
  // |angle / step| against a half-integer: far enough (1e-13 rad, over a hundred times
  // the two errors, plus 1e-15 relative for the divisions' roundings), both quotients
  // round to the same integer.
  const double t = angle / step;
  if (t < 4.0e15) {
    const auto whole = static_cast<long>(t);
    const double fraction = t - static_cast<double>(whole);
    if (std::fabs(fraction - 0.5) > 1e-13 / step + 1e-15 * t) {
      const long n = whole + (fraction > 0.5 ? 1 : 0);
      return y < 0.0 ? -n : n;
    }
  }
  return std::lround(std::atan2(y, x) / step);
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl

PCL_INSTANTIATE(SphericalDelaunay, PCL_SELSEG_POINT_TYPES)
