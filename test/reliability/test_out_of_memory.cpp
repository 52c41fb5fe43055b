/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Out of memory (docs/reliability.md, "Out of memory"): the Nth allocation of an
// extract() or an update() throws std::bad_alloc, for N spread over every allocation of
// the call. Each trial runs in a child process of its own (a parent that never ran an
// OpenMP region, so that every child starts its own thread pool). A trial must end in
// one of three ways: the call succeeds with the result of a run without the failure;
// it returns false with the result cleared, the parameters and the input as they were,
// and the segmenter still works (update() refuses, extract() gives the result of a run
// without the failure); or, for an allocation inside a parallel stage, the process ends
// by std::terminate (SIGABRT: an exception cannot leave an OpenMP region). Anything
// else (another signal, a hang, a wrong result, a changed state) fails the test.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include <cube_scene.h>

namespace {

std::atomic<long> g_countdown{-1}; ///< allocations left before one fails; < 0: none fails
std::atomic<long> g_count{0};      ///< allocations so far

void*
allocate(std::size_t n, std::size_t alignment)
{
  g_count.fetch_add(1, std::memory_order_relaxed);
  if (g_countdown.load(std::memory_order_relaxed) >= 0 && g_countdown.fetch_sub(1) == 0)
    throw std::bad_alloc();
  void* p = nullptr;
  if (alignment <= alignof(std::max_align_t))
    p = std::malloc(n ? n : 1);
  else if (posix_memalign(&p, alignment, n ? n : 1) != 0)
    p = nullptr;
  if (!p)
    throw std::bad_alloc();
  return p;
}

} // namespace

void*
operator new(std::size_t n)
{
  return allocate(n, 0);
}
void*
operator new[](std::size_t n)
{
  return allocate(n, 0);
}
void*
operator new(std::size_t n, std::align_val_t a)
{
  return allocate(n, static_cast<std::size_t>(a));
}
void*
operator new[](std::size_t n, std::align_val_t a)
{
  return allocate(n, static_cast<std::size_t>(a));
}
void
operator delete(void* p) noexcept
{
  std::free(p);
}
void
operator delete[](void* p) noexcept
{
  std::free(p);
}
void
operator delete(void* p, std::size_t) noexcept
{
  std::free(p);
}
void
operator delete[](void* p, std::size_t) noexcept
{
  std::free(p);
}
void
operator delete(void* p, std::align_val_t) noexcept
{
  std::free(p);
}
void
operator delete[](void* p, std::align_val_t) noexcept
{
  std::free(p);
}
void
operator delete(void* p, std::size_t, std::align_val_t) noexcept
{
  std::free(p);
}
void
operator delete[](void* p, std::size_t, std::align_val_t) noexcept
{
  std::free(p);
}

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Seg = pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ>;

/** Exit codes of a trial. */
enum Outcome : int {
  kSucceeded = 0,
  kRefusedCleanly = 3,
  kWrongResult = 4,
  kBrokenAfter = 5,
  kStateChanged = 6,
  kSetupFailed = 8
};

struct Scans {
  Cloud::Ptr first = pcl::make_shared<Cloud>(); ///< four points in five
  Cloud::Ptr rest = pcl::make_shared<Cloud>();  ///< the fifth
  Cloud::Ptr both = pcl::make_shared<Cloud>();  ///< first, then rest
  Scans()
  {
    const auto scan = selseg_test::cubeScan(4000, 5);
    for (std::size_t i = 0; i < scan->size(); ++i) {
      const auto& p = (*scan)[i];
      ((i % 5 == 4) ? rest : first)->push_back(pcl::PointXYZ(p.x, p.y, p.z));
    }
    *both = *first;
    *both += *rest;
  }
};

/** A segmenter on two threads that has segmented \a first. */
bool
prepare(Seg& seg, const Cloud::Ptr& first)
{
  auto p = seg.getParameters();
  p.num_threads = 2;
  seg.setParameters(p);
  seg.setInputCloud(first);
  std::vector<pcl::PointIndices> clusters;
  return seg.extract(clusters);
}

/** The call under test: extract() of both, or update() of first with rest. */
bool
call(Seg& seg, const Scans& s, bool update, std::vector<pcl::PointIndices>& clusters)
{
  if (update)
    return seg.update(*s.rest, clusters);
  seg.setInputCloud(s.both);
  return seg.extract(clusters);
}

/** In a child: the labels of the call without a failure, of extract() on the union
 * (what a segmenter must give after a failed call), and the call's allocations. */
