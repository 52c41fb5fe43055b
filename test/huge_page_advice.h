/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Helpers of the tests that read the huge-page advice back from the kernel
// (/proc/self/smaps: "hg" among a mapping's VmFlags). Linux with MADV_HUGEPAGE only:
// SELSEG_TEST_HUGE_PAGE_ADVICE is then defined.

#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#if defined(__linux__) && defined(MADV_HUGEPAGE)
#define SELSEG_TEST_HUGE_PAGE_ADVICE 1

namespace selseg_test {

constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;

/** The first 2 MB boundary at or after \a p. */
inline std::uintptr_t
firstHugePage(const void* p)
{
  return (reinterpret_cast<std::uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
}

/** Whether the mapping holding \a address carries the huge-page advice, from
 * /proc/self/smaps; false if no mapping holds it. */
inline bool
advised(std::uintptr_t address)
{
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= address && address < end;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0)
      return (line + " ").find(" hg ") != std::string::npos;
  }
  return false;
}

/** An anonymous private mapping of \a bytes, unmapped at the end of the scope. */
class Mapping {
public:
  explicit Mapping(std::size_t bytes)
      : bytes_(bytes)
  {
    void* p = mmap(
        nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    data_ = p == MAP_FAILED ? nullptr : static_cast<char*>(p);
  }
  ~Mapping()
  {
    if (data_)
      munmap(data_, bytes_);
  }
  Mapping(const Mapping&) = delete;
  Mapping& operator=(const Mapping&) = delete;
  char* data() const { return data_; }

private:
  std::size_t bytes_;
  char* data_ = nullptr;
};

/** Skips the calling test where the kernel takes no huge-page advice. */
#define SKIP_WITHOUT_HUGE_PAGE_ADVICE()                                                \
  do {                                                                                 \
    selseg_test::Mapping probe(4 * selseg_test::kHugePage);                            \
    ASSERT_NE(probe.data(), nullptr);                                                  \
    const std::uintptr_t first = selseg_test::firstHugePage(probe.data());             \
    if (madvise(reinterpret_cast<void*>(first),                                        \
                selseg_test::kHugePage,                                                \
                MADV_HUGEPAGE) != 0 ||                                                 \
        !selseg_test::advised(first))                                                  \
      GTEST_SKIP() << "this kernel takes no MADV_HUGEPAGE advice";                     \
  } while (false)

} // namespace selseg_test

#endif // __linux__ && MADV_HUGEPAGE
