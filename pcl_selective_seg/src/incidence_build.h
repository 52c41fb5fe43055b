/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

/* Internal header: the counting sort behind every incidence list (vertex -> triangles,
 * leaf -> triangles, vertex -> half-edges). Not installed. */

#pragma once

#include <pcl_selective_seg/impl/large_arrays.hpp>
#include <pcl_selective_seg/region_merging.h>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <type_traits>
#include <vector>

namespace pcl {
namespace selective_seg {
namespace detail {

/** \brief An array stored in blocks of 4,096 entries: a large temporary array that can
 * reuse the memory earlier stages freed to the allocator (one block of it is below
 * malloc's mapping threshold) instead of mapping fresh pages on top of it. The entries
 * are left uninitialized (T is trivial): the caller writes every one, and filling the
 * blocks first was a sequential pass over the whole array. */
template <typename T>
class BlockArray {
  static_assert(std::is_trivially_default_constructible<T>::value &&
                    std::is_trivially_destructible<T>::value,
                "BlockArray leaves its entries uninitialized");

public:
  /** Blocks for \a size entries (the previous ones are freed), not initialized. */
  void resize(std::size_t size)
  {
    blocks_.clear();
    blocks_.resize((size + kMask) >> kShift);
    for (std::size_t b = 0; b < blocks_.size(); ++b)
      blocks_[b].reset(new T[std::min<std::size_t>(kMask + 1, size - (b << kShift))]);
  }
  T& operator[](std::size_t i) { return blocks_[i >> kShift][i & kMask]; }
  const T& operator[](std::size_t i) const { return blocks_[i >> kShift][i & kMask]; }

private:
  static constexpr std::size_t kShift = 12;
  static constexpr std::size_t kMask = (std::size_t{1} << kShift) - 1;
  std::vector<std::unique_ptr<T[]>> blocks_;
};

/** \brief Buckets by a counting sort: emit(item, f) calls f(group, value) for each entry
 * of the item. Once the sizes are known, offsets[g] .. offsets[g + 1] is the range of
 * bucket g (offsets has num_groups + 1 entries) and prepare(offsets) is called; then
 * store(g, slot, value) places each entry at its slot in that range, the entries of a
 * bucket in the order of their items (and of the calls within an item).
 *
 * With several threads the items are cut into one consecutive chunk per thread, each
 * chunk counted and then placed by its thread from its own cursors (a chunk's cursor
 * for a group starts after the earlier chunks' entries): the same buckets as one
 * thread gives. */
template <typename Value, typename Emit, typename Prepare, typename Store>
void
placeInBuckets(std::size_t num_items,
               std::size_t num_groups,
               Emit emit,
               int num_threads,
               std::vector<std::size_t>& offsets,
               Prepare prepare,
               Store store)
{
  const bool parallel = num_threads > 1 && num_items >= kMinParallelItems;
  const std::size_t chunks = parallel ? static_cast<std::size_t>(num_threads) : 1;
  const std::size_t chunk_size = (num_items + chunks - 1) / chunks;
  const auto chunk_begin = [&](std::size_t c) {
    return std::min(num_items, c * chunk_size);
  };
  // cursors[c][g]: first the number of entries of group g in chunk c, then where the
  // chunk's first one goes.
  std::vector<std::vector<std::size_t>> cursors(chunks);
  for (auto& cursor : cursors)
    assignLarge(cursor, num_groups, 0);
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(chunks)) schedule(static, 1)
#endif
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(chunks); ++c) {
    auto& count = cursors[c];
    for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
      emit(i, [&](pcl::index_t g, const Value&) { ++count[static_cast<std::size_t>(g)]; });
  }
  resizeLarge(offsets, num_groups + 1);
  std::size_t total = 0;
  for (std::size_t g = 0; g < num_groups; ++g) {
    offsets[g] = total;
    for (auto& cursor : cursors) {
      const std::size_t n = cursor[g];
      cursor[g] = total;
      total += n;
    }
  }
  offsets[num_groups] = total;
  prepare(offsets);
#ifdef _OPENMP
#pragma omp parallel for num_threads(static_cast<int>(chunks)) schedule(static, 1)
#endif
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(chunks); ++c) {
    auto& next = cursors[c];
    for (std::size_t i = chunk_begin(c); i < chunk_begin(c + 1); ++i)
      emit(i, [&](pcl::index_t g, const Value& value) {
        store(g, next[static_cast<std::size_t>(g)]++, value);
      });
  }
}

/** \brief values.resize(n): a std::vector into storage advised as huge-page memory
 * (resizeLarge()), a BlockArray in its blocks. */
template <typename T>
void
resizeBuckets(std::vector<T>& values, std::size_t n)
{
  resizeLarge(values, n);
}

template <typename Values>
void
resizeBuckets(Values& values, std::size_t n)
{
  values.resize(n);
}

/** \brief placeInBuckets() into one array: bucket g is values[offsets[g] ..
 * offsets[g + 1]). */
template <typename Value, typename Emit, typename Values = std::vector<Value>>
void
buildBuckets(std::size_t num_items,
             std::size_t num_groups,
             Emit emit,
             int num_threads,
             std::vector<std::size_t>& offsets,
             Values& values)
{
  placeInBuckets<Value>(
      num_items,
      num_groups,
      emit,
      num_threads,
      offsets,
      [&](const std::vector<std::size_t>& sizes) {
        resizeBuckets(values, sizes.back());
      },
      [&](pcl::index_t, std::size_t slot, const Value& value) {
        values[slot] = value;
      });
}

/** \brief Compressed incidence lists: groups_of(item, f) calls f(group) for each group
 * of the item; each group lists its items in increasing order (buildBuckets()). */
template <typename GroupsOf>
Incidence
buildIncidence(std::size_t num_items,
               std::size_t num_groups,
               GroupsOf groups_of,
               int num_threads = 1)
{
  Incidence inc;
  buildBuckets<pcl::index_t>(
      num_items,
      num_groups,
      [&](std::size_t i, auto f) {
        groups_of(i, [&](pcl::index_t g) { f(g, static_cast<pcl::index_t>(i)); });
      },
      num_threads,
      inc.offsets,
      inc.items);
  return inc;
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
