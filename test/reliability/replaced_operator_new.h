/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// The global operator new and delete, replaced for fault injection
// (test_out_of_memory.cpp, fail_allocation.cpp): every throwing form of new calls
// selsegTestAllocate(size, alignment), which the file that includes this header
// defines; every delete frees. The standard library's nothrow forms call these. Include
// it in one file of a program or module only: it defines the operators.

#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>

/** Defined by the includer: may throw std::bad_alloc, else returns selsegTestMalloc().
 */
void* selsegTestAllocate(std::size_t n, std::size_t alignment);

/** \a n bytes (at least 1), aligned to \a alignment when it exceeds malloc's; throws
 * std::bad_alloc when there are none. */
inline void*
selsegTestMalloc(std::size_t n, std::size_t alignment)
{
  void* p = nullptr;
  if (alignment <= alignof(std::max_align_t))
    p = std::malloc(n ? n : 1);
  else if (posix_memalign(&p, alignment, n ? n : 1) != 0)
    p = nullptr;
  if (!p)
    throw std::bad_alloc();
  return p;
}

void*
operator new(std::size_t n)
{
  return selsegTestAllocate(n, 0);
}
void*
operator new[](std::size_t n)
{
  return selsegTestAllocate(n, 0);
}
void*
operator new(std::size_t n, std::align_val_t a)
{
  return selsegTestAllocate(n, static_cast<std::size_t>(a));
}
void*
operator new[](std::size_t n, std::align_val_t a)
{
  return selsegTestAllocate(n, static_cast<std::size_t>(a));
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
