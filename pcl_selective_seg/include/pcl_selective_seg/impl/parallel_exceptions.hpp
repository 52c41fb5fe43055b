/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <atomic>
#include <exception>
#include <utility>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief Carries an exception out of an OpenMP parallel region.
 *
 * An exception must not leave a parallel region, nor a work-sharing construct inside
 * one: the runtime would call std::terminate (docs/reliability.md, "Out of memory").
 * Every piece of work in a region that can throw (in practice: that allocates) runs
 * through run(), which catches; after the region, rethrow() throws the first exception
 * caught, on the calling thread. After a failure the remaining pieces are skipped, but
 * every thread still meets every barrier and work-sharing construct of the region, as
 * OpenMP requires. The caller's work is abandoned, so what the skipped pieces would have
 * written does not matter.
 *
 * \code
 * ParallelExceptions errors;
 * #pragma omp parallel for
 * for (std::ptrdiff_t i = 0; i < n; ++i)
 *   errors.run([&] { work(i); });
 * errors.rethrow();
 * \endcode
 *
 * Neither catching nor carrying allocates (std::exception_ptr refers to the exception
 * object in flight), so it works when memory has run out.
 */
class ParallelExceptions {
public:
  /** \brief f(), unless a piece of work has already failed; an exception it throws is
   * kept (the first one of all threads) and not propagated. */
  template <typename F>
  void
  run(F&& f) noexcept
  {
    if (failed_.load(std::memory_order_relaxed))
      return;
    try {
      std::forward<F>(f)();
    } catch (...) {
      if (!failed_.exchange(true))
        first_ = std::current_exception();
    }
  }

  /** \brief Whether a piece of work has failed. */
  bool
  failed() const noexcept
  {
    return failed_.load(std::memory_order_relaxed);
  }

  /** \brief Throws the kept exception, if any. Call after the region, on the calling
   * thread (the end of the region orders the workers' writes before it). */
  void
  rethrow() const
  {
    if (first_)
      std::rethrow_exception(first_);
  }

private:
  std::atomic<bool> failed_{false};
  std::exception_ptr first_;
};

} // namespace detail
} // namespace selective_seg
} // namespace pcl