struct Reference {
  std::vector<std::uint32_t> call_labels, union_labels;
  long allocations = 0;
};

Reference
reference(const Scans& s, bool update)
{
  Reference r;
  Seg seg;
  if (!prepare(seg, s.first))
    std::_Exit(kSetupFailed);
  std::vector<pcl::PointIndices> clusters;
  const long before = g_count.load();
  if (!call(seg, s, update, clusters))
    std::_Exit(kSetupFailed);
  r.allocations = g_count.load() - before;
  r.call_labels = seg.getResult().labels;
  Seg fresh;
  if (!prepare(fresh, s.both))
    std::_Exit(kSetupFailed);
  r.union_labels = fresh.getResult().labels;
  return r;
}

/** In a child: fail the nth allocation of the call, then check the state. */
int
trial(const Scans& s, const Reference& ref, bool update, long n)
{
  Seg seg;
  if (!prepare(seg, s.first))
    return kSetupFailed;
  const auto params = seg.getParameters();
  std::vector<pcl::PointIndices> clusters;
  g_countdown = n;
  bool ok = false;
  try {
    ok = call(seg, s, update, clusters);
  } catch (const std::bad_alloc&) {
    return kWrongResult; // the library lets no std::bad_alloc out
  }
  g_countdown = -1;
  if (ok)
    return seg.getResult().labels == ref.call_labels ? kSucceeded : kWrongResult;
  if (!clusters.empty() || !seg.getResult().labels.empty() ||
      seg.getParameters().min_voxel_size != params.min_voxel_size)
    return kStateChanged;
  if (update) {
    if (seg.getInputCloud() != s.first)
      return kStateChanged;
    if (seg.update(*s.rest, clusters)) // nothing to fold into
      return kStateChanged;
    seg.setInputCloud(s.both);
  }
  if (!seg.extract(clusters))
    return kBrokenAfter;
  return seg.getResult().labels == ref.union_labels ? kRefusedCleanly : kBrokenAfter;
}

/** Runs f in a child process with a time limit; its wait status. */
template <typename F>
int
inChild(F f)
{
  const pid_t pid = fork();
  if (pid == 0) {
    alarm(120);
    // std::terminate's message, once per trial that ends so: not wanted in the log.
    if (FILE* null = std::freopen("/dev/null", "w", stderr); !null)
      std::_Exit(kSetupFailed);
    std::_Exit(f());
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

void
sweep(bool update)
{
  const Scans scans;
  // The number of allocations, from a child (the parent runs no OpenMP region).
  int pipe_fd[2];
  ASSERT_EQ(pipe(pipe_fd), 0);
  const int status = inChild([&] {
    const Reference ref = reference(scans, update);
    return write(pipe_fd[1], &ref.allocations, sizeof ref.allocations) ==
                   sizeof ref.allocations
               ? 0
               : kSetupFailed;
  });
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  long allocations = 0;
  ASSERT_EQ(read(pipe_fd[0], &allocations, sizeof allocations), sizeof allocations);
  close(pipe_fd[0]);
  close(pipe_fd[1]);
  ASSERT_GT(allocations, 100);
  const long step = std::max(1L, allocations / 150);
  int refused = 0, terminated = 0;
  for (long n = 0; n < allocations; n += step) {
    const int s = inChild([&] {
      const Reference ref = reference(scans, update);
      return trial(scans, ref, update, n);
    });
    if (WIFSIGNALED(s) && WTERMSIG(s) == SIGABRT) {
      ++terminated;
      continue;
    }
    ASSERT_TRUE(WIFEXITED(s)) << "allocation " << n << " of " << allocations
                              << ": signal " << WTERMSIG(s);
    const int code = WEXITSTATUS(s);
    ASSERT_TRUE(code == kSucceeded || code == kRefusedCleanly)
        << "allocation " << n << " of " << allocations << ": outcome " << code;
    refused += code == kRefusedCleanly;
  }
  // Both kinds occur: failures in sequential code are reported, in parallel stages
  // they end the process.
  EXPECT_GT(refused, 0);
  EXPECT_GT(terminated, 0);
  std::printf("%ld allocations, every %ld-th failed: %d reported, %d ended the process\n",
              allocations,
              step,
              refused,
              terminated);
}

} // namespace

TEST(OutOfMemory, ExtractReportsItOrEndsTheProcess)
{
  sweep(false);
}

TEST(OutOfMemory, UpdateReportsItOrEndsTheProcess)
{
  sweep(true);
}

int
main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  return RUN_ALL_TESTS();
}
