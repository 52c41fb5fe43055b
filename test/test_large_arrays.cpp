/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// detail::adviseHugePages() and the vector helpers built on it: the advice covers
// exactly the whole 2 MB pages inside an array of at least the threshold
// (setHugePageAdviceThreshold(), 32 MB by default), and nothing else; the helpers size
// and fill the vectors as reserve/resize/assign do. The advice is read back from the
// kernel (/proc/self/smaps: "hg" among a mapping's VmFlags), on Linux with transparent
// huge pages; elsewhere those tests are skipped.

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/parameters.h>

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "huge_page_advice.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace seg = pcl::selective_seg;
namespace detail = pcl::selective_seg::detail;

namespace {

#if defined(SELSEG_TEST_HUGE_PAGE_ADVICE)

using selseg_test::advised;
using selseg_test::firstHugePage;
using selseg_test::kHugePage;
using selseg_test::Mapping;

TEST(AdviseHugePages, CoversExactlyTheWholeHugePagesInsideTheArray)
{
  SKIP_WITHOUT_HUGE_PAGE_ADVICE();
  // An array starting 1 MB + 12 bytes past a 2 MB boundary, ending 3 bytes short of
  // one: its whole huge pages run from the next boundary to the last one inside it.
  const std::size_t bytes = seg::kDefaultHugePageAdviceBytes + kHugePage + 1000;
  Mapping mapping(bytes + 4 * kHugePage);
  ASSERT_NE(mapping.data(), nullptr);
  const std::uintptr_t base = firstHugePage(mapping.data());
  const std::uintptr_t begin = base + kHugePage / 2 + 12;
  const std::uintptr_t end = begin + bytes;
  const std::uintptr_t first = base + kHugePage;
  const std::uintptr_t last = end & ~(kHugePage - 1);
  ASSERT_LT(first, last);
  detail::adviseHugePages(reinterpret_cast<const void*>(begin), bytes);
  EXPECT_TRUE(advised(first));
  EXPECT_TRUE(advised(last - 1));
  EXPECT_TRUE(advised((first + last) / 2));
  EXPECT_FALSE(advised(first - 1)) << "the partial page at the array's start";
  EXPECT_FALSE(advised(begin)) << "the partial page at the array's start";
  EXPECT_FALSE(advised(last)) << "the partial page at the array's end";
  EXPECT_FALSE(advised(end - 1)) << "the partial page at the array's end";
}

TEST(AdviseHugePages, LeavesSmallerArraysAlone)
{
  SKIP_WITHOUT_HUGE_PAGE_ADVICE();
  Mapping mapping(seg::kDefaultHugePageAdviceBytes + 2 * kHugePage);
  ASSERT_NE(mapping.data(), nullptr);
  const std::uintptr_t first = firstHugePage(mapping.data());
  // Several whole huge pages, but one byte short of the threshold.
  detail::adviseHugePages(reinterpret_cast<const void*>(first),
                          seg::kDefaultHugePageAdviceBytes - 1);
  EXPECT_FALSE(advised(first));
  EXPECT_FALSE(advised(first + seg::kDefaultHugePageAdviceBytes / 2));
}

/** Sets the advice threshold for the scope of a test, then restores it. */
class ScopedThreshold {
public:
  explicit ScopedThreshold(std::size_t bytes)
      : saved_(seg::getHugePageAdviceThreshold())
  {
    seg::setHugePageAdviceThreshold(bytes);
  }
  ~ScopedThreshold() { seg::setHugePageAdviceThreshold(saved_); }
  ScopedThreshold(const ScopedThreshold&) = delete;
  ScopedThreshold& operator=(const ScopedThreshold&) = delete;

private:
  std::size_t saved_;
};

TEST(AdviseHugePages, FollowsTheThresholdSet)
{
  SKIP_WITHOUT_HUGE_PAGE_ADVICE();
  const std::size_t bytes = 3 * kHugePage;
  Mapping mapping(bytes + 4 * kHugePage);
  ASSERT_NE(mapping.data(), nullptr);
  const std::uintptr_t first = firstHugePage(mapping.data());
  const auto* array = reinterpret_cast<const void*>(first);
  {
    ScopedThreshold off(std::numeric_limits<std::size_t>::max());
    detail::adviseHugePages(array, bytes);
    EXPECT_FALSE(advised(first)) << "advice off";
  }
  detail::adviseHugePages(array, bytes);
  EXPECT_FALSE(advised(first)) << "6 MB, under the default threshold";
  {
    ScopedThreshold low(bytes);
    detail::adviseHugePages(array, bytes);
    EXPECT_TRUE(advised(first));
    EXPECT_TRUE(advised(first + bytes - 1));
  }
}

TEST(LargeVectors, NewStorageOfALargeVectorIsAdvised)
{
  SKIP_WITHOUT_HUGE_PAGE_ADVICE();
  std::vector<std::uint32_t> v;
  const std::size_t n =
      (seg::kDefaultHugePageAdviceBytes + 3 * kHugePage) / sizeof(v[0]);
  detail::resizeLarge(v, n);
  const std::uintptr_t first = firstHugePage(v.data());
  EXPECT_TRUE(advised(first));
  EXPECT_TRUE(advised(first + seg::kDefaultHugePageAdviceBytes));
}

#endif // SELSEG_TEST_HUGE_PAGE_ADVICE

} // namespace

