/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// detail::ParallelExceptions: an exception thrown on any thread of an OpenMP region
// comes out after the region, on the calling thread, instead of ending the process.
// (The library's own regions are tested through it in
// test/reliability/test_out_of_memory.cpp.)

#include <pcl_selective_seg/impl/parallel_exceptions.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using pcl::selective_seg::detail::ParallelExceptions;

namespace {

constexpr int kThreads = 4;
constexpr std::ptrdiff_t kItems = 10000;

} // namespace

TEST(ParallelExceptions, WithoutAnExceptionEveryPieceRunsAndNothingIsThrown)
{
  ParallelExceptions errors;
  std::vector<int> done(kItems, 0);
#pragma omp parallel for num_threads(kThreads) schedule(static)
  for (std::ptrdiff_t i = 0; i < kItems; ++i)
    errors.run([&] { done[i] = 1; });
  EXPECT_FALSE(errors.failed());
  EXPECT_NO_THROW(errors.rethrow());
  EXPECT_EQ(std::vector<int>(kItems, 1), done);
}

TEST(ParallelExceptions, AnExceptionOnAWorkerComesOutAfterTheRegion)
{
  // Item 7,777 is on the fourth thread with a static schedule: not the caller's.
  ParallelExceptions errors;
  std::atomic<std::ptrdiff_t> ran{0};
#pragma omp parallel for num_threads(kThreads) schedule(static)
  for (std::ptrdiff_t i = 0; i < kItems; ++i)
    errors.run([&] {
      ++ran;
      if (i == 7777)
        throw std::runtime_error("item 7777");
    });
  EXPECT_TRUE(errors.failed());
  EXPECT_GE(ran.load(), 1);
  try {
    errors.rethrow();
    FAIL() << "nothing thrown";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string("item 7777"), e.what());
  }
}

TEST(ParallelExceptions, StdBadAllocKeepsItsType)
{
  ParallelExceptions errors;
#pragma omp parallel for num_threads(kThreads) schedule(dynamic, 1)
  for (std::ptrdiff_t i = 0; i < kThreads; ++i)
    errors.run([&] {
      if (i == kThreads - 1)
        throw std::bad_alloc();
    });
  EXPECT_THROW(errors.rethrow(), std::bad_alloc);
}

TEST(ParallelExceptions, OneOfManyExceptionsComesOutAndLaterPiecesAreSkipped)
{
  // Every piece throws: the first one caught is kept; once a thread has seen the
  // failure it skips its remaining pieces, so far fewer than all of them run.
  ParallelExceptions errors;
  std::atomic<std::ptrdiff_t> ran{0};
#pragma omp parallel for num_threads(kThreads) schedule(static, 1)
  for (std::ptrdiff_t i = 0; i < kItems; ++i)
    errors.run([&] {
      ++ran;
      throw std::runtime_error(std::to_string(i));
    });
  EXPECT_LT(ran.load(), kItems / 2);
  try {
    errors.rethrow();
    FAIL() << "nothing thrown";
  } catch (const std::runtime_error& e) {
    const long item = std::stol(e.what());
    EXPECT_GE(item, 0);
    EXPECT_LT(item, kItems);
  }
}

TEST(ParallelExceptions, EveryThreadStillMeetsTheBarriersOfItsRegion)
{
  // A region of two work-sharing loops with a barrier between them, as the library's
  // regions have (a master part beside a loop): a failure in the first loop on one
  // thread must neither leave the others waiting at the barrier nor end the process.
  ParallelExceptions errors;
  std::atomic<int> after_barrier{0};
  int team = 0;
#pragma omp parallel num_threads(kThreads)
  {
#pragma omp master
    errors.run([&] { throw std::runtime_error("in the master part"); });
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < kItems; ++i)
      errors.run([] {});
#pragma omp barrier
    ++after_barrier;
#pragma omp single
    {
#ifdef _OPENMP
      team = omp_get_num_threads();
#else
      team = 1;
#endif
    }
  }
  EXPECT_EQ(team, after_barrier.load());
  EXPECT_THROW(errors.rethrow(), std::runtime_error);
}