TEST(LargeVectors, SizeAndValuesAreThoseOfTheStandardCalls)
{
  // Below and above the threshold; from empty and from a vector with elements.
  for (const std::size_t n : {std::size_t{0},
                              std::size_t{5},
                              seg::kDefaultHugePageAdviceBytes / sizeof(int) + 77}) {
    std::vector<int> resized{1, 2, 3};
    detail::resizeLarge(resized, n);
    std::vector<int> expected{1, 2, 3};
    expected.resize(n);
    EXPECT_EQ(resized, expected);

    std::vector<int> assigned{4, 5};
    detail::assignLarge(assigned, n, -7);
    EXPECT_EQ(assigned, std::vector<int>(n, -7));

    std::vector<int> reserved{8, 9};
    detail::reserveLarge(reserved, n);
    EXPECT_GE(reserved.capacity(), n);
    EXPECT_EQ(reserved, (std::vector<int>{8, 9}));
  }
}

TEST(LargeVectors, StorageLargeEnoughIsKept)
{
  std::vector<double> v(1000, 1.5);
  v.reserve(5000);
  const double* const data = v.data();
  detail::reserveLarge(v, 4000);
  EXPECT_EQ(v.data(), data);
  detail::resizeLarge(v, 3000);
  EXPECT_EQ(v.data(), data);
  EXPECT_EQ(v.size(), 3000u);
  EXPECT_EQ(v[999], 1.5);
  EXPECT_EQ(v[1000], 0.0);
}

TEST(HugePageAdviceThreshold, DefaultIsThirtyTwoMegabytesAndSetValuesAreKept)
{
  EXPECT_EQ(seg::kDefaultHugePageAdviceBytes, std::size_t{32} << 20);
  EXPECT_EQ(seg::getHugePageAdviceThreshold(), seg::kDefaultHugePageAdviceBytes);
  seg::setHugePageAdviceThreshold(std::size_t{4} << 20);
  EXPECT_EQ(seg::getHugePageAdviceThreshold(), std::size_t{4} << 20);
  seg::setHugePageAdviceThreshold(seg::kDefaultHugePageAdviceBytes);
  EXPECT_EQ(seg::getHugePageAdviceThreshold(), seg::kDefaultHugePageAdviceBytes);
}

TEST(AdviseHugePages, NullOrEmptyIsANoOp)
{
  detail::adviseHugePages(nullptr, seg::kDefaultHugePageAdviceBytes * 2);
  int x = 0;
  detail::adviseHugePages(&x, 0);
  detail::adviseHugePages(&x, sizeof x);
  EXPECT_EQ(x, 0);
}
